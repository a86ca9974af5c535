// The interface every backend implements (interpreter, LLVM JIT). The runtime sees compiled shapes
// only through it, so every algorithm runs with every engine.
#pragma once

#include "numeric/interval.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

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
    std::uint64_t hits = 0;       // ... answered by an existing one (compiled, or a sibling's pushed tape)
    std::uint64_t compiled = 0;   // ... that compiled a new one (machine code)
    std::uint64_t pushes = 0;     // ... that made a pruned tape the interpreter runs (no compile)
    std::uint64_t fallbacks = 0;  // ... that made a second-tier (interpreted) one, no compile
    double compile_ms = 0;        // time spent compiling them (machine code; 0 for the interpreter)
    double record_ms = 0;         // time spent recording choices
    double prune_ms = 0;          // time spent building pruned tapes (ir::specialize, the rule)

    SpecializeStats& operator+=(const SpecializeStats& o);
};

// What a cover concludes of a cell from the enclosure [lo, hi] of f over its box (runtime/rss.hpp):
//  - hi < 0, or hi <= 0 with closed_inside               -> inside
//  - lo > 0, or an empty enclosure (f undefined on the box) -> outside
//  - anything else, including a NaN bound                -> undecided (the safe answer)
// The NaN test comes first because an interval with a NaN bound also looks empty (!(lo <= hi)).
enum class CellVerdict : std::uint8_t { inside = 0, outside = 1, undecided = 2 };

inline CellVerdict classify(Interval z, bool closed_inside) {
    if (std::isnan(z.lo) || std::isnan(z.hi)) return CellVerdict::undecided;
    if (z.lo > z.hi) return CellVerdict::outside;
    if (z.hi < 0 || (closed_inside && z.hi <= 0)) return CellVerdict::inside;
    if (z.lo > 0) return CellVerdict::outside;
    return CellVerdict::undecided;
}

// The cells of one level of a regular grid, for Evaluator::eval_cells: per axis, the interval of each
// cell along it; cell (i, j, k) is the box axis(0)[i] x axis(1)[j] x axis(2)[k]. Filled once per level
// (the storage is kept from one fill to the next), then read by any number of threads.
class CellGrid {
public:
    // `dimension` axes (1 to 3) of cells[a] cells each (at most 2^32: coordinates are 32-bit); entry i
    // of axis a is fill(a, i). Throws std::invalid_argument for a dimension or a count out of range.
    template <class Fill>
    void assign(int dimension, const std::uint64_t* cells, Fill&& fill) {
        check_shape(dimension, cells);
        dimension_ = dimension;
        nonempty_ = true;
        for (int a = 0; a < dimension; ++a) {
            std::vector<Interval>& axis = axes_[a];
            axis.resize(static_cast<std::size_t>(cells[a]));
            for (std::size_t i = 0; i < axis.size(); ++i) {
                axis[i] = fill(a, static_cast<std::uint64_t>(i));
                nonempty_ &= axis[i].lo <= axis[i].hi;
            }
        }
    }

    int dimension() const { return dimension_; }
    std::size_t cells(int axis) const { return axes_[axis].size(); }
    const Interval* axis(int a) const { return axes_[a].data(); }
    // Every entry is a non-empty interval (lo <= hi, no NaN bound), hence so is every cell's box.
    bool nonempty() const { return nonempty_; }
    // The box of the cell at `coords` (one coordinate per axis, in range).
    void box(const std::uint32_t* coords, Interval* out) const {
        for (int a = 0; a < dimension_; ++a) out[a] = axes_[a][coords[a]];
    }
    // Throws std::invalid_argument unless the grid has `dimension` axes and stride >= dimension, and
    // std::out_of_range unless the coordinates of the n cells coords[k * stride + a] are in range.
    void check(int dimension, const std::uint32_t* coords, std::size_t stride, std::size_t n) const;

private:
    static void check_shape(int dimension, const std::uint64_t* cells);
    int dimension_ = 0;
    bool nonempty_ = false;
    std::vector<Interval> axes_[3];
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
    // The verdicts of n cells of a grid: out[k] = classify(enclosure over the box of cell k), where
    // cell k has the coordinates coords[k * stride + a] (a < dimension()). The same evaluations, bits
    // and counters as eval_boxes on the cells' boxes; an engine may build the boxes and classify in its
    // own code (the JIT), the default builds them here and calls eval_boxes. Throws as
    // CellGrid::check does.
    virtual void eval_cells(const CellGrid& grid, const std::uint32_t* coords, std::size_t stride,
                            std::size_t n, CellVerdict* out, bool closed_inside);

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
    // False when specialize(box, expected_evaluations) returns null for every box as things stand (a
    // rule that depends only on the tape and the expected evaluations, or an engine not ready to
    // prune): a cover asks once per level and then skips its cells' requests.
    virtual bool may_specialize_now(double expected_evaluations) { return may_specialize(); }
    // Whether specialize() depends only on this evaluator's function and the box, not on a state
    // shared with its clones (a cache filled in the order of requests): then a cover asks on every
    // thread at once, and the answers do not depend on which thread asked first.
    virtual bool specializes_independently() const { return false; }

    // A point of the caller's work that depends neither on threads nor on timing: a cover calls it on
    // each of its evaluators at the start of every level, with the cells evaluated so far. A tiered
    // evaluator whose two engines' bits may differ changes engine only here (backend/llvm/tiered.hpp),
    // so that the output does not depend on when its compile finished.
    virtual void checkpoint(std::uint64_t evaluated) {}
    // The evaluations the caller foresees asking of this evaluator and its clones from now on (a cover:
    // at the start of a level, the cells to its depth as the frontier's growth foretells them). A tiered
    // evaluator that waits before it compiles (a long tape) compiles when that work would repay it,
    // and no longer by the time it has interpreted.
    virtual void foresee(double evaluations) {}
    // Instructions of the function this evaluator computes (its tape).
    virtual std::size_t instruction_count() const { return 0; }

    EvalStats stats;
    SpecializeStats specialize_stats;
};

} // namespace frac::ir
