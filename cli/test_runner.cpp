// frac test / frac run: print statements and test blocks.
#include "cli/commands.hpp"

#include "ir/semantics.hpp"

#include <fmt/format.h>
#include <iostream>

namespace frac::cli {

namespace {

struct ClosedEval {
    std::unique_ptr<ir::Evaluator> eval;
    std::vector<ir::Interval> inputs;
};

// Evaluates a closed expression (one that reads only query answers) as an enclosure and a point value.
// An expression that reads an enclosure (enclose(s, B)) has no point value: the midpoint of the
// enclosure would pose as one, so `point` is left empty then.
ir::Interval enclose_closed(const front::Module& m, ir::NodeId node, const EngineOptions& engine,
                            std::vector<std::optional<ir::Interval>>& answers, std::optional<double>* point) {
    const int inputs = static_cast<int>(m.queries.size());
    const ir::Tape tape = ir::build_tape(m.graph, node, inputs);
    std::vector<ir::Interval> in = answer_queries(m, tape, engine, answers);
    auto eval = make_evaluator(m, node, inputs, engine);
    if (point) {
        bool reads_enclosure = false;
        for (std::size_t k = 0; k < tape.input_slots.size(); ++k)
            reads_enclosure |=
                tape.input_slots[k] != ir::no_slot && m.queries[k].kind == front::Query::Kind::enclose;
        point->reset();
        if (!reads_enclosure) {
            std::vector<double> p;
            for (const ir::Interval& v : in) p.push_back(num::midpoint(v));
            *point = eval->eval_point(p.data());
        }
    }
    return eval->eval_box(in.data());
}

std::string truth_text(ir::Interval t) {
    if (t == ir::tv_true) return "true";
    if (t == ir::tv_false) return "false";
    if (t.is_empty()) return "undefined";
    return "unknown";
}

std::string value_text(ir::Interval v, std::optional<double> point) {
    if (v.is_thin()) return fmt::format("{}", v.lo);
    if (v.is_empty()) return "empty";
    if (!point) return format_interval(v);
    return fmt::format("{} in {}", *point, format_interval(v));
}

void run_prints(const front::Compilation& c, const EngineOptions& engine,
                std::vector<std::optional<ir::Interval>>& answers) {
    const front::Module& m = c.module;
    for (const front::PrintInfo& p : m.prints) {
        switch (p.kind) {
        case front::ValueKind::interval: std::cout << format_interval(p.box[0]) << "\n"; break;
        case front::ValueKind::box: {
            std::string s;
            for (std::size_t i = 0; i < p.box.size(); ++i) s += (i ? " × " : "") + format_interval(p.box[i]);
            std::cout << s << "\n";
            break;
        }
        case front::ValueKind::boolean:
            std::cout << truth_text(enclose_closed(m, p.nodes[0], engine, answers, nullptr)) << "\n";
            break;
        case front::ValueKind::scalar:
        case front::ValueKind::point: {
            std::string s;
            for (std::size_t i = 0; i < p.nodes.size(); ++i) {
                std::optional<double> pt;
                const ir::Interval v = enclose_closed(m, p.nodes[i], engine, answers, &pt);
                s += (i ? ", " : "") + value_text(v, pt);
            }
            std::cout << (p.kind == front::ValueKind::point ? "(" + s + ")" : s) << "\n";
            break;
        }
        }
    }
}

} // namespace

int run_tests(const std::vector<std::string>& files, bool prints, const EngineOptions& engine) {
    int passed = 0, failed = 0;
    bool compile_failed = false, any_tests = false;
    for (const std::string& file : files) {
        auto c = compile_or_report(file);
        if (!c) {
            compile_failed = true;
            continue;
        }
        std::vector<std::optional<ir::Interval>> answers;
        if (prints) run_prints(*c, engine, answers);
        for (const front::TestInfo& t : c->module.tests) {
            any_tests = true;
            std::vector<std::string> problems;
            for (const front::Expectation& x : t.expects) {
                try {
                    const ir::Interval truth = enclose_closed(c->module, x.truth, engine, answers, nullptr);
                    if (truth == ir::tv_true) continue;
                    std::string shown;
                    for (ir::NodeId n : x.shown) {
                        std::optional<double> pt;
                        const ir::Interval v = enclose_closed(c->module, n, engine, answers, &pt);
                        shown += (shown.empty() ? "" : ", ") + value_text(v, pt);
                    }
                    problems.push_back(
                        fmt::format("  {}:{}:{}: expectation is {}{}\n    {}", c->sources.name(x.loc.file),
                                    x.loc.line, x.loc.column, truth_text(truth),
                                    shown.empty() ? "" : " (values: " + shown + ")", x.source));
                } catch (const RunError& e) {
                    problems.push_back(fmt::format("  {}:{}:{}: {}", c->sources.name(x.loc.file), x.loc.line,
                                                   x.loc.column, e.what()));
                }
            }
            if (problems.empty()) {
                ++passed;
                std::cout << fmt::format("test \"{}\" ... ok\n", t.name);
            } else {
                ++failed;
                std::cout << fmt::format("test \"{}\" ... FAILED\n", t.name);
                for (const std::string& p : problems) std::cout << p << "\n";
            }
        }
    }
    if (!prints || any_tests) std::cout << fmt::format("{} passed, {} failed\n", passed, failed);
    if (compile_failed) return front::exit_compile_error;
    return failed ? 1 : 0;
}

} // namespace frac::cli
