// A cover: the cells of a grid over a box with their verdicts, at every level of a subdivision
// (level k has split^k cells per axis). Recursive space subdivision produces one (runtime/rss.hpp);
// slices, attractor covers and chaos-game densities are covers too. Pictures, reliefs, slices,
// dimensions and meshes take a Cover, whatever made it.
#pragma once

#include "ir/evaluator.hpp"
#include "numeric/interval.hpp"
#include "support/fill_later.hpp"

#include <cstdint>
#include <vector>

namespace frac::rt {

using num::Interval;

enum class CellClass : std::uint8_t { inside, outside, boundary, subdivided };

// A cell of the cover: level k, integer position ix, iy (and iz) in the split^k grid.
struct Cell {
    std::uint8_t level = 0;
    CellClass cls = CellClass::boundary;
    std::uint32_t ix = 0, iy = 0, iz = 0;
};

// Cells in memory; resize() leaves new cells unwritten (support::FillLater): a subdivision sizes a
// level's cells, then its threads write them.
using CellList = std::vector<Cell, support::FillLater<Cell>>;

struct LevelCounts {
    std::uint64_t evaluated = 0, inside = 0, outside = 0, undecided = 0;
};

struct Cover {
    std::vector<Interval> root; // the root box, one interval per axis
    int depth = 0;              // the deepest level
    int split = 2;              // parts per axis and level
    // The cells, when kept: ordered by level, then within a level by position (iz, then iy, then ix:
    // row-major, x fastest). A leaf is a cell of class inside, outside or boundary.
    CellList cells;
    std::vector<LevelCounts> levels; // index = level, 0..depth
    // Totals over all levels; evaluated = inside + outside + boundary + subdivided.
    std::uint64_t evaluated = 0, inside = 0, outside = 0, boundary = 0, subdivided = 0;

    // Outward enclosure of a cell's box along `axis`: lo = RD(x0 + (x1-x0)*i/n),
    // hi = RU(x0 + (x1-x0)*(i+1)/n), n = split^level, clamped to the root box. Neighbouring cells
    // overlap (or touch) rather than leave gaps. Sets upward rounding itself.
    Interval cell_interval(const Cell& c, int axis) const;
    // Number of axes (2 or 3).
    int dimension() const { return static_cast<int>(root.size()); }
    // split^level: the number of cells per axis at `level`.
    std::uint64_t cells_per_axis(int level) const;
};

// Whether two covers hold the same cells (level, class and position, in the same order), e.g. with
// pruning on and off, or with two engines.
bool same_cover(const Cover& a, const Cover& b);

// The grid of a cover along one axis, shared with the subdivision that evaluates its cells.
namespace grid {
// split^k; exact in 64 bits (and as a double) for split <= 4, k <= 24.
std::uint64_t ipow(int split, int k);
// Enclosure of the grid point x0 + w * j / n of an axis, w enclosing x1 - x0. Requires upward
// rounding. j and n are below 2^53, hence exact doubles.
Interval point(Interval axis, Interval w, std::uint64_t j, std::uint64_t n);
// Outward box of cell i of n along an axis. Requires upward rounding. The end points shared by
// neighbours are computed by the same expression, so hi(cell i) >= lo(cell i+1): no gaps. Clamping
// to the root keeps the enclosure (the exact grid points lie in the root) and makes the outer
// cells end exactly on the root's bounds.
Interval cell(Interval axis, Interval w, std::uint64_t i, std::uint64_t n);
// Enclosure of the root's width along an axis. Requires upward rounding.
Interval width(Interval axis);
// The cells of a level with n cells per axis over `root` (2 or 3 axes) into `out`, for
// Evaluator::eval_cells: entry i of axis a is cell(root[a], width(root[a]), i, n), each grid point
// computed once (into `points`, the caller's scratch). Sets upward rounding itself.
void level_cells(const std::vector<Interval>& root, std::uint64_t n, ir::CellGrid& out,
                 std::vector<Interval>& points);
} // namespace grid

} // namespace frac::rt
