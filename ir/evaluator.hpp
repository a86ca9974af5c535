// The interface every backend implements (interpreter, LLVM JIT). The runtime sees compiled shapes
// only through it, so every algorithm runs with every engine.
#pragma once

#include "numeric/interval.hpp"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace frac::ir {

using num::Interval;

// Limits every engine honours.
struct EvalOptions {
    // Most terms summed of an infinite series before its tail bound takes over (sound either way).
    int max_terms = 128;
    // Stop a series when the box is too wide for further terms to resolve anything (see
    // docs/design.md). Off: sum until the tail is negligible or max_terms (for measurements).
    bool adaptive_terms = true;
    // Min/max pruning per region (Evaluator::specialize, ir/specialize.hpp). Off: specialize()
    // returns null, every box evaluates the whole function (`--prune=off`).
    bool prune = true;
};
inline constexpr int max_terms_limit = 100000;

// Counters an evaluator keeps (reset by the caller when it wants per-run numbers).
struct EvalStats {
    std::uint64_t calls = 0;         // point or box evaluations
    std::uint64_t series_terms = 0;  // series terms evaluated in total
    std::uint64_t series_capped = 0; // series stopped by the term limit, not by resolution

    EvalStats& operator+=(const EvalStats& o);
};

// What min/max pruning did (ir/specialize.hpp), counted by the evaluator that was asked.
struct SpecializeStats {
    std::uint64_t requests = 0;   // specialize() calls that recorded choices over a box
    std::uint64_t unpruned = 0;   // ... where nothing could be pruned
    std::uint64_t too_little = 0; // ... where pruning saved less than the rule asks
    std::uint64_t declined = 0;   // ... where compiling would cost more than it saves (or the cache is full)
    std::uint64_t hits = 0;       // ... answered by an already compiled specialisation
    std::uint64_t compiled = 0;   // ... that compiled a new one (machine code)
    std::uint64_t pushes = 0;     // ... that made a pruned tape the interpreter runs (no compile)
    std::uint64_t fallbacks = 0;  // ... that made a second-tier (interpreted) one, no compile
    double compile_ms = 0;        // time spent compiling them (machine code; 0 for the interpreter)
    double record_ms = 0;         // time spent recording choices
    double prune_ms = 0;          // time spent building pruned tapes (ir::specialize, the rule)

    SpecializeStats& operator+=(const SpecializeStats& o);
};

class Evaluator {
public:
    virtual ~Evaluator() = default;

    // Number of coordinates the shape takes (2 or 3; 0 for a closed expression).
    virtual int dimension() const = 0;
    // Name of the engine ("interp", "jit").
    virtual std::string engine() const = 0;

    // Value at a point (round to nearest; series summed until their tail is below an ulp).
    virtual double eval_point(const double* coords) = 0;
    // Guaranteed enclosure of the values over a box: contains f(p) for every p in the box.
    // Sets upward rounding itself.
    virtual Interval eval_box(const Interval* box) = 0;

    // Batches: `coords` / `boxes` hold n consecutive groups of dimension() values.
    virtual void eval_points(const double* coords, std::size_t n, double* out);
    virtual void eval_boxes(const Interval* boxes, std::size_t n, Interval* out);

    // An independent evaluator of the same function, for use on another thread.
    virtual std::unique_ptr<Evaluator> clone() const = 0;

    // Min/max pruning: records which operands the min/max/select instructions take over `box` and,
    // when the rule of ir/specialize.hpp says it pays for about `expected_evaluations` evaluations
    // of sub-boxes, returns an evaluator of the simplified function, valid on every sub-box of
    // `box` (shared and cached: clone it for another thread). Null when nothing is pruned, when it
    // would not pay, or when the engine does not specialise.
    virtual std::shared_ptr<Evaluator> specialize(const Interval* box, double expected_evaluations);
    // specialize() for box k of this evaluator's last evaluation (eval_box: k = 0; eval_boxes: box k
    // of its batch): an engine that keeps the values of its last kept_evaluations() boxes records
    // the choices from them instead of evaluating again.
    virtual std::shared_ptr<Evaluator> specialize_after_eval(std::size_t k, const Interval* box,
                                                             double expected_evaluations) {
        return specialize(box, expected_evaluations);
    }
    // How many boxes of its last evaluation (the first ones of a batch) an evaluator keeps the values
    // of for specialize_after_eval: a caller that prunes evaluates in batches of this size.
    virtual std::size_t kept_evaluations() const { return 0; }
    // False when specialize() returns null whatever it is asked (nothing to prune, pruning off, an
    // engine that does not specialise): callers skip asking per cell.
    virtual bool may_specialize() const { return false; }
    // Whether specialize() depends only on this evaluator's function and the box, not on a state
    // shared with its clones (a cache filled in the order of requests): then a cover asks on every
    // thread at once, and the answers do not depend on which thread asked first.
    virtual bool specializes_independently() const { return false; }

    // A point of the caller's work that depends neither on threads nor on timing: a cover calls it on
    // each of its evaluators at the start of every level, with the cells evaluated so far. A tiered
    // evaluator whose two engines' bits may differ changes engine only here (backend/llvm/tiered.hpp),
    // so that the output does not depend on when its compile finished.
    virtual void checkpoint(std::uint64_t evaluated) {}
    // Instructions of the function this evaluator computes (its tape).
    virtual std::size_t instruction_count() const { return 0; }

    EvalStats stats;
    SpecializeStats specialize_stats;
};

} // namespace frac::ir
