#include "runtime/legend.hpp"
#include "support/huge_pages.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace frac::rt {

namespace {

// 5 x 7 glyphs of the letters the legend uses, one row a byte (bit 4 = leftmost column).
struct Glyph {
    char c;
    std::array<std::uint8_t, 7> rows;
};
constexpr Glyph glyphs[] = {
    {'a', {0x00, 0x00, 0x0e, 0x01, 0x0f, 0x11, 0x0f}}, {'b', {0x10, 0x10, 0x1e, 0x11, 0x11, 0x11, 0x1e}},
    {'c', {0x00, 0x00, 0x0e, 0x10, 0x10, 0x11, 0x0e}}, {'d', {0x01, 0x01, 0x0f, 0x11, 0x11, 0x11, 0x0f}},
    {'e', {0x00, 0x00, 0x0e, 0x11, 0x1f, 0x10, 0x0e}}, {'i', {0x04, 0x00, 0x0c, 0x04, 0x04, 0x04, 0x0e}},
    {'n', {0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11}}, {'o', {0x00, 0x00, 0x0e, 0x11, 0x11, 0x11, 0x0e}},
    {'r', {0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10}}, {'s', {0x00, 0x00, 0x0f, 0x10, 0x0e, 0x01, 0x1e}},
    {'t', {0x08, 0x08, 0x1c, 0x08, 0x08, 0x09, 0x06}}, {'u', {0x00, 0x00, 0x11, 0x11, 0x11, 0x13, 0x0d}},
    {'y', {0x00, 0x00, 0x11, 0x11, 0x0f, 0x01, 0x0e}},
};

const Glyph* glyph(char c) {
    for (const Glyph& g : glyphs)
        if (g.c == c) return &g;
    return nullptr;
}

struct Entry {
    std::string word;
    std::array<std::uint8_t, 3> colour;
};

class Canvas {
public:
    Canvas(Image& img, int top) : img_(img), top_(top) {}
    void pixel(int x, int y, std::array<std::uint8_t, 3> c) {
        if (x < 0 || x >= img_.width || y < top_ || y >= img_.height) return;
        const auto k = (static_cast<std::size_t>(y) * static_cast<std::size_t>(img_.width) +
                        static_cast<std::size_t>(x)) *
                       3;
        for (std::size_t ch = 0; ch < 3; ++ch) img_.rgb[k + ch] = c[ch];
    }
    void rect(int x, int y, int w, int h, std::array<std::uint8_t, 3> c) {
        for (int j = 0; j < h; ++j)
            for (int i = 0; i < w; ++i) pixel(x + i, y + j, c);
    }
    // Draws `word` at (x, y) with `scale` pixels a font pixel; returns the x after it.
    int text(int x, int y, const std::string& word, int scale) {
        for (char ch : word) {
            if (const Glyph* g = glyph(ch))
                for (int row = 0; row < 7; ++row)
                    for (int col = 0; col < 5; ++col)
                        if ((g->rows[static_cast<std::size_t>(row)] >> (4 - col)) & 1)
                            rect(x + col * scale, y + row * scale, scale, scale, {0, 0, 0});
            x += 6 * scale;
        }
        return x;
    }

private:
    Image& img_;
    int top_;
};

} // namespace

Image with_legend(const Image& image, PictureKind kind) {
    const int scale = std::max(1, image.width / (kind == PictureKind::both ? 1024 : 512));
    const int strip = 12 * scale;
    Image out;
    out.width = image.width;
    out.height = image.height + strip;
    support::assign_huge(out.rgb,
                         static_cast<std::size_t>(out.width) * static_cast<std::size_t>(out.height) * 3,
                         std::uint8_t{255});
    std::copy(image.rgb.begin(), image.rgb.end(), out.rgb.begin());
    Canvas canvas(out, image.height);
    const std::vector<Entry> process = {
        {"inside", {77, 77, 77}}, {"boundary", {226, 60, 40}}, {"outside", {255, 255, 255}}};
    const std::vector<Entry> cover = {{"inside", {200, 200, 200}}, {"boundary", {0, 0, 0}}};
    const int y = image.height + 2 * scale, box = 7 * scale;
    auto draw = [&](const std::vector<Entry>& entries, int x) {
        for (const Entry& e : entries) {
            canvas.rect(x, y, box, box, {0, 0, 0}); // outline, so a white swatch shows
            canvas.rect(x + 1, y + 1, box - 2, box - 2, e.colour);
            x = canvas.text(x + box + 2 * scale, y, e.word, scale) + 4 * scale;
        }
    };
    if (kind == PictureKind::cover) {
        draw(cover, 2 * scale);
    } else {
        draw(process, 2 * scale);
        if (kind == PictureKind::both) draw(cover, out.width / 2 + 2 * scale);
    }
    return out;
}

} // namespace frac::rt
