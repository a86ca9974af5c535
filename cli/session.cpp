#include "cli/session.hpp"

#include "backend/interp/interpreter.hpp"
#include "backend/llvm/jit.hpp"
#include "runtime/dimension.hpp"
#include "runtime/rss.hpp"

#include <fmt/format.h>
#include <iostream>
#include <sstream>

namespace frac::cli {

std::unique_ptr<front::Compilation> compile_or_report(const std::string& path, front::StopAfter stop) {
    auto c = front::compile_file(path, {}, stop);
    if (!c->ok()) {
        std::cerr << c->diags.render(c->sources);
        const std::size_t n = c->diags.error_count();
        std::cerr << fmt::format("{} error{} in {}\n", n, n == 1 ? "" : "s", path);
        return nullptr;
    }
    if (!c->diags.all().empty()) std::cerr << c->diags.render(c->sources); // warnings
    return c;
}

const front::ShapeInfo& find_shape(const front::Compilation& c, const std::string& name) {
    if (const front::ShapeInfo* s = c.module.find_shape(name)) return *s;
    std::string known;
    for (const auto& s : c.module.shapes) known += (known.empty() ? "" : ", ") + s.name;
    throw RunError(
        fmt::format("no shape '{}' in the model (shapes: {})", name, known.empty() ? "none" : known));
}

const front::ShapeInfo& pick_shape(const front::Compilation& c, const std::string& name) {
    if (!name.empty()) return find_shape(c, name);
    if (c.module.shapes.empty()) throw RunError("the model defines no shape");
    // The last shape of the main file: imported libraries come first.
    return c.module.shapes.back();
}

std::unique_ptr<ir::Evaluator> make_evaluator(const front::Module& m, ir::NodeId root, int inputs,
                                              const EngineOptions& options) {
    ir::Tape tape = ir::build_tape(m.graph, root, inputs);
    if (std::string defect = ir::verify_tape(tape); !defect.empty())
        throw front::InternalError("malformed tape: " + defect);
    if (options.engine == "jit") {
        std::string why;
        if (jit::jit_available(&why)) {
            try {
                return jit::make_jit(tape, options.eval);
            } catch (const jit::JitError& e) {
                why = e.what();
            }
        }
        static bool told = false; // say it once per run
        if (!told)
            std::cerr << fmt::format("frac: note: the JIT cannot be used ({}); using the interpreter\n", why);
        told = true;
    } else if (options.engine != "interp") {
        throw RunError(fmt::format("unknown engine '{}' (available: jit, interp)", options.engine));
    }
    return interp::make_interpreter(std::move(tape), options.eval);
}

namespace {

std::vector<std::string> split(const std::string& text, char sep) {
    std::vector<std::string> parts;
    std::stringstream ss(text);
    std::string part;
    while (std::getline(ss, part, sep)) parts.push_back(part);
    return parts;
}

ir::Interval parse_number(const std::string& text) {
    std::size_t used = 0;
    try {
        (void)std::stod(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used == 0 || used != text.size()) throw RunError(fmt::format("'{}' is not a number", text));
    return num::from_decimal(text);
}

} // namespace

std::vector<ir::Interval> parse_box(const std::string& text, int dimension) {
    const auto axes = split(text, ',');
    if (static_cast<int>(axes.size()) != dimension)
        throw RunError(fmt::format("the box '{}' has {} axes, the shape has {} coordinates", text,
                                   axes.size(), dimension));
    std::vector<ir::Interval> box;
    for (const std::string& axis : axes) {
        const auto bounds = split(axis, ':');
        if (bounds.size() != 2) throw RunError(fmt::format("'{}' is not an interval lo:hi", axis));
        const ir::Interval lo = parse_number(bounds[0]), hi = parse_number(bounds[1]);
        if (!(lo.lo <= hi.hi)) throw RunError(fmt::format("empty interval '{}'", axis));
        box.push_back({lo.lo, hi.hi});
    }
    return box;
}

std::vector<double> parse_point(const std::string& text, int dimension,
                                std::vector<ir::Interval>* enclosure) {
    const auto coords = split(text, ',');
    if (static_cast<int>(coords.size()) != dimension)
        throw RunError(fmt::format("the point '{}' has {} coordinates, the shape has {}", text, coords.size(),
                                   dimension));
    std::vector<double> p;
    for (const std::string& c : coords) {
        const ir::Interval v = parse_number(c);
        if (enclosure) enclosure->push_back(v);
        p.push_back(std::stod(c));
    }
    return p;
}

std::string format_interval(ir::Interval v) {
    if (v.is_empty()) return "empty";
    return fmt::format("[{}, {}]", v.lo, v.hi);
}

std::vector<ir::Interval> answer_queries(const front::Module& m, const ir::Tape& tape,
                                         const EngineOptions& options,
                                         std::vector<std::optional<ir::Interval>>& answers) {
    answers.resize(m.queries.size());
    std::vector<ir::Interval> inputs(m.queries.size(), ir::Interval(0.0));
    for (std::size_t k = 0; k < tape.input_slots.size(); ++k) {
        if (tape.input_slots[k] == ir::no_slot) continue;
        if (!answers[k]) {
            const front::Query& q = m.queries[k];
            const front::ShapeInfo& s = m.shapes[q.shape];
            auto eval = make_evaluator(m, s.root, s.dimension, options);
            if (q.kind == front::Query::Kind::enclose) {
                answers[k] = eval->eval_box(q.box.data());
            } else {
                rt::RssOptions ro;
                ro.depth = q.to;
                ro.split = q.split;
                ro.keep_cells = false;
                ro.threads = options.threads;
                try {
                    const rt::RssResult r = rt::subdivide(*eval, q.box, ro);
                    answers[k] = ir::Interval(rt::box_counting(r, q.from, q.to).dimension);
                } catch (const std::invalid_argument& e) {
                    throw RunError(fmt::format("dimension of '{}': {}", s.name, e.what()));
                }
            }
        }
        inputs[k] = *answers[k];
    }
    return inputs;
}

} // namespace frac::cli
