// Box-counting dimension of a boundary from one subdivision (paper sec. 3 reports covers; the slope
// of log N_k against log(split^k) estimates the fractal dimension of the boundary).
//
// N_k is the number of cells of level k that meet the boundary as far as interval evaluation can
// tell: the cells undecided at level k, i.e. the cells of level k that were subdivided or are
// boundary leaves (LevelCounts::undecided). Needs only the per-level counts, so it also works on a
// result computed with keep_cells = false. For a Lipschitz f, interval overestimation widens the
// undecided band by a bounded number of cells, a roughly constant factor on N_k that changes the
// intercept, not the slope.
#pragma once

#include "runtime/cover.hpp"

#include <cstdint>
#include <utility>
#include <vector>

namespace frac::rt {

struct DimensionEstimate {
    double dimension = 0; // least-squares slope of log N_k against k * log(split)
    double r_squared = 0; // coefficient of determination of that fit (1 when all N_k are equal)
    // level, number of cells of that level meeting the boundary (undecided at that level)
    std::vector<std::pair<int, std::uint64_t>> counts;
};

// A lower bound of the same counts: the cells of level k, k < depth, that contain both a cell proven
// inside and a cell proven outside (at some finer level). Such a cell provably meets the boundary
// (f changes sign on it), so these counts never exceed the true N_k, while the undecided counts never
// fall below it. Interval overestimation that grows with the depth (the wrapping of an orbit box
// through a rotation, for instance) thickens the undecided band and biases the first estimate up;
// this one only loses cells that touch the boundary too little to hold a proven cell of each kind.
// Needs a result with keep_cells. Same fit, same exceptions as box_counting.
DimensionEstimate box_counting_proven(const Cover& r, int from_level, int to_level);

// Fits the levels from_level..to_level (inclusive). Throws std::invalid_argument unless
// 0 <= from_level < to_level <= depth, or when some N_k in the range is 0 (no boundary left).
DimensionEstimate box_counting(const Cover& r, int from_level, int to_level);

} // namespace frac::rt
