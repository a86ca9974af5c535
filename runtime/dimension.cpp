#include "runtime/dimension.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace frac::rt {

DimensionEstimate box_counting(const RssResult& r, int from_level, int to_level) {
    const int depth = static_cast<int>(r.levels.size()) - 1;
    if (from_level < 0 || from_level >= to_level || to_level > depth)
        throw std::invalid_argument(
            fmt::format("box_counting: levels {}..{} are not a range 0 <= from < to <= depth = {}",
                        from_level, to_level, depth));
    DimensionEstimate est;
    const double log_split = std::log(static_cast<double>(r.options.split));
    std::vector<double> xs, ys;
    bool constant = true;
    for (int k = from_level; k <= to_level; ++k) {
        const std::uint64_t n = r.levels[static_cast<std::size_t>(k)].undecided;
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

} // namespace frac::rt
