#include "runtime/dimension.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_set>

namespace frac::rt {

namespace {

void check_range(const Cover& r, int from_level, int to_level) {
    const int depth = static_cast<int>(r.levels.size()) - 1;
    if (from_level < 0 || from_level >= to_level || to_level > depth)
        throw std::invalid_argument(
            fmt::format("box_counting: levels {}..{} are not a range 0 <= from < to <= depth = {}",
                        from_level, to_level, depth));
}

// Least-squares slope of log N_k against k log(split) over the counts of levels from..to.
DimensionEstimate fit(const Cover& r, int from_level, const std::vector<std::uint64_t>& counts) {
    DimensionEstimate est;
    const double log_split = std::log(static_cast<double>(r.split));
    std::vector<double> xs, ys;
    bool constant = true;
    for (std::size_t i = 0; i < counts.size(); ++i) {
        const int k = from_level + static_cast<int>(i);
        const std::uint64_t n = counts[i];
        if (n == 0)
            throw std::invalid_argument(
                fmt::format("box_counting: no cell of level {} meets the boundary; nothing to count", k));
        constant = constant && (est.counts.empty() || n == est.counts.front().second);
        est.counts.emplace_back(k, n);
        xs.push_back(k * log_split);
        ys.push_back(std::log(static_cast<double>(n)));
    }
    // Ordinary least squares, two-pass (centred) for accuracy.
    const double m = static_cast<double>(xs.size());
    double mx = 0, my = 0;
    for (std::size_t i = 0; i < xs.size(); ++i) {
        mx += xs[i];
        my += ys[i];
    }
    mx /= m;
    my /= m;
    double sxx = 0, sxy = 0, syy = 0;
    for (std::size_t i = 0; i < xs.size(); ++i) {
        sxx += (xs[i] - mx) * (xs[i] - mx);
        sxy += (xs[i] - mx) * (ys[i] - my);
        syy += (ys[i] - my) * (ys[i] - my);
    }
    // At least two levels, so sxx > 0. A constant N_k is fitted exactly by slope 0.
    est.dimension = constant ? 0.0 : sxy / sxx;
    est.r_squared = constant ? 1.0 : std::min(1.0, sxy * sxy / (sxx * syy));
    return est;
}

struct CellKey {
    std::uint32_t x, y, z;
    bool operator==(const CellKey&) const = default;
};
struct CellKeyHash {
    std::size_t operator()(const CellKey& k) const {
        return std::hash<std::uint64_t>{}((static_cast<std::uint64_t>(k.x) << 32 | k.y) ^
                                          (static_cast<std::uint64_t>(k.z) * 0x9e3779b97f4a7c15ULL));
    }
};

} // namespace

DimensionEstimate box_counting(const Cover& r, int from_level, int to_level) {
    check_range(r, from_level, to_level);
    std::vector<std::uint64_t> counts;
    for (int k = from_level; k <= to_level; ++k)
        counts.push_back(r.levels[static_cast<std::size_t>(k)].undecided);
    return fit(r, from_level, counts);
}

DimensionEstimate box_counting_proven(const Cover& r, int from_level, int to_level) {
    check_range(r, from_level, to_level);
    if (r.cells.empty()) throw std::invalid_argument("box_counting_proven: the subdivision kept no cells");
    // For each level k, the cells with an inside (outside) cell strictly below them.
    const auto levels = static_cast<std::size_t>(to_level - from_level + 1);
    std::vector<std::unordered_set<CellKey, CellKeyHash>> with_in(levels), with_out(levels);
    const auto split = static_cast<std::uint64_t>(r.split);
    for (const Cell& c : r.cells) {
        if (c.cls != CellClass::inside && c.cls != CellClass::outside) continue;
        std::uint64_t scale = 1; // split^(c.level - k)
        for (int k = c.level - 1; k >= 0; --k) {
            scale *= split;
            if (k > to_level) continue;
            if (k < from_level) break;
            const CellKey up{static_cast<std::uint32_t>(c.ix / scale),
                             static_cast<std::uint32_t>(c.iy / scale),
                             static_cast<std::uint32_t>(c.iz / scale)};
            (c.cls == CellClass::inside ? with_in : with_out)[static_cast<std::size_t>(k - from_level)]
                .insert(up);
        }
    }
    std::vector<std::uint64_t> counts;
    for (std::size_t i = 0; i < levels; ++i) {
        std::uint64_t n = 0;
        for (const CellKey& k : with_in[i]) n += with_out[i].count(k);
        counts.push_back(n);
    }
    return fit(r, from_level, counts);
}

} // namespace frac::rt
