#include "runtime/relief.hpp"
#include "support/huge_pages.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <stdexcept>

namespace frac::rt {

Image relief_image(const Cover& r, int pixels) {
    if (r.dimension() != 3 || r.cells.empty())
        throw std::invalid_argument("relief_image: needs a 3D cover computed with its cells");
    if (pixels < 16 || pixels > 16384)
        throw std::invalid_argument(fmt::format("relief_image: {} pixels; use 16 to 16384", pixels));
    const double wx = r.root[0].hi - r.root[0].lo, wy = r.root[1].hi - r.root[1].lo;
    const double wz = r.root[2].hi - r.root[2].lo;
    const double longer = std::max(wx, wy);
    const int width = std::max(1, static_cast<int>(std::lround(pixels * wx / longer)));
    const int height = std::max(1, static_cast<int>(std::lround(pixels * wy / longer)));
    const auto W = static_cast<std::uint64_t>(width), H = static_cast<std::uint64_t>(height);
    constexpr double none = -std::numeric_limits<double>::infinity();
    std::vector<double> top(W * H, none); // fraction of the root's z extent, rows from the bottom
    std::vector<std::uint8_t> on_boundary(W * H, 0);
    for (const Cell& c : r.cells) {
        if (c.cls != CellClass::inside && c.cls != CellClass::boundary) continue;
        const std::uint64_t n = r.cells_per_axis(c.level);
        // Pixels whose centres lie in the cell's x and y ranges (at least one, so no cell vanishes).
        auto span = [n](std::uint64_t i, std::uint64_t size) {
            std::uint64_t a = (2 * i * size + n) / (2 * n), b = (2 * (i + 1) * size + n) / (2 * n);
            if (b <= a) b = std::min(a + 1, size);
            return std::pair{std::min(a, size - 1), b};
        };
        const auto [x0, x1] = span(c.ix, W);
        const auto [y0, y1] = span(c.iy, H);
        const double z = static_cast<double>(c.iz + 1) / static_cast<double>(n);
        for (std::uint64_t y = y0; y < y1; ++y)
            for (std::uint64_t x = x0; x < x1; ++x) {
                const std::uint64_t k = y * W + x;
                if (z > top[k] || (z == top[k] && c.cls == CellClass::boundary)) {
                    top[k] = z;
                    on_boundary[k] = c.cls == CellClass::boundary;
                }
            }
    }
    // Lambert shading with the normal of the height field in world units.
    const double px = wx / static_cast<double>(W), py = wy / static_cast<double>(H);
    const double lx = -0.45, ly = 0.45, lz = 0.77; // a light from the upper left, above
    auto height_at = [&](std::int64_t x, std::int64_t y, double fallback) {
        if (x < 0 || y < 0 || x >= static_cast<std::int64_t>(W) || y >= static_cast<std::int64_t>(H))
            return fallback;
        const double t = top[static_cast<std::uint64_t>(y) * W + static_cast<std::uint64_t>(x)];
        return t == none ? fallback : t * wz;
    };
    Image img;
    img.width = width;
    img.height = height;
    support::assign_huge(img.rgb, W * H * 3, std::uint8_t{255});
    for (std::uint64_t y = 0; y < H; ++y)
        for (std::uint64_t x = 0; x < W; ++x) {
            const std::uint64_t k = y * W + x;
            if (top[k] == none) continue;
            const auto xi = static_cast<std::int64_t>(x), yi = static_cast<std::int64_t>(y);
            const double h = top[k] * wz;
            const double dx = (height_at(xi + 1, yi, h) - height_at(xi - 1, yi, h)) / (2 * px);
            const double dy = (height_at(xi, yi + 1, h) - height_at(xi, yi - 1, h)) / (2 * py);
            const double norm = std::sqrt(dx * dx + dy * dy + 1);
            const double light = std::max(0.0, (-dx * lx - dy * ly + lz) / norm);
            const double shade = 0.2 + 0.8 * light;
            const double base[3] = {on_boundary[k] ? 225.0 : 190.0, on_boundary[k] ? 120.0 : 195.0,
                                    on_boundary[k] ? 100.0 : 210.0};
            const std::uint64_t row = H - 1 - y; // top line = highest y
            for (int ch = 0; ch < 3; ++ch)
                img.rgb[(row * W + x) * 3 + static_cast<std::uint64_t>(ch)] =
                    static_cast<std::uint8_t>(std::clamp(base[ch] * shade, 0.0, 255.0));
        }
    return img;
}

} // namespace frac::rt
