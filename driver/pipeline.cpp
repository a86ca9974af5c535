// Every stage from source to evaluator, in order. A new stage is added here: to the table, to the run
// of compile(), and to emit().
#include "driver/pipeline.hpp"

#include "driver/external_functions.hpp"

#include "backend/interp/interpreter.hpp"
#include "backend/llvm/jit.hpp"
#include "frontend/inline_size.hpp"
#include "frontend/resolve.hpp"
#include "frontend/topology.hpp"
#include "ir/specialize.hpp"
#include "ir/tape.hpp"

#include <chrono>
#include <fmt/format.h>
#include <stdexcept>

namespace frac::driver {

const std::vector<StageInfo>& stages() {
    static const std::vector<StageInfo> table = {
        {Stage::lex, "lex", "the tokens of the main file"},
        {Stage::parse, "parse", "the syntax tree of the main file (imports read and parsed)"},
        {Stage::constraints, "constraints",
         "each bcifs's operators and constraints, with those its topology declarations generate"},
        {Stage::resolve, "resolve", "the definitions every name resolves to"},
        {Stage::typecheck, "typecheck", "the type of every definition and function instance"},
        {Stage::const_eval, "consteval",
         "the value of every constant: exact where it is rational, else enclosed"},
        {Stage::lower, "lower", "the expression graph of each shape (constants folded, series bounded)"},
        {Stage::automaton, "automaton", "the automaton IR of each ifs and cifs (lowered with the shapes)"},
        {Stage::tape, "tape", "the instruction tape of each shape"},
        {Stage::specialize, "specialize", "each shape's tape pruned over its default box"},
        {Stage::codegen, "codegen", "the JIT's optimised LLVM module of each shape"},
    };
    return table;
}

std::optional<Stage> find_stage(const std::string& name) {
    for (const StageInfo& s : stages())
        if (name == s.name) return s.stage;
    // The names earlier versions used.
    if (name == "ast") return Stage::parse;
    if (name == "ir") return Stage::lower;
    if (name == "llvm") return Stage::codegen;
    return std::nullopt;
}

std::string stage_names() {
    std::string out;
    for (const StageInfo& s : stages()) out += (out.empty() ? "" : ", ") + std::string(s.name);
    return out;
}

namespace {

const char* stage_name(Stage stage) {
    for (const StageInfo& s : stages())
        if (s.stage == stage) return s.name;
    throw front::InternalError("a stage missing from the pipeline's table");
}

// Times one stage into `times` (when not null).
template <class F>
auto timed(PassTimes* times, const std::string& name, F&& run) {
    const auto start = std::chrono::steady_clock::now();
    struct Record {
        PassTimes* times;
        const std::string& name;
        std::chrono::steady_clock::time_point start;
        ~Record() {
            if (times)
                times->add(name,
                           std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        }
    } record{times, name, start};
    return run();
}

// The stages after loading, up to options.stop.
void run_frontend(front::Compilation& c, const CompileOptions& options) {
    const auto reached = [&](Stage s) { return options.stop < s || c.diags.has_errors(); };
    if (reached(Stage::constraints)) return;
    timed(options.times, stage_name(Stage::constraints), [&] { front::expand_topology(c.program, c.diags); });
    if (reached(Stage::resolve)) return;
    timed(options.times, stage_name(Stage::resolve), [&] {
        front::resolve_names(c.program, c.diags);
        // Before anything inlines: a definition too large inlined is refused at once (inline_size.hpp).
        if (!c.diags.has_errors()) front::check_inline_size(c.program, options.limits, c.diags);
    });
    if (reached(Stage::typecheck)) return;
    const bool resolve_errors = c.diags.has_errors();
    timed(options.times, stage_name(Stage::typecheck),
          [&] { front::typecheck(c.program, options.limits, c.typed, c.diags); });
    // Constant evaluation and lowering run on what type-checked (typecheck.hpp), so one run reports
    // errors of every stage.
    if (options.stop < Stage::const_eval || resolve_errors) return;
    timed(options.times, stage_name(Stage::const_eval), [&] {
        front::evaluate_constants(c.program, c.typed, c.sources, options.limits, c.constants, c.diags);
    });
    if (options.stop < Stage::lower) return;
    timed(options.times, stage_name(Stage::lower), [&] {
        front::lower(c.program, c.typed, c.sources, options.limits, c.module, c.diags, &c.constants,
                     options.free_entry_seed);
    });
    // The runtime's implementations of the graph's external functions (dist): tapes carry them.
    if (!c.diags.has_errors()) timed(options.times, "bind", [&] { bind_externals(c.module, c.diags); });
    timed(options.times, "verify", [&] {
        if (std::string defect = ir::verify_graph(c.module.graph); !defect.empty())
            throw front::InternalError("malformed expression graph: " + defect);
    });
}

void add_load_times(const front::LoadTimes& load, PassTimes* times) {
    if (!times) return;
    times->add(stage_name(Stage::lex), load.lex);
    times->add(stage_name(Stage::parse), load.parse);
}

std::vector<const front::ShapeInfo*> selected(const front::Compilation& c,
                                              const std::vector<std::string>& names) {
    std::vector<const front::ShapeInfo*> out;
    if (names.empty())
        for (const front::ShapeInfo& s : c.module.shapes) out.push_back(&s);
    for (const std::string& n : names)
        if (const front::ShapeInfo* s = c.module.find_shape(n)) out.push_back(s);
    return out;
}

std::string token_text(const front::Token& t) {
    using front::Tok;
    const char* kind = t.kind == Tok::ident    ? "name"
                       : t.kind == Tok::number ? "number"
                       : t.kind == Tok::string ? "string"
                       : t.kind == Tok::end    ? "end"
                       : t.kind < Tok::lparen  ? "keyword"
                                               : "punctuation";
    return fmt::format("{}:{} {} {}\n", t.loc.line, t.loc.column, kind, t.text);
}

const char* item_kind_name(front::ItemKind k) {
    switch (k) {
    case front::ItemKind::import: return "import";
    case front::ItemKind::fn: return "fn";
    case front::ItemKind::const_: return "const";
    case front::ItemKind::shape: return "shape";
    case front::ItemKind::test: return "test";
    case front::ItemKind::print: return "print";
    case front::ItemKind::automaton: return "automaton";
    }
    return "?";
}

// The definitions of the program (the main file's and the imported ones), with where they are written.
std::string definitions_text(const front::Compilation& c) {
    std::string out;
    for (const front::Item& it : c.program.items) {
        if (it.kind == front::ItemKind::test || it.kind == front::ItemKind::print) continue;
        std::string params;
        for (const front::Param& p : it.params) params += (params.empty() ? "" : ", ") + p.name;
        out += fmt::format("{} {}{} at {}:{}\n", item_kind_name(it.kind), it.name,
                           it.kind == front::ItemKind::fn || it.has_params ? "(" + params + ")" : "",
                           c.sources.name(it.loc.file), it.loc.line);
    }
    return out;
}

} // namespace

void PassTimes::add(const std::string& name, double seconds) {
    for (auto& [n, s] : passes)
        if (n == name) {
            s += seconds;
            return;
        }
    passes.emplace_back(name, seconds);
}

std::string PassTimes::report() const {
    double total = 0;
    for (const auto& [name, s] : passes) total += s;
    std::string out = "pass           time (ms)   share\n";
    for (const auto& [name, s] : passes)
        out += fmt::format("{:<14} {:>9.3f}  {:>5.1f}%\n", name, s * 1e3, total > 0 ? 100 * s / total : 0.0);
    out += fmt::format("{:<14} {:>9.3f}\n", "total", total * 1e3);
    return out;
}

std::unique_ptr<front::Compilation> compile_file(const std::string& path, const CompileOptions& options) {
    auto c = std::make_unique<front::Compilation>();
    front::LoadTimes load;
    const bool read = front::load_file(*c, path, options.limits, &load);
    add_load_times(load, options.times);
    if (!read) return c;
    front::apply_overrides(*c, options.overrides);
    if (!c->unknown_overrides.empty()) return c;
    run_frontend(*c, options);
    return c;
}

std::unique_ptr<front::Compilation> compile_source(const std::string& name, const std::string& text,
                                                   const CompileOptions& options) {
    auto c = std::make_unique<front::Compilation>();
    front::LoadTimes load;
    front::load_source(*c, name, text, options.limits, &load);
    add_load_times(load, options.times);
    run_frontend(*c, options);
    return c;
}

std::string emit(const front::Compilation& c, Stage stage, const std::vector<std::string>& shapes,
                 PassTimes* times) {
    constexpr std::uint32_t main_file = 1; // imported files' items are not the model's own text
    switch (stage) {
    case Stage::lex: {
        front::Diagnostics ignored; // the load already reported them
        std::string out;
        for (const front::Token& t : front::lex(c.sources.text(main_file), main_file, ignored))
            out += token_text(t);
        return out;
    }
    case Stage::parse: return front::print_ast(c.program, main_file);
    case Stage::constraints: return front::print_constraints(c.program, main_file);
    case Stage::resolve: return definitions_text(c);
    case Stage::typecheck: return front::print_types(c.program, c.typed, main_file);
    case Stage::const_eval: return front::print_constants(c.program, c.constants, main_file);
    case Stage::automaton: {
        std::string out;
        for (const front::AutomatonInfo& a : c.module.automata)
            if (a.loc.file == main_file)
                out += ir::print_automaton(a.automaton) + fmt::format("  contracts: {}\n", a.contraction);
        return out;
    }
    default: break;
    }
    const front::Module& m = c.module;
    std::string out;
    for (const front::ShapeInfo* s : selected(c, shapes)) {
        if (stage == Stage::lower) {
            out += fmt::format("shape {} ({} coordinates):\n{}", s->name, s->dimension,
                               ir::print_graph(m.graph, {s->root}));
            continue;
        }
        // The backend stages run in order up to the one asked for, each timed; only that one prints.
        const ir::Tape tape = timed(times, stage_name(Stage::tape),
                                    [&] { return ir::build_tape(m.graph, s->root, s->dimension); });
        if (stage == Stage::tape) {
            out += fmt::format("shape {}:\n{}", s->name, ir::print_tape(tape));
            continue;
        }
        const ir::Tape pruned = timed(times, stage_name(Stage::specialize), [&] {
            interp::ChoiceRecorder recorder(tape, {});
            return ir::specialize(tape, recorder.record(s->box.data()));
        });
        if (stage == Stage::specialize) {
            out += fmt::format("shape {} over its box:\n{}", s->name, ir::print_tape(pruned));
            continue;
        }
        std::string why;
        if (!jit::jit_available(&why))
            throw std::runtime_error("the codegen stage needs the LLVM backend, which cannot be used here: " +
                                     why);
        // The optimised module the JIT compiles for this host (frac compile --emit-llvm writes the one of
        // a compiled model, with its C entry points).
        out += fmt::format("; shape {}\n{}", s->name,
                           timed(times, stage_name(Stage::codegen), [&] { return jit::emit_llvm(tape); }));
    }
    return out;
}

} // namespace frac::driver
