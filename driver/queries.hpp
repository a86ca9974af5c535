// The run-time questions of tests and print statements: answering the queries a model's tests ask
// of its shapes (enclose, dimension) and evaluating the closed expressions that read the answers.
#pragma once

#include "driver/engines.hpp"
#include "frontend/module.hpp"
#include "ir/tape.hpp"

#include <optional>
#include <vector>

namespace frac::driver {

// Answers, by query index, computed once per model and reused by every expression that reads them.
using QueryAnswers = std::vector<std::optional<ir::Interval>>;

// Runs the model's queries that `tape` reads (caching them in `answers`) and returns the tape's inputs.
// Throws RunError when a query cannot be answered.
std::vector<ir::Interval> answer_queries(const front::Module& m, const ir::Tape& tape,
                                         const EngineOptions& options, QueryAnswers& answers);

// The similarity dimension of an automaton as a proven bracket (RunError when a map on a cycle is not a
// similitude).
ir::Interval automaton_dimension(const front::AutomatonInfo& a);

// A closed expression (one that reads only query answers): its enclosure, and its point value when it
// has one. An expression that reads an enclosure (enclose(s, B)) has none: the midpoint of the
// enclosure would pose as one.
struct ClosedValue {
    ir::Interval enclosure;
    std::optional<double> point;
};
// `with_point`: also its point value (a truth value needs only its enclosure).
ClosedValue evaluate_closed(const front::Module& m, ir::NodeId node, const EngineOptions& engine,
                            QueryAnswers& answers, bool with_point = true);

} // namespace frac::driver
