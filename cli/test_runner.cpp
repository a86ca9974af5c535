// frac test / frac run: print statements and test blocks.
#include "cli/commands.hpp"

#include "driver/tests.hpp"
#include "ir/semantics.hpp"

#include <cmath>
#include <fmt/format.h>
#include <iostream>

namespace frac::cli {

namespace {

std::string truth_text(ir::Interval t) {
    if (t == ir::tv_true) return "true";
    if (t == ir::tv_false) return "false";
    if (t.is_empty()) return "undefined";
    return "unknown";
}

std::string value_text(const driver::ClosedValue& v) {
    if (v.enclosure.is_thin()) return fmt::format("{}", v.enclosure.lo);
    if (v.enclosure.is_empty()) return "empty";
    // A point value that is no number (inf / inf in a constant) tells nothing beyond the enclosure.
    if (!v.point || std::isnan(*v.point)) return format_interval(v.enclosure);
    return fmt::format("{} in {}", *v.point, format_interval(v.enclosure));
}

// One print statement's line on stdout.
void run_print(const front::Module& m, const front::PrintInfo& p, const EngineOptions& engine,
               driver::QueryAnswers& answers) {
    switch (p.kind) {
    case front::ValueKind::interval: std::cout << format_interval(p.box[0]) << "\n"; break;
    case front::ValueKind::box: {
        std::string s;
        for (std::size_t i = 0; i < p.box.size(); ++i) s += (i ? " × " : "") + format_interval(p.box[i]);
        std::cout << s << "\n";
        break;
    }
    case front::ValueKind::boolean:
        std::cout << truth_text(driver::evaluate_closed(m, p.nodes[0], engine, answers, false).enclosure)
                  << "\n";
        break;
    case front::ValueKind::scalar:
    case front::ValueKind::point: {
        std::string s;
        for (std::size_t i = 0; i < p.nodes.size(); ++i) {
            const driver::ClosedValue v = driver::evaluate_closed(m, p.nodes[i], engine, answers);
            s += (i ? ", " : "") + value_text(v);
        }
        std::cout << (p.kind == front::ValueKind::point ? "(" + s + ")" : s) << "\n";
        break;
    }
    }
}

// Runs every print statement; one that cannot be done (a dimension the automaton does not allow, a
// limit) is reported at the statement, with its line and a caret, and the others still run. Returns
// whether all were done.
bool run_prints(const front::Compilation& c, const EngineOptions& engine, driver::QueryAnswers& answers) {
    front::Diagnostics failures;
    for (const front::PrintInfo& p : c.module.prints) {
        try {
            run_print(c.module, p, engine, answers);
        } catch (const driver::RunError& e) {
            failures.error(p.loc, e.what());
        }
    }
    if (!failures.has_errors()) return true;
    std::cout.flush();
    std::cerr << failures.render(c.sources);
    return false;
}

} // namespace

int run_tests(const std::vector<std::string>& files, bool prints, const EngineOptions& engine) {
    int passed = 0, failed = 0;
    bool compile_failed = false, any_tests = false, print_failed = false;
    for (const std::string& file : files) {
        auto c = compile_or_report(file);
        if (!c) {
            compile_failed = true;
            continue;
        }
        driver::QueryAnswers answers;
        if (prints && !run_prints(*c, engine, answers)) print_failed = true;
        for (const front::TestInfo& t : c->module.tests) {
            any_tests = true;
            const driver::TestOutcome outcome = driver::run_test(c->module, t, engine, answers);
            if (outcome.passed()) {
                ++passed;
                std::cout << fmt::format("test \"{}\" ... ok\n", t.name);
                continue;
            }
            ++failed;
            std::cout << fmt::format("test \"{}\" ... FAILED\n", t.name);
            for (const driver::ExpectationFailure& f : outcome.failures) {
                const front::Expectation& x = *f.expectation;
                const std::string where =
                    fmt::format("  {}:{}:{}: ", c->sources.name(x.loc.file), x.loc.line, x.loc.column);
                if (!f.error.empty()) {
                    std::cout << where << f.error << "\n";
                    continue;
                }
                std::string shown;
                for (const driver::ClosedValue& v : f.shown)
                    shown += (shown.empty() ? "" : ", ") + value_text(v);
                std::cout << fmt::format("{}expectation is {}{}\n    {}\n", where, truth_text(f.truth),
                                         shown.empty() ? "" : " (values: " + shown + ")", x.source);
            }
        }
    }
    if (!prints || any_tests) std::cout << fmt::format("{} passed, {} failed\n", passed, failed);
    if (compile_failed) return front::exit_compile_error;
    return failed || print_failed ? 1 : 0;
}

} // namespace frac::cli
