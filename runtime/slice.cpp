#include "runtime/slice.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <stdexcept>
#include <tuple>

namespace frac::rt {

namespace {

std::uint32_t coord(const Cell& c, int axis) {
    return axis == 0 ? c.ix : axis == 1 ? c.iy : c.iz;
}

} // namespace

Cover slice(const Cover& r, double value, int axis) {
    if (r.dimension() != 3) throw std::invalid_argument("slice needs a 3D cover");
    if (r.cells.empty())
        throw std::invalid_argument("slice needs the cells: run subdivide with keep_cells = true");
    if (axis < 0 || axis > 2)
        throw std::invalid_argument(fmt::format("slice: axis {} is not 0, 1 or 2", axis));
    const Interval range = r.root[static_cast<std::size_t>(axis)];
    const char* name = axis == 0 ? "x" : axis == 1 ? "y" : "z";
    if (!(range.lo <= value && value <= range.hi))
        throw std::invalid_argument(
            fmt::format("slice: {} = {} is outside the root box [{}, {}]", name, value, range.lo, range.hi));
    const int au = axis == 0 ? 1 : 0, av = axis == 2 ? 1 : 2;

    // Per level, the positions along `axis` whose outward cell box holds the value: the grid cell
    // of the value and its neighbours, tested with the same boxes as the subdivision used.
    const int depth = r.depth;
    std::vector<std::array<std::int64_t, 3>> hit(static_cast<std::size_t>(depth) + 1);
    for (int k = 0; k <= depth; ++k) {
        const std::uint64_t n = r.cells_per_axis(k);
        const double t = (value - range.lo) / (range.hi - range.lo) * static_cast<double>(n);
        const auto j =
            std::clamp<std::int64_t>(static_cast<std::int64_t>(t), 0, static_cast<std::int64_t>(n) - 1);
        auto& h = hit[static_cast<std::size_t>(k)];
        h = {-1, -1, -1};
        for (std::int64_t d = -1; d <= 1; ++d) {
            const std::int64_t i = j + d;
            if (i < 0 || i >= static_cast<std::int64_t>(n)) continue;
            Cell probe;
            probe.level = static_cast<std::uint8_t>(k);
            (axis == 0 ? probe.ix : axis == 1 ? probe.iy : probe.iz) = static_cast<std::uint32_t>(i);
            if (r.cell_interval(probe, axis).contains(value)) h[static_cast<std::size_t>(d + 1)] = i;
        }
    }

    Cover s;
    s.root = {r.root[static_cast<std::size_t>(au)], r.root[static_cast<std::size_t>(av)]};
    s.depth = r.depth;
    s.split = r.split;
    for (const Cell& c : r.cells) {
        if (c.level > depth) continue;
        const auto& h = hit[c.level];
        const std::int64_t i = coord(c, axis);
        if (i != h[0] && i != h[1] && i != h[2]) continue;
        s.cells.push_back({c.level, c.cls, coord(c, au), coord(c, av), 0});
    }
    const auto key = [](const Cell& c) { return std::make_tuple(c.level, c.iy, c.ix, c.cls); };
    std::sort(s.cells.begin(), s.cells.end(), [&](const Cell& a, const Cell& b) { return key(a) < key(b); });
    s.cells.erase(std::unique(s.cells.begin(), s.cells.end(),
                              [&](const Cell& a, const Cell& b) { return key(a) == key(b); }),
                  s.cells.end());

    s.levels.assign(static_cast<std::size_t>(depth) + 1, LevelCounts{});
    for (const Cell& c : s.cells) {
        LevelCounts& lc = s.levels[c.level];
        ++lc.evaluated;
        switch (c.cls) {
        case CellClass::inside: ++lc.inside, ++s.inside; break;
        case CellClass::outside: ++lc.outside, ++s.outside; break;
        case CellClass::boundary: ++lc.undecided, ++s.boundary; break;
        case CellClass::subdivided: ++lc.undecided, ++s.subdivided; break;
        }
    }
    s.evaluated = s.cells.size();
    return s;
}

void write_slice_png(const Cover& r, double value, const std::string& path, PictureKind kind, int pixels,
                     int axis) {
    write_png(slice(r, value, axis), path, kind, pixels);
}

} // namespace frac::rt
