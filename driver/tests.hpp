// Test blocks: every expectation of a test evaluated to a proven truth value (frac test). The
// commands print the outcomes.
#pragma once

#include "driver/queries.hpp"

#include <string>
#include <vector>

namespace frac::driver {

struct ExpectationFailure {
    const front::Expectation* expectation = nullptr;
    ir::Interval truth;             // not proven true: false, unknown (both) or empty (undefined)
    std::vector<ClosedValue> shown; // the values the expectation compares
    std::string error;              // not empty when a query could not be answered (RunError)
};

struct TestOutcome {
    const front::TestInfo* test = nullptr;
    std::vector<ExpectationFailure> failures; // empty: passed
    bool passed() const { return failures.empty(); }
};

TestOutcome run_test(const front::Module& m, const front::TestInfo& test, const EngineOptions& engine,
                     QueryAnswers& answers);

} // namespace frac::driver
