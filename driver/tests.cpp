#include "driver/tests.hpp"

#include "ir/semantics.hpp"

namespace frac::driver {

TestOutcome run_test(const front::Module& m, const front::TestInfo& test, const EngineOptions& engine,
                     QueryAnswers& answers) {
    TestOutcome outcome;
    outcome.test = &test;
    for (const front::Expectation& x : test.expects) {
        ExpectationFailure failure;
        failure.expectation = &x;
        try {
            failure.truth = evaluate_closed(m, x.truth, engine, answers, false).enclosure;
            if (failure.truth == ir::tv_true) continue;
            for (ir::NodeId n : x.shown) failure.shown.push_back(evaluate_closed(m, n, engine, answers));
        } catch (const RunError& e) {
            failure.error = e.what();
        }
        outcome.failures.push_back(std::move(failure));
    }
    return outcome;
}

} // namespace frac::driver
