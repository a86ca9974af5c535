// Recursive space subdivision (RSS, paper sec. 2.2): classify boxes as inside (f < 0 on the whole
// box), outside (f > 0) or undecided, subdividing undecided boxes down to a depth limit. The
// undecided boxes at the deepest level form the cover of the boundary.
//
// Classification of a cell from the enclosure [lo, hi] of f over its box:
//  - hi < 0                      -> inside   (f < 0 everywhere on the box)
//    or, with RssOptions::closed_inside, hi <= 0 -> inside (the closed cell lies in the closed solid
//    {f <= 0}; it may touch the boundary, so this rule is for solids, not for boundary covers)
//  - lo > 0                      -> outside  (f > 0 everywhere on the box)
//  - empty enclosure (lo > hi)   -> outside: f is undefined on the whole box (e.g. sqrt of a
//                                   negative number), so no point of the box satisfies f < 0 or
//                                   f = 0, and the box holds neither the shape nor its boundary.
//  - anything else, including a NaN bound (which the numeric core never produces, but a backend
//    might) -> undecided: subdivided below `depth`, a `boundary` cell at `depth`. Undecided is
//    always the safe answer: the cover may be too large, never too small.
//
// The root is level 0; level k has split^k cells per axis. Cells are evaluated level by level
// (breadth first) through the batch API Evaluator::eval_boxes.
#pragma once

#include "ir/evaluator.hpp"
#include "runtime/cover.hpp"
#include "runtime/limits.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace frac::rt {

// Called after each completed level and, during a long level, after a batch when at least a second
// has passed since the previous call. `level` is the level being evaluated, `evaluated` the number
// of cells evaluated so far over all levels.
using RssProgress = std::function<void(int level, std::uint64_t evaluated)>;

// Min/max pruning (ir/specialize.hpp, switched by EvalOptions::prune): an undecided cell at least
// RssOptions::prune_min_remaining levels above the depth limit asks its evaluator for a simplified
// function, which its descendants then evaluate, and which they simplify further in turn (the tapes
// shrink down the tree). The evaluator's rule says whether it pays for the expected descendants. The
// cover is the same with and without it (docs/design.md, "Pruning"). The default, 1 (every level
// with children), measured on bench/bench_large.cpp and bench/csg_scene.frac (docs/performance.md).
inline constexpr int default_prune_min_remaining = 1;

struct RssOptions {
    int depth = 8; // levels of subdivision below the root box
    // The most levels allowed; 0: max_depth_2d or max_depth_3d. Above them, only split^depth <= 2^32
    // bounds it (the CLI's FRAC_MAX_DEPTH; max_cells bounds the memory).
    int max_depth = 0;
    int split = 2;          // parts per axis and level
    bool keep_cells = true; // record every evaluated cell (for pictures); false keeps only counts
    // Cells per eval_boxes call (>= 1); once cells prune, a batch ends before the children of a parent
    // row it would cut (a parent's children stay together). With several threads a batch holds this
    // many cells per thread, cut into chunks. Each batch costs a hand-over and a wait; with 4096 they
    // took 3-4% of a depth-12 carpet cover on two threads (docs/performance.md).
    std::size_t batch = 16384;
    RssProgress progress; // optional
    // Threads evaluating each batch (0: all cores). Each thread has its own clone of the evaluator,
    // and results are placed by cell position, so the output is the same for every thread count.
    int threads = 1;
    // Inside means hi <= 0 instead of hi < 0: the cell is proven to lie in the closed solid {f <= 0}.
    // For meshes of solids (cells whose faces lie on the solid's boundary are inside); boundary covers
    // (pictures, dimension) keep the default, since a cell with hi = 0 may hold boundary points.
    bool closed_inside = false;
    // Most cells evaluated (and, with keep_cells, kept in memory); 0: no limit. The run refuses before
    // a level that would pass it, and as soon as the growth of the last level foretells that the depth
    // would pass it (a LimitError, with the estimate).
    std::uint64_t max_cells = 0;
    // Levels above the depth limit (at least) where undecided cells ask for a pruned function.
    int prune_min_remaining = default_prune_min_remaining;
};

// The default of the command line's --max-cells: 2^27 cells, about 2 GB kept (16 bytes a cell, and the
// frontier of undecided cells beside them) and a few seconds to a minute of evaluation.
inline constexpr std::uint64_t default_max_cells = std::uint64_t{1} << 27;

// The stack of the worker threads that evaluate cells (address space only: pages are touched as used).
// Generated code keeps its spilled values on the stack: 4 MB of them for a tape of 38,000 instructions
// compiled with LLVM's fast machine code generation, which overflowed TBB's default. A cover asks for
// it while it runs (tbb::global_control), which reaches the workers TBB starts then; a program whose
// other parallel work may start them first (the CLI) asks for it from the start.
inline constexpr std::size_t worker_stack_bytes = std::size_t{256} << 20;

// Default limits of the depth, reported as errors when exceeded (RssOptions::max_depth raises them).
// Besides, split^depth must not exceed 2^32 (cell positions are 32-bit): with split 3 the depth is at
// most 20, with split 4 at most 16.
inline constexpr int max_depth_2d = 24;
inline constexpr int max_depth_3d = 14;

// What pruning did on one level.
struct PruneLevel {
    std::uint64_t requests = 0;           // undecided cells that asked their evaluator for a pruned function
    std::uint64_t pruned = 0;             // ... and got one, for their children
    std::uint64_t pruned_evaluations = 0; // cells of the level evaluated with a pruned function
    double instructions = 0;              // instructions of the functions evaluated, summed over the cells
};

// A subdivision's cover (depth and split from its options) with what the run measured.
struct RssResult : Cover {
    RssOptions options;
    double seconds = 0; // wall time of subdivide (steady clock)
    // Pruning: cells evaluated with a simplified function, and how many distinct functions they used.
    std::uint64_t pruned_evaluations = 0;
    std::size_t specializations = 0;
    std::vector<PruneLevel> prune_levels; // index = level, 0..depth
};

// Throws std::invalid_argument on a bad depth/split/batch or a box of the wrong dimension (the
// root must have 2 or 3 axes, as many as f.dimension(), each finite with lo < hi).
RssResult subdivide(ir::Evaluator& f, const std::vector<Interval>& root, const RssOptions& options);

} // namespace frac::rt
