// Min/max pruning per region (libfive's tape push, Fidget's simplify-and-recompile): when an interval
// evaluation over a box proves that a min, max, and, or picks one operand everywhere in the box (their
// enclosures do not overlap), or that the condition of a select is decided, the sub-boxes evaluate a
// tape where that instruction is replaced by the operand it picks, and the code only the other
// operand needed is gone.
//
// Soundness and identity (docs/design.md, "Pruning"):
//  - Only instructions of block 0 (run once per evaluation) are pruned; a choice inside a series block
//    would have to hold for terms the parent box never evaluated.
//  - A choice is taken only when the dropped operand (the select's condition) cannot become empty on
//    a sub-box: every partial operation (sqrt, log, div, pow) it depends on had its argument inside
//    the domain over the whole box. An empty operand would make min/max empty, and the pruned tape
//    would not.
//  - Given inclusion isotone enclosures (a sub-box's enclosure lies in the box's), the pruned tape
//    computes bit for bit what the full tape computes on every sub-box; without it (a series whose
//    adaptive term count changes), it is still a guaranteed enclosure of the same function.
#pragma once

#include "ir/evaluator.hpp"
#include "ir/semantics.hpp"
#include "ir/tape.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace frac::ir {

// Which operand a choice instruction takes over a box. For min/max/and/or: first = in[0],
// second = in[1]; for select: first = the then-value (in[1]), second = the else-value (in[2]).
enum class Choice : std::uint8_t { both, first, second };

// Min, Max, And, Or, Select.
inline bool is_choice(Op op) {
    return op == Op::Min || op == Op::Max || op == Op::And || op == Op::Or || op == Op::Select;
}
// Whether block 0 of the tape has a choice instruction (else nothing can ever be pruned).
bool has_choices(const Tape& tape);

// Whether operation `op` (arguments a, b; imm its immediate) is defined on every sub-box of a box
// over which its arguments have these enclosures (partial operations: div, sqrt, log, pow, powi).
bool defined_over_box(Op op, Interval a, Interval b, std::int64_t imm);

// The choice a min/max/and/or/select makes over a box where its operands (select: the condition
// and the then-value) have the enclosures a and b; `x_may_empty`: that operand's enclosure can be
// empty on a sub-box (it is then never dropped, nor a select decided by it).
// Inline: tape pushes call it for every choice of the live code.
inline Choice decide_choice(Op op, Interval a, Interval b, bool a_may_empty, bool b_may_empty) {
    // Enclosures that are empty or NaN decide nothing.
    const auto usable = [](Interval v) { return !v.is_empty() && !std::isnan(v.lo) && !std::isnan(v.hi); };
    if (!usable(a) || !usable(b)) return Choice::both;
    // The dropped operand must not become empty below (it would empty the result).
    const bool keep_a = !b_may_empty, keep_b = !a_may_empty;
    // Min and max need disjoint operands: where they touch, the result's bounds could be a 0 of
    // the other operand's sign. On truth values (exactly 0 or 1) and is min and or is max, and
    // false decides an and, true an or, whatever the other operand.
    switch (op) {
    case Op::Min:
        if (b.hi < a.lo && keep_b) return Choice::second;
        if (a.hi < b.lo && keep_a) return Choice::first;
        return Choice::both;
    case Op::And:
        if (a.hi <= b.lo && keep_a) return Choice::first;
        if (b.hi <= a.lo && keep_b) return Choice::second;
        return Choice::both;
    case Op::Max:
        if (b.lo > a.hi && keep_b) return Choice::second;
        if (a.lo > b.hi && keep_a) return Choice::first;
        return Choice::both;
    case Op::Or:
        if (a.lo >= b.hi && keep_a) return Choice::first;
        if (b.lo >= a.hi && keep_b) return Choice::second;
        return Choice::both;
    case Op::Select: // a is the condition
        if (a_may_empty) return Choice::both;
        if (a == tv_true) return Choice::first;
        if (a == tv_false) return Choice::second;
        return Choice::both;
    default: return Choice::both;
    }
}

// The choices of the block-0 instructions (one entry per instruction of tape.blocks[0], `both` for
// any other) after an interval evaluation of `tape` over a box; `slots` is the evaluator's register
// file (indexed by slot) after that evaluation, so it holds every block-0 value for the box.
std::vector<Choice> record_choices(const Tape& tape, const Interval* slots);

// Whether any entry is decided.
bool any_decided(const std::vector<Choice>& choices);

// The tape with each decided choice of block 0 replaced by the operand it takes, the code no longer
// needed removed (series included) and the slots renumbered densely in program order, so two ways
// of pruning to the same function give the same tape. When that tape would cost (tape_cost) more
// than `max_cost`, returns an empty tape (no blocks) without copying the code. Throws
// std::invalid_argument on a choices vector of the wrong size.
Tape specialize(const Tape& tape, const std::vector<Choice>& choices,
                double max_cost = std::numeric_limits<double>::infinity());

// A byte string identifying a tape exactly (the cache key of compiled specialisations).
std::string tape_key(const Tape& tape);

// Relative cost of one box evaluation: block-0 instructions count once, the instructions of a series
// block `series_terms_estimate` times (per level of nesting).
inline constexpr double series_terms_estimate = 8;
double tape_cost(const Tape& tape);

// What an engine's specialisation costs and saves, measured by bench/bench_prune.cpp (the constants
// are in each engine; docs/performance.md has the measurements).
struct PruneCosts {
    double eval_ns_per_cost = 1;           // evaluation time per unit of tape_cost, per box
    double compile_ns_fixed = 0;           // compiling a specialised tape: fixed part ...
    double compile_ns_per_instruction = 0; // ... and per instruction of the pruned tape
    // Time per evaluation in a cover apart from the tape's instructions (the call, the cell's box,
    // its verdict), in the unit of eval_ns_per_cost: what a short pruned tape cannot save.
    double eval_ns_fixed = 0;
};
// Time per evaluation in a cover of a tape of cost `cost`.
inline double eval_ns(const PruneCosts& c, double cost) {
    return c.eval_ns_fixed + c.eval_ns_per_cost * cost;
}

// The rule (docs/design.md). A pruned tape is used when
//   cost(pruned) <= max_cost_ratio * cost(current),
// and it is compiled once the evaluations asked for it (the sum of expected_evaluations over every
// request for that same tape, compiled or not: the cache remembers the demand) would save more
// than compiling it costs:
//   demand * eval_ns_per_cost * (cost(current) - cost(pruned)) >= compile_ns_fixed
//                                             + compile_ns_per_instruction * instructions(pruned).
// Until then an engine with a cheaper second tier (the JIT: the interpreter, no compile time) uses
// it when that evaluates the pruned tape faster, in a cover, than the engine evaluates the current one:
//   fallback_eval_ns(pruned) < eval_ns(costs, cost(current)),
// the fallback's time including its fixed part per evaluation (and its own pushes below).
inline constexpr double max_cost_ratio = 0.9;
// The rule of an engine that runs a pruned tape without compiling it (the interpreter, and the
// JIT's second tier): a tape push pays when the expected evaluations of the sub-boxes save more than
// building the pruned tape costs, about `push_build_evaluations` evaluations of the current tape
// (bench/bench_large.cpp measures it):
//   expected_evaluations * (cost(current) - cost(pruned)) >= push_build_evaluations * cost(current),
// and cost(pruned) < cost(current): the most a pruned tape may cost is push_max_cost.
inline constexpr double push_build_evaluations = 2;
double push_max_cost(double cost_current, double expected_evaluations);

// Compiled specialisations one evaluator family keeps; past it, new ones are declined.
inline constexpr std::size_t max_specializations = 512;

// The specialisations of one evaluator family (an evaluator, its clones and its specialisations):
// compiled once per distinct pruned tape, shared by all. Thread-safe.
class SpecializationCache {
public:
    using Compile = std::function<std::unique_ptr<Evaluator>(const Tape&)>;
    using CostOf = std::function<double(const Tape&)>;
    // `fallback` (optional) makes the second tier's evaluator of a tape, whose results are the
    // engine's bit for bit; `fallback_eval_ns` gives its time per evaluation of a tape in a cover
    // (the interpreter's depends on the tape: flat or not; the least of it is an empty tape's);
    // without them the fallback is never used.
    SpecializationCache(Compile compile, PruneCosts costs, Compile fallback = {},
                        CostOf fallback_eval_ns = {})
        : compile_(std::move(compile)), fallback_(std::move(fallback)), costs_(costs),
          fallback_eval_ns_(std::move(fallback_eval_ns)),
          fallback_ns_fixed_(fallback_eval_ns_ ? fallback_eval_ns_(Tape{}) : 0) {}

    // Whether recording the choices over a box of a tape of cost `cost_current`, which costs
    // `record_ns` (in the unit of eval_ns_per_cost), can pay at all for a cell with
    // `expected_evaluations` descendant evaluations: the best a pruned tape could save them (an empty
    // one, compiled for this demand alone or run by the fallback, whose fixed part stays) is more than
    // the recording, or a compiled specialisation exists already (the recording may find it). Where
    // none holds every request would be declined after its recording was paid for: short tapes, whose
    // evaluation by the JIT is mostly its fixed part.
    bool may_pay(double cost_current, double expected_evaluations, double record_ns) const;

    // Applies the rule to the choices recorded on `current`'s box; returns the specialised evaluator
    // (shared: clone it for another thread) or null. Counts what happened in `stats`.
    std::shared_ptr<Evaluator> get(const Tape& current, const std::vector<Choice>& choices,
                                   double expected_evaluations, SpecializeStats& stats);

    const PruneCosts& costs() const { return costs_; }
    std::size_t size() const;

private:
    struct Entry {
        std::shared_ptr<Evaluator> compiled, fallback;
        double demand = 0; // expected evaluations asked for so far
    };
    Compile compile_, fallback_;
    PruneCosts costs_;
    CostOf fallback_eval_ns_;
    double fallback_ns_fixed_; // fallback_eval_ns_ of an empty tape
    mutable std::mutex mu_;    // held while compiling, so no tape is compiled twice
    std::map<std::string, Entry> entries_;
    std::size_t compiled_count_ = 0;
};

} // namespace frac::ir
