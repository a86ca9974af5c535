#include "runtime/fit/height_grid.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>

#include <fmt/format.h>
#include <png.h>

namespace frac::rt::fit {

DataError::DataError(std::string f, std::size_t l, std::size_t c, const std::string& message, std::string src)
    : std::runtime_error(message), file(std::move(f)), source_line(std::move(src)), line(l), column(c) {}

namespace {

bool ends_with(const std::string& s, const std::string& tail) {
    return s.size() >= tail.size() && std::equal(tail.rbegin(), tail.rend(), s.rbegin(),
                                                 [](char a, char b) { return std::tolower(a) == b; });
}

void set_peak_from_range(HeightGrid& g) {
    const auto [lo, hi] = std::minmax_element(g.z.begin(), g.z.end());
    g.peak = *hi > *lo ? *hi - *lo : 1.0;
}

// Too few samples for a surface: at least 2 x 2.
void check_size(const HeightGrid& g, const std::string& path) {
    if (g.width < 2 || g.height < 2)
        throw DataError(
            path, 0, 0,
            fmt::format("too few samples: {} x {}, a surface needs at least 2 x 2", g.width, g.height));
}

} // namespace

HeightGrid read_csv_grid(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw DataError(path, 0, 0, fmt::format("cannot read the file: {}", std::strerror(errno)));
    HeightGrid g;
    std::string text;
    std::size_t line_no = 0;
    while (std::getline(in, text)) {
        ++line_no;
        if (!text.empty() && text.back() == '\r') text.pop_back();
        const auto first = text.find_first_not_of(" \t");
        if (first == std::string::npos || text[first] == '#') continue;
        std::size_t count = 0, pos = 0;
        while (true) {
            const auto comma = text.find(',', pos);
            const std::size_t end = comma == std::string::npos ? text.size() : comma;
            std::size_t b = pos, e = end;
            while (b < e && (text[b] == ' ' || text[b] == '\t')) ++b;
            while (e > b && (text[e - 1] == ' ' || text[e - 1] == '\t')) --e;
            double v = 0;
            const auto [ptr, ec] = std::from_chars(text.data() + b, text.data() + e, v);
            if (b == e || ec != std::errc() || ptr != text.data() + e)
                throw DataError(path, line_no, b + 1,
                                b == e ? std::string("a value is missing")
                                       : fmt::format("'{}' is not a number", text.substr(b, e - b)),
                                text);
            if (!std::isfinite(v))
                throw DataError(path, line_no, b + 1,
                                fmt::format("'{}' is not a finite number", text.substr(b, e - b)), text);
            g.z.push_back(v);
            ++count;
            if (comma == std::string::npos) break;
            pos = comma + 1;
        }
        if (g.height == 0)
            g.width = count;
        else if (count != g.width)
            throw DataError(path, line_no, 1,
                            fmt::format("this row has {} values, the first row {}", count, g.width), text);
        ++g.height;
    }
    check_size(g, path);
    set_peak_from_range(g);
    return g;
}

namespace {

struct PngRead {
    std::uint32_t width = 0, height = 0;
    int bit_depth = 0, colour_type = 0;
    std::vector<unsigned char> bytes;
    char message[256] = {};
};

void on_png_error(png_structp png, png_const_charp message) {
    auto* read = static_cast<PngRead*>(png_get_error_ptr(png));
    std::snprintf(read->message, sizeof read->message, "%s", message);
    png_longjmp(png, 1);
}

void on_png_warning(png_structp, png_const_charp) {}

// libpng's classic reader: it reports the file's own bit depth and colour type (the simplified API
// converts them). Returns false with read->message set on a libpng error; C frames only past setjmp.
bool read_png(std::FILE* file, PngRead* read, bool header_only) {
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, read, on_png_error, on_png_warning);
    if (png == nullptr) return false;
    png_infop info = png_create_info_struct(png);
    if (info == nullptr || setjmp(png_jmpbuf(png))) {
        png_destroy_read_struct(&png, &info, nullptr);
        return false;
    }
    png_init_io(png, file);
    png_read_info(png, info);
    read->width = png_get_image_width(png, info);
    read->height = png_get_image_height(png, info);
    read->bit_depth = png_get_bit_depth(png, info);
    read->colour_type = png_get_color_type(png, info);
    if (!header_only) {
        const std::size_t row_bytes = png_get_rowbytes(png, info);
        std::vector<png_bytep> rows(read->height);
        for (std::uint32_t y = 0; y < read->height; ++y) rows[y] = read->bytes.data() + y * row_bytes;
        png_read_image(png, rows.data());
    }
    png_destroy_read_struct(&png, &info, nullptr);
    return true;
}

const char* colour_name(int type) {
    switch (type) {
    case PNG_COLOR_TYPE_GRAY: return "grey";
    case PNG_COLOR_TYPE_GRAY_ALPHA: return "grey with alpha";
    case PNG_COLOR_TYPE_PALETTE: return "palette";
    case PNG_COLOR_TYPE_RGB: return "RGB";
    case PNG_COLOR_TYPE_RGB_ALPHA: return "RGBA";
    default: return "unknown";
    }
}

} // namespace

HeightGrid read_png_grid(const std::string& path) {
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"), std::fclose);
    if (!file) throw DataError(path, 0, 0, fmt::format("cannot read the file: {}", std::strerror(errno)));
    unsigned char signature[8] = {};
    if (std::fread(signature, 1, 8, file.get()) != 8 || png_sig_cmp(signature, 0, 8) != 0)
        throw DataError(path, 0, 0, "not a PNG file");
    std::rewind(file.get());
    PngRead read;
    if (!read_png(file.get(), &read, true))
        throw DataError(path, 0, 0, fmt::format("unreadable PNG: {}", read.message));
    if (read.colour_type != PNG_COLOR_TYPE_GRAY)
        throw DataError(
            path, 0, 0,
            fmt::format("the image is {} ({} bits per channel); fit reads grey PNG only: 8 bits (an "
                        "image) or 16 bits (heights)",
                        colour_name(read.colour_type), read.bit_depth));
    if (read.bit_depth != 8 && read.bit_depth != 16)
        throw DataError(path, 0, 0,
                        fmt::format("the grey image has {} bits per pixel; fit reads 8 bits (an image) or 16 "
                                    "bits (heights)",
                                    read.bit_depth));
    if (std::uint64_t{read.width} * read.height > (std::uint64_t{1} << 24))
        throw DataError(path, 0, 0,
                        fmt::format("the image has {} x {} pixels, more than 2^24", read.width, read.height));
    const std::size_t bytes_per_pixel = read.bit_depth / 8;
    read.bytes.assign(std::size_t{read.width} * read.height * bytes_per_pixel, 0);
    std::rewind(file.get());
    if (!read_png(file.get(), &read, false))
        throw DataError(path, 0, 0, fmt::format("unreadable PNG: {}", read.message));
    HeightGrid g;
    g.width = read.width;
    g.height = read.height;
    g.bits = read.bit_depth;
    g.peak = read.bit_depth == 8 ? 255.0 : 65535.0;
    g.z.resize(g.width * g.height);
    for (std::size_t i = 0; i < g.z.size(); ++i)
        g.z[i] = bytes_per_pixel == 1 ? read.bytes[i] : read.bytes[2 * i] * 256.0 + read.bytes[2 * i + 1];
    check_size(g, path);
    return g;
}

HeightGrid read_height_grid(const std::string& path) {
    return ends_with(path, ".csv") ? read_csv_grid(path) : read_png_grid(path);
}

HeightGrid elliptic_paraboloid(std::size_t width, std::size_t height, double x0, double y0, double sx,
                               double sy, double z0) {
    HeightGrid g;
    g.width = width;
    g.height = height;
    g.z.resize(width * height);
    for (std::size_t y = 0; y < height; ++y)
        for (std::size_t x = 0; x < width; ++x) {
            const double u = (static_cast<double>(x) / static_cast<double>(width - 1) - x0) / sx;
            const double v = (static_cast<double>(y) / static_cast<double>(height - 1) - y0) / sy;
            g.z[y * width + x] = z0 - u * u - v * v;
        }
    set_peak_from_range(g);
    return g;
}

ErrorStats error_stats(const HeightGrid& grid, const std::vector<double>& approximation) {
    ErrorStats s;
    double sum = 0;
    for (std::size_t i = 0; i < grid.z.size(); ++i) {
        const double d = approximation[i] - grid.z[i];
        s.max_error = std::max(s.max_error, std::abs(d));
        sum += d * d;
    }
    s.mse = sum / static_cast<double>(grid.z.size());
    s.psnr = s.mse > 0 ? 10.0 * std::log10(grid.peak * grid.peak / s.mse)
                       : std::numeric_limits<double>::infinity();
    return s;
}

} // namespace frac::rt::fit
