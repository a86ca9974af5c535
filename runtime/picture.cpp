#include "runtime/picture.hpp"
#include "support/atomic_file.hpp"
#include "support/huge_pages.hpp"

#include <fmt/format.h>
#include <png.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <stdexcept>

namespace frac::rt {

namespace {

struct Rgb {
    std::uint8_t r, g, b;
};

// Colours of the process picture (paper, left) and of the cover (paper, right).
constexpr Rgb white{255, 255, 255};
constexpr Rgb process_inside{77, 77, 77};
constexpr Rgb process_boundary{226, 60, 40};
constexpr Rgb outline{0, 0, 0};
constexpr Rgb cover_inside{200, 200, 200};
constexpr Rgb cover_boundary{0, 0, 0};
constexpr const char* svg_process_inside = "#4d4d4d";
constexpr const char* svg_process_outside = "#ffffff";
constexpr const char* svg_process_boundary = "#e23c28";
constexpr const char* svg_cover_inside = "#c8c8c8";
constexpr const char* svg_cover_boundary = "#000000";

// Pixel classes, ordered by importance: a pixel shows the largest one among the leaves meeting it.
enum Paint : std::uint8_t { none = 0, paint_outside = 1, paint_inside = 2, paint_boundary = 3 };

Paint paint_of(CellClass c) {
    switch (c) {
    case CellClass::inside: return paint_inside;
    case CellClass::outside: return paint_outside;
    case CellClass::boundary: return paint_boundary;
    case CellClass::subdivided: return none;
    }
    return none;
}

bool is_leaf(CellClass c) {
    return c != CellClass::subdivided;
}

void require_2d_cells(const Cover& r) {
    if (r.dimension() != 2) throw std::invalid_argument("pictures need a 2D cover; use slices");
    if (r.cells.empty())
        throw std::invalid_argument("pictures need the cells: run subdivide with keep_cells = true");
}

// Size of one panel: the longer side of the root box gets `longer` units, the other follows.
struct PanelSize {
    int w, h;
};

PanelSize panel_size(const Cover& r, int longer) {
    const double wx = r.root[0].hi - r.root[0].lo, wy = r.root[1].hi - r.root[1].lo;
    if (wx >= wy) return {longer, std::max(1, static_cast<int>(std::lround(longer * (wy / wx))))};
    return {std::max(1, static_cast<int>(std::lround(longer * (wx / wy)))), longer};
}

// Ranges [first, last] of the units (pixels, characters) of an axis of `units` that cell i of n meets
// with positive area: floor(i*units/n) .. ceil((i+1)*units/n) - 1. Products stay below 2^46.
struct Span {
    std::uint64_t first, last;
};

Span span(std::uint64_t i, std::uint64_t n, std::uint64_t units) {
    return {i * units / n, ((i + 1) * units + n - 1) / n - 1};
}

// Per-level cache of split^level.
std::vector<std::uint64_t> grid_sizes(const Cover& r) {
    std::vector<std::uint64_t> n;
    for (int k = 0; k <= r.depth; ++k) n.push_back(r.cells_per_axis(k));
    return n;
}

// One panel: a class per pixel (rows from the bottom) and an outline mask.
struct Raster {
    int w, h;
    std::vector<std::uint8_t> paint, line;

    Raster(int w_, int h_) : w(w_), h(h_) {
        support::assign_huge(paint, static_cast<std::size_t>(w_) * h_, std::uint8_t{none});
        support::assign_huge(line, static_cast<std::size_t>(w_) * h_, std::uint8_t{0});
    }
    std::size_t at(std::uint64_t x, std::uint64_t y) const { return y * static_cast<std::uint64_t>(w) + x; }
};

Raster rasterize(const Cover& r, PanelSize size, bool outlines) {
    Raster ras(size.w, size.h);
    const auto n_of = grid_sizes(r);
    const auto W = static_cast<std::uint64_t>(size.w), H = static_cast<std::uint64_t>(size.h);
    for (const Cell& c : r.cells) {
        const std::uint64_t n = n_of[c.level];
        if (is_leaf(c.cls)) {
            const Span sx = span(c.ix, n, W), sy = span(c.iy, n, H);
            const std::uint8_t p = paint_of(c.cls);
            for (std::uint64_t y = sy.first; y <= sy.last; ++y)
                for (std::uint64_t x = sx.first; x <= sx.last; ++x) {
                    std::uint8_t& q = ras.paint[ras.at(x, y)];
                    q = std::max(q, p);
                }
        }
        // Edges at floor(j*W/n), clamped: neighbours share their edge pixels, so lines are 1 px.
        if (outlines && W >= 4 * n && H >= 4 * n) {
            const std::uint64_t x0 = c.ix * W / n, x1 = std::min((c.ix + 1) * W / n, W - 1);
            const std::uint64_t y0 = c.iy * H / n, y1 = std::min((c.iy + 1) * H / n, H - 1);
            for (std::uint64_t y = y0; y <= y1; ++y) ras.line[ras.at(x0, y)] = ras.line[ras.at(x1, y)] = 1;
            for (std::uint64_t x = x0; x <= x1; ++x) ras.line[ras.at(x, y0)] = ras.line[ras.at(x, y1)] = 1;
        }
    }
    return ras;
}

// Copies a panel into the image at column offset `ox`, flipping y.
void blit(const Raster& ras, bool process, Image& img, int ox) {
    for (int y = 0; y < ras.h; ++y) {
        const int row = ras.h - 1 - y;
        for (int x = 0; x < ras.w; ++x) {
            const std::size_t i = ras.at(static_cast<std::uint64_t>(x), static_cast<std::uint64_t>(y));
            Rgb c = white;
            switch (ras.paint[i]) {
            case paint_inside: c = process ? process_inside : cover_inside; break;
            case paint_boundary: c = process ? process_boundary : cover_boundary; break;
            default: break;
            }
            if (ras.line[i]) c = outline;
            std::uint8_t* px = &img.rgb[(static_cast<std::size_t>(row) * img.width + ox + x) * 3];
            px[0] = c.r;
            px[1] = c.g;
            px[2] = c.b;
        }
    }
}

// Fixed-point number with trailing zeros removed ("12.5", "3").
std::string num_text(double v, int decimals) {
    std::string s = fmt::format("{:.{}f}", v, decimals);
    if (s.find('.') != std::string::npos) {
        while (s.back() == '0') s.pop_back();
        if (s.back() == '.') s.pop_back();
    }
    if (s == "-0") s = "0";
    return s;
}

// Writes an SVG incrementally so that a large cover never sits in memory twice; atomically, so that a
// failed or interrupted write leaves the previous file in place.
class SvgWriter {
public:
    explicit SvgWriter(const std::string& path) : file_(path, "SVG") {}
    fmt::memory_buffer& buf() { return buf_; }
    void maybe_flush() {
        if (buf_.size() > (1u << 20)) flush();
    }
    void close() {
        flush();
        file_.commit();
    }

private:
    void flush() {
        file_.write(buf_.data(), buf_.size());
        buf_.clear();
    }
    support::AtomicFile file_;
    fmt::memory_buffer buf_;
};

// Index ranges of the levels in r.cells (cells are ordered by level).
std::vector<std::pair<std::size_t, std::size_t>> level_ranges(const Cover& r) {
    std::vector<std::pair<std::size_t, std::size_t>> ranges(static_cast<std::size_t>(r.depth) + 1, {0, 0});
    std::size_t i = 0;
    for (int k = 0; k <= r.depth; ++k) {
        const std::size_t begin = i;
        while (i < r.cells.size() && r.cells[i].level == k) ++i;
        ranges[static_cast<std::size_t>(k)] = {begin, i};
    }
    return ranges;
}

// Rects of the cells of [begin, end) whose class passes `keep`, in one <g fill=...> group.
template <typename Keep>
void svg_rects(SvgWriter& out, const Cover& r, std::pair<std::size_t, std::size_t> range, Keep keep,
               const char* fill, PanelSize size, std::uint64_t n) {
    const double cw = static_cast<double>(size.w) / static_cast<double>(n);
    const double ch = static_cast<double>(size.h) / static_cast<double>(n);
    // Enough decimals to place the smallest cell to ~1/1000 of its size.
    const int decimals = std::clamp(static_cast<int>(std::ceil(-std::log10(std::min(cw, ch)))) + 3, 0, 15);
    const std::string w = num_text(cw, decimals), h = num_text(ch, decimals);
    bool open = false;
    for (std::size_t i = range.first; i < range.second; ++i) {
        const Cell& c = r.cells[i];
        if (!keep(c.cls)) continue;
        if (!open) {
            fmt::format_to(std::back_inserter(out.buf()), "<g fill=\"{}\">\n", fill);
            open = true;
        }
        const double x = static_cast<double>(c.ix) * cw;
        const double y = static_cast<double>(n - 1 - c.iy) * ch; // y up
        fmt::format_to(std::back_inserter(out.buf()),
                       "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\"/>\n", num_text(x, decimals),
                       num_text(y, decimals), w, h);
        out.maybe_flush();
    }
    if (open) fmt::format_to(std::back_inserter(out.buf()), "</g>\n");
}

void svg_process(SvgWriter& out, const Cover& r, PanelSize size, int ox) {
    const auto ranges = level_ranges(r);
    fmt::format_to(std::back_inserter(out.buf()), "<g transform=\"translate({},0)\" stroke=\"#000000\">\n",
                   ox);
    for (int k = 0; k <= r.depth; ++k) {
        const std::uint64_t n = r.cells_per_axis(k);
        const double cell = std::min(size.w, size.h) / static_cast<double>(n);
        if (cell < 0.3) break; // too small to see: the undecided parents show the region
        const auto range = ranges[static_cast<std::size_t>(k)];
        fmt::format_to(std::back_inserter(out.buf()), "<g stroke-width=\"{}\">\n",
                       num_text(std::min(1.0, cell / 16), 6));
        svg_rects(
            out, r, range, [](CellClass c) { return c == CellClass::outside; }, svg_process_outside, size, n);
        svg_rects(
            out, r, range, [](CellClass c) { return c == CellClass::inside; }, svg_process_inside, size, n);
        svg_rects(
            out, r, range, [](CellClass c) { return c == CellClass::boundary || c == CellClass::subdivided; },
            svg_process_boundary, size, n);
        fmt::format_to(std::back_inserter(out.buf()), "</g>\n");
    }
    fmt::format_to(std::back_inserter(out.buf()), "</g>\n");
}

void svg_cover(SvgWriter& out, const Cover& r, PanelSize size, int ox) {
    const auto ranges = level_ranges(r);
    fmt::format_to(std::back_inserter(out.buf()), "<g transform=\"translate({},0)\">\n", ox);
    for (int k = 0; k <= r.depth; ++k)
        svg_rects(
            out, r, ranges[static_cast<std::size_t>(k)], [](CellClass c) { return c == CellClass::inside; },
            svg_cover_inside, size, r.cells_per_axis(k));
    for (int k = 0; k <= r.depth; ++k)
        svg_rects(
            out, r, ranges[static_cast<std::size_t>(k)], [](CellClass c) { return c == CellClass::boundary; },
            svg_cover_boundary, size, r.cells_per_axis(k));
    fmt::format_to(std::back_inserter(out.buf()), "</g>\n");
}

} // namespace

Image render(const Cover& r, PictureKind kind, int pixels) {
    require_2d_cells(r);
    if (pixels < 1 || pixels > 16384)
        throw std::invalid_argument(fmt::format("render: pixels {} is out of range [1, 16384]", pixels));
    const PanelSize size = panel_size(r, pixels);
    const int gap = kind == PictureKind::both ? std::max(2, pixels / 64) : 0;
    Image img;
    img.width = kind == PictureKind::both ? 2 * size.w + gap : size.w;
    img.height = size.h;
    support::assign_huge(img.rgb, static_cast<std::size_t>(img.width) * img.height * 3, std::uint8_t{255});
    if (kind != PictureKind::cover) blit(rasterize(r, size, true), true, img, 0);
    if (kind != PictureKind::process)
        blit(rasterize(r, size, false), false, img, kind == PictureKind::both ? size.w + gap : 0);
    return img;
}

void write_png(const Image& image, const std::string& path) {
    if (image.width < 1 || image.height < 1 ||
        image.rgb.size() != static_cast<std::size_t>(image.width) * image.height * 3)
        throw std::invalid_argument(fmt::format("write_png '{}': malformed image", path));
    support::AtomicFile out(path, "PNG");
    // The simplified libpng API reports errors by return value (no setjmp/longjmp through C++).
    png_image png;
    std::memset(&png, 0, sizeof png);
    png.version = PNG_IMAGE_VERSION;
    png.width = static_cast<png_uint_32>(image.width);
    png.height = static_cast<png_uint_32>(image.height);
    png.format = PNG_FORMAT_RGB;
    // Faster deflate, no row filters: a picture of flat colours comes out 1.4-2.2 times larger (14 to
    // 30 KB for the Koch tiling at depth 9) and is written in a fraction of the time (about 20 ms less
    // of a 66 ms `frac render`; docs/performance.md, "Frontend, exit and allocator").
    png.flags = PNG_IMAGE_FLAG_FAST;
    const int ok = png_image_write_to_stdio(&png, out.stream(), 0, image.rgb.data(), 0, nullptr);
    const std::string reason = ok ? "" : png.message;
    png_image_free(&png);
    if (!ok) out.fail(reason);
    out.commit();
}

void write_png(const Cover& r, const std::string& path, PictureKind kind, int pixels) {
    write_png(render(r, kind, pixels), path);
}

void write_svg(const Cover& r, const std::string& path, PictureKind kind) {
    require_2d_cells(r);
    const PanelSize size = panel_size(r, 1024);
    const int gap = kind == PictureKind::both ? 16 : 0;
    const int width = kind == PictureKind::both ? 2 * size.w + gap : size.w;
    SvgWriter out(path);
    fmt::format_to(
        std::back_inserter(out.buf()),
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\">\n"
        "<rect width=\"{0}\" height=\"{1}\" fill=\"#ffffff\"/>\n",
        width, size.h);
    if (kind != PictureKind::cover) svg_process(out, r, size, 0);
    if (kind != PictureKind::process) svg_cover(out, r, size, kind == PictureKind::both ? size.w + gap : 0);
    fmt::format_to(std::back_inserter(out.buf()), "</svg>\n");
    out.close();
}

std::string ascii_picture(const Cover& r, int columns, int rows) {
    require_2d_cells(r);
    if (columns < 1 || columns > 4096 || rows < 1 || rows > 4096)
        throw std::invalid_argument(
            fmt::format("ascii_picture: {}x{} characters; each side must be in [1, 4096]", columns, rows));
    enum : std::uint8_t { seen_inside = 1, seen_outside = 2, seen_boundary = 4 };
    const auto C = static_cast<std::uint64_t>(columns), R = static_cast<std::uint64_t>(rows);
    std::vector<std::uint8_t> seen(static_cast<std::size_t>(C * R), 0); // rows from the bottom
    const auto n_of = grid_sizes(r);
    for (const Cell& c : r.cells) {
        if (!is_leaf(c.cls)) continue;
        const std::uint8_t bit = c.cls == CellClass::inside    ? seen_inside
                                 : c.cls == CellClass::outside ? seen_outside
                                                               : seen_boundary;
        const std::uint64_t n = n_of[c.level];
        const Span sx = span(c.ix, n, C), sy = span(c.iy, n, R);
        for (std::uint64_t y = sy.first; y <= sy.last; ++y)
            for (std::uint64_t x = sx.first; x <= sx.last; ++x) seen[y * C + x] |= bit;
    }
    std::string out;
    out.reserve(static_cast<std::size_t>((C + 1) * R));
    for (std::uint64_t line = 0; line < R; ++line) {
        const std::uint64_t y = R - 1 - line;
        for (std::uint64_t x = 0; x < C; ++x) {
            const std::uint8_t s = seen[y * C + x];
            out += (s & seen_boundary)                       ? '+'
                   : (s & seen_inside) && (s & seen_outside) ? ':'
                   : (s & seen_inside)                       ? '#'
                                                             : '.';
        }
        out += '\n';
    }
    return out;
}

} // namespace frac::rt
