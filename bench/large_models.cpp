#include "bench/large_models.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <string_view>
#include <vector>

namespace frac::bench {

namespace {

// Deterministic on every platform (the standard distributions are not).
class Random {
public:
    explicit Random(std::uint64_t seed) : s_(seed) {}
    std::uint64_t next() {
        std::uint64_t z = (s_ += 0x9e3779b97f4a7c15ULL);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
        return z ^ (z >> 31);
    }
    double uniform(double lo, double hi) {
        return lo + (hi - lo) * static_cast<double>(next() >> 11) * 0x1p-53;
    }
    int between(int lo, int hi) {
        return lo + static_cast<int>(next() % static_cast<std::uint64_t>(hi - lo + 1));
    }

private:
    std::uint64_t s_;
};

// A stroke font: each letter a list of segments (x0 y0 x1 y1) in a unit cell, coordinates 0..2 for
// 0, 1/2, 1.
struct Glyph {
    char letter;
    std::string_view segments; // groups of four digits
};
constexpr std::array<Glyph, 26> font = {{
    {'a', "0020"
          "2022"
          "0222"
          "0001"
          "0121"},
    {'b', "0002"
          "0020"
          "0121"
          "0222"
          "2021"},
    {'c', "0002"
          "0020"
          "0222"},
    {'d', "0002"
          "0010"
          "0212"
          "1021"
          "1221"
          "2021"},
    {'e', "0002"
          "0020"
          "0111"
          "0222"},
    {'f', "0002"
          "0111"
          "0222"},
    {'g', "0002"
          "0020"
          "0222"
          "2021"
          "1121"},
    {'h', "0002"
          "2022"
          "0121"},
    {'i', "1012"
          "0020"
          "0222"},
    {'j', "2022"
          "0020"
          "0001"},
    {'k', "0002"
          "0122"
          "0120"},
    {'l', "0002"
          "0020"},
    {'m', "0002"
          "2022"
          "0211"
          "1122"},
    {'n', "0002"
          "2022"
          "0220"},
    {'o', "0002"
          "2022"
          "0020"
          "0222"},
    {'p', "0002"
          "0222"
          "0121"
          "2122"},
    {'q', "0002"
          "2022"
          "0222"
          "0020"
          "1120"},
    {'r', "0002"
          "0222"
          "0121"
          "2122"
          "0120"},
    {'s', "0020"
          "0222"
          "0121"
          "0102"
          "2021"},
    {'t', "1012"
          "0222"},
    {'u', "0002"
          "2022"
          "0020"},
    {'v', "0210"
          "1022"},
    {'w', "0002"
          "2022"
          "0011"
          "1120"},
    {'x', "0022"
          "0220"},
    {'y', "0211"
          "2211"
          "1110"},
    {'z', "0222"
          "2200"
          "0020"},
}};

std::string num(double v) {
    return fmt::format("{:.4f}", v);
}

// x - c, written as an exporter writes it (x + 0.5 for x - -0.5 would be tidier; exporters are not).
std::string minus(std::string_view var, double c) {
    return fmt::format("({} - {})", var, num(c));
}

// A balanced min of `items` (at most `fan` arguments per min).
std::string union_of(std::vector<std::string> items, std::size_t fan = 8) {
    while (items.size() > 1) {
        std::vector<std::string> next;
        for (std::size_t i = 0; i < items.size(); i += fan) {
            const std::size_t end = std::min(items.size(), i + fan);
            if (end - i == 1) {
                next.push_back(items[i]);
                continue;
            }
            std::string s = "min(";
            for (std::size_t j = i; j < end; ++j) s += (j > i ? ", " : "") + items[j];
            next.push_back(s + ")");
        }
        items.swap(next);
    }
    return items.empty() ? "1" : items[0];
}

// Distance to the segment (ax, ay)-(bx, by) minus r: the point's parameter on the segment clamped to
// [0, 1], squares as products.
std::string capsule(double ax, double ay, double bx, double by, double r) {
    const double dx = bx - ax, dy = by - ay, inv = 1 / (dx * dx + dy * dy);
    return fmt::format(
        "let h = max(0, min(1, ({} * {} + {} * {}) * {})), u = {} - {} * h, v = {} - {} * h in "
        "sqrt(u * u + v * v) - {}",
        minus("x", ax), num(dx), minus("y", ay), num(dy), num(inv), minus("x", ax), num(dx), minus("y", ay),
        num(dy), num(r));
}

std::string disk(double cx, double cy, double r) {
    return fmt::format("sqrt({} * {} + {} * {}) - {}", minus("x", cx), minus("x", cx), minus("y", cy),
                       minus("y", cy), num(r));
}

std::string rect(double x0, double y0, double x1, double y1) {
    return fmt::format("max({} - x, x - {}, {} - y, y - {})", num(x0), num(x1), num(y0), num(y1));
}

// The model's parts, each adding clauses until its budget is spent.
class Writer {
public:
    Writer(int clauses, std::uint64_t seed) : rng_(seed), total_(clauses) {}

    std::string text(int budget) {
        std::vector<std::string> lines;
        double y = height - 1.2;
        int used = 0;
        while (used < budget && y > text_floor) {
            std::vector<std::string> words;
            double x = 1;
            while (used < budget) {
                const int letters = rng_.between(2, 9);
                if (x + letters * advance > width - 1) break;
                std::vector<std::string> glyphs;
                for (int l = 0; l < letters && used < budget; ++l, x += advance) {
                    const Glyph& g = font[rng_.next() % font.size()];
                    std::vector<std::string> strokes;
                    for (std::size_t k = 0; k + 4 <= g.segments.size() && used < budget; k += 4, ++used) {
                        const auto at = [&](std::size_t i, double size) {
                            return (g.segments[k + i] - '0') * size / 2;
                        };
                        strokes.push_back(capsule(x + at(0, glyph_w), y + at(1, glyph_h), x + at(2, glyph_w),
                                                  y + at(3, glyph_h), stroke_r));
                    }
                    glyphs.push_back(union_of(std::move(strokes)));
                }
                words.push_back(union_of(std::move(glyphs)));
                x += advance;
            }
            lines.push_back(union_of(std::move(words)));
            y -= line_h;
        }
        spent_ += used;
        return union_of(std::move(lines));
    }

    // Buildings on the ground: a wall with a grid of windows cut out, columns in front, an arched door.
    std::string architecture(int budget) {
        std::vector<std::string> buildings;
        int used = 0;
        while (used < budget) {
            const double x0 = rng_.uniform(0.5, width - 9), w = rng_.uniform(3, 8), h = rng_.uniform(4, 11);
            std::string wall = rect(x0, 0.5, x0 + w, 0.5 + h);
            ++used;
            std::vector<std::string> holes;
            const int cols = std::max(1, static_cast<int>(w / 1.2)),
                      rows = std::max(1, static_cast<int>(h / 1.5));
            for (int r = 0; r < rows && used < budget; ++r)
                for (int c = 0; c < cols && used < budget; ++c, ++used) {
                    const double wx = x0 + 0.4 + c * (w - 0.8) / cols, wy = 1.6 + r * (h - 1.4) / rows;
                    holes.push_back(rect(wx, wy, wx + 0.5 * (w - 0.8) / cols, wy + 0.6));
                }
            if (used < budget) { // the arched door: a rectangle and a half disk on it
                const double dx = x0 + w / 2;
                holes.push_back(fmt::format("min({}, max({}, {}))", rect(dx - 0.4, 0.4, dx + 0.4, 1.3),
                                            disk(dx, 1.3, 0.4), num(1.3) + " - y"));
                ++used;
            }
            std::string building =
                holes.empty() ? wall : fmt::format("max({}, -({}))", wall, union_of(holes));
            std::vector<std::string> parts{building};
            for (double cx = x0 + 0.3; cx < x0 + w && used < budget; cx += 1.5, ++used)
                parts.push_back(disk(cx, 0.3, 0.25));
            buildings.push_back(union_of(std::move(parts)));
        }
        spent_ += used;
        return union_of(std::move(buildings));
    }

    // Smooth unions (the polynomial blend of stdlib/csg.frac, inlined) of a disk and a rectangle.
    std::string blends(int budget) {
        std::vector<std::string> items;
        int used = 0;
        for (; used + 2 <= budget; used += 2) {
            const double cx = rng_.uniform(1, width - 1), cy = rng_.uniform(1, height - 1);
            const double r = rng_.uniform(0.2, 0.6), k = rng_.uniform(0.1, 0.4);
            const double rx = cx + rng_.uniform(-0.6, 0.6), ry = cy + rng_.uniform(-0.6, 0.6);
            const double hw = rng_.uniform(0.2, 0.7), hh = rng_.uniform(0.2, 0.7);
            items.push_back(fmt::format("let a = {}, b = {}, h = max({} - abs(a - b), 0) / {} in "
                                        "min(a, b) - h * h * {}",
                                        disk(cx, cy, r), rect(rx - hw, ry - hh, rx + hw, ry + hh), num(k),
                                        num(k), num(k / 4)));
        }
        if (used < budget) { // an odd budget: one plain disk
            items.push_back(disk(rng_.uniform(1, width - 1), rng_.uniform(1, height - 1), 0.3));
            ++used;
        }
        spent_ += used;
        return union_of(std::move(items));
    }

    int spent() const { return spent_; }

    static constexpr double width = 64, height = 40;

private:
    static constexpr double glyph_w = 0.45, glyph_h = 0.8, advance = 0.6, line_h = 1.1, stroke_r = 0.06;
    static constexpr double text_floor = 13;
    Random rng_;
    int total_;
    int spent_ = 0;
};

} // namespace

LargeModel large_model(int clauses, std::uint64_t seed) {
    Writer w(clauses, seed);
    const int arch = clauses / 4, blend = clauses * 3 / 20;
    std::string text = w.text(clauses - arch - blend);
    std::string buildings = w.architecture(arch);
    // Whatever the text could not place (a full page) goes to the blends.
    std::string blobs = w.blends(clauses - w.spent());
    LargeModel m;
    m.name = fmt::format("large_{}", clauses);
    m.clauses = w.spent();
    m.source =
        fmt::format("// Generated by bench/large_models.cpp: {} clauses (text strokes, buildings, blends), "
                    "seed {}.\nshape {}(x, y) over [0, {}] × [0, {}] =\n    min({},\n        {},\n        "
                    "{});\n",
                    m.clauses, seed, m.name, Writer::width, Writer::height, text, buildings, blobs);
    return m;
}

} // namespace frac::bench
