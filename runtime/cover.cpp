#include "runtime/cover.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <stdexcept>

namespace frac::rt {

namespace grid {

std::uint64_t ipow(int split, int k) {
    std::uint64_t n = 1;
    for (int i = 0; i < k; ++i) n *= static_cast<std::uint64_t>(split);
    return n;
}

Interval point(Interval axis, Interval w, std::uint64_t j, std::uint64_t n) {
    const Interval jd(static_cast<double>(j)), nd(static_cast<double>(n));
    Interval t = num::div(num::mul(w, jd), nd);
    // Past the largest double w * j overflows (a box wider than about 1e308 / n): divide first.
    if (!std::isfinite(t.hi)) t = num::mul(num::div(w, nd), jd);
    return num::add(Interval(axis.lo), t);
}

namespace {

// Cell i of n along `axis`: from grid point i to grid point i + 1 (point(j) their enclosures, taken
// outward), clamped to the axis, whose ends are exact.
template <class Point>
Interval cell_between(Interval axis, std::uint64_t i, std::uint64_t n, Point&& point) {
    return {i == 0 ? axis.lo : std::max(axis.lo, point(i).lo),
            i + 1 >= n ? axis.hi : std::min(axis.hi, point(i + 1).hi)};
}

} // namespace

Interval cell(Interval axis, Interval w, std::uint64_t i, std::uint64_t n) {
    return cell_between(axis, i, n, [&](std::uint64_t j) { return point(axis, w, j, n); });
}

Interval width(Interval axis) {
    return num::sub(Interval(axis.hi), Interval(axis.lo));
}

void level_cells(const std::vector<Interval>& root, std::uint64_t n, ir::CellGrid& out,
                 std::vector<Interval>& points) {
    num::UpwardRounding up;
    const std::size_t d = root.size(), m = static_cast<std::size_t>(n) + 1;
    points.resize(d * m);
    for (std::size_t a = 0; a < d; ++a) {
        const Interval w = grid::width(root[a]);
        for (std::size_t j = 0; j < m; ++j) points[a * m + j] = grid::point(root[a], w, j, n);
    }
    const std::uint64_t cells[3] = {n, n, n};
    out.assign(static_cast<int>(d), cells, [&](int a, std::uint64_t i) {
        const auto ax = static_cast<std::size_t>(a);
        const Interval* p = &points[ax * m];
        return cell_between(root[ax], i, n, [p](std::uint64_t j) { return p[j]; });
    });
}

} // namespace grid

std::uint64_t Cover::cells_per_axis(int level) const {
    return grid::ipow(split, level);
}

Interval Cover::cell_interval(const Cell& c, int axis) const {
    if (axis < 0 || axis >= dimension())
        throw std::out_of_range(fmt::format("cell_interval: axis {} of a {}D box", axis, dimension()));
    const std::uint32_t i = axis == 0 ? c.ix : axis == 1 ? c.iy : c.iz;
    const Interval x = root[static_cast<std::size_t>(axis)];
    num::UpwardRounding up;
    return grid::cell(x, grid::width(x), i, cells_per_axis(c.level));
}

bool same_cover(const Cover& a, const Cover& b) {
    return std::equal(
        a.cells.begin(), a.cells.end(), b.cells.begin(), b.cells.end(), [](const Cell& x, const Cell& y) {
            return x.level == y.level && x.cls == y.cls && x.ix == y.ix && x.iy == y.iy && x.iz == y.iz;
        });
}

} // namespace frac::rt
