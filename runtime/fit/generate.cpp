#include "runtime/fit/generate.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace frac::rt::fit {

namespace {

Piece whole(const FractalFunction& f, Shear s) {
    return {s, f.t0, f.t1, 0, 0};
}

} // namespace

FractalFunction table1_fif() {
    FractalFunction f;
    f.t0 = -1;
    f.t1 = 1;
    Shear t1, t2;
    t1.a = 0.5, t1.b[0] = 0.746, t1.c[0][0] = 0.5, t1.d = -0.5, t1.e[0] = 0.246;
    t2.a = 0.5, t2.b[0] = -0.199, t2.c[0][0] = -0.6, t2.d = 0.5, t2.e[0] = 0.189;
    f.pieces = {whole(f, t1), whole(f, t2)};
    for (Piece& p : f.pieces) {
        p.lo = p.map.map_t(f.t0);
        p.hi = p.map.map_t(f.t1);
    }
    return f;
}

FractalFunction sierpinski_space_curve() {
    FractalFunction f;
    f.curve = true;
    const double h = std::sqrt(3.0) / 4; // half the height of the gasket of side 1
    // (1/2) R(theta) diag(1, -1): a reflection, so the corner copies run the opposite way.
    auto corner = [&](double theta, double ex, double ey) {
        Shear s;
        s.a = 1.0 / 3;
        s.c = {{{0.5 * std::cos(theta), 0.5 * std::sin(theta)},
                {0.5 * std::sin(theta), -0.5 * std::cos(theta)}}};
        s.e = {ex, ey};
        return s;
    };
    Shear first = corner(M_PI / 3, 0, 0), middle, last = corner(-M_PI / 3, 0.75, h);
    middle.a = 1.0 / 3;
    middle.c = {{{0.5, 0}, {0, 0.5}}};
    middle.e = {0.25, h};
    first.d = 0, middle.d = 1.0 / 3, last.d = 2.0 / 3;
    f.pieces = {whole(f, first), whole(f, middle), whole(f, last)};
    for (Piece& p : f.pieces) {
        p.lo = p.map.map_t(f.t0);
        p.hi = p.map.map_t(f.t1);
    }
    return f;
}

Samples feature_points(const FractalFunction& f, int level) {
    if (!f.every_domain_whole()) throw std::invalid_argument("feature points of a FIF only");
    const auto start = f(f.t0), end = f(f.t1);
    // The end points of F under one shear: the fixed points of the maps at the ends of [t0, t1].
    struct Point {
        double t, x, y;
    };
    std::vector<Point> points{{f.t0, start[0], start[1]}, {f.t1, end[0], end[1]}};
    for (int n = 0; n < level; ++n) {
        std::vector<Point> next;
        for (const Piece& p : f.pieces)
            for (const Point& q : points) {
                const Shear& s = p.map;
                next.push_back({s.map_t(q.t), s.b[0] * q.t + s.c[0][0] * q.x + s.c[0][1] * q.y + s.e[0],
                                s.b[1] * q.t + s.c[1][0] * q.x + s.c[1][1] * q.y + s.e[1]});
            }
        points = std::move(next);
    }
    std::stable_sort(points.begin(), points.end(), [](const Point& p, const Point& q) { return p.t < q.t; });
    Samples s;
    const double tolerance = 1e-12 * (f.t1 - f.t0);
    for (const Point& p : points) {
        if (!s.t.empty() && p.t - s.t.back() <= tolerance) continue;
        s.t.push_back(p.t);
        s.x.push_back(p.x);
        if (f.curve) s.y.push_back(p.y);
    }
    return s;
}

std::vector<std::string> generator_names() {
    return {"table1", "sierpinski"};
}

FractalFunction generator(const std::string& name) {
    if (name == "table1") return table1_fif();
    if (name == "sierpinski") return sierpinski_space_curve();
    throw std::invalid_argument("no generator '" + name + "'");
}

} // namespace frac::rt::fit
