#include "runtime/fit/model.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <numeric>
#include <optional>

namespace frac::rt::fit {

Shear Shear::after(const Shear& q) const {
    // this(q(t, v)) = (a (a_q t + d_q) + d, b (a_q t + d_q) + C (b_q t + C_q v + e_q) + e)
    Shear r;
    r.a = a * q.a;
    r.d = a * q.d + d;
    for (int i = 0; i < 2; ++i) {
        r.b[i] = b[i] * q.a + c[i][0] * q.b[0] + c[i][1] * q.b[1];
        r.e[i] = b[i] * q.d + c[i][0] * q.e[0] + c[i][1] * q.e[1] + e[i];
        for (int j = 0; j < 2; ++j) r.c[i][j] = c[i][0] * q.c[0][j] + c[i][1] * q.c[1][j];
    }
    return r;
}

double Shear::vertical_norm(bool curve) const {
    if (!curve) return std::abs(c[0][0]);
    return std::max(std::abs(c[0][0]) + std::abs(c[0][1]), std::abs(c[1][0]) + std::abs(c[1][1]));
}

std::array<double, 2> FractalFunction::operator()(double t) const {
    // F(t) = v + M F(u): each step takes u back through the piece whose range holds it.
    std::array<double, 2> v{0, 0};
    double m[2][2] = {{1, 0}, {0, 1}};
    double u = std::clamp(t, t0, t1);
    for (int depth = 0; depth < 400; ++depth) {
        auto it = std::upper_bound(pieces.begin(), pieces.end(), u,
                                   [](double value, const Piece& p) { return value < p.lo; });
        const Piece& p = it == pieces.begin() ? pieces.front() : *std::prev(it);
        const Shear& s = p.map;
        u = std::clamp((u - s.d) / s.a, p.alpha, p.beta);
        for (int i = 0; i < 2; ++i) {
            const double w0 = s.b[0] * u + s.e[0], w1 = s.b[1] * u + s.e[1];
            v[i] += m[i][0] * w0 + m[i][1] * w1;
        }
        double n[2][2];
        for (int i = 0; i < 2; ++i)
            for (int j = 0; j < 2; ++j) n[i][j] = m[i][0] * s.c[0][j] + m[i][1] * s.c[1][j];
        std::copy(&n[0][0], &n[0][0] + 4, &m[0][0]);
        if (std::max({std::abs(m[0][0]), std::abs(m[0][1]), std::abs(m[1][0]), std::abs(m[1][1])}) < 1e-15)
            break;
    }
    return v;
}

bool FractalFunction::every_domain_whole() const {
    return std::all_of(pieces.begin(), pieces.end(),
                       [&](const Piece& p) { return p.alpha == t0 && p.beta == t1; });
}

std::size_t FractalFunction::parameter_count() const {
    bool coupled = false;
    for (const Piece& p : pieces) coupled = coupled || p.map.c[0][1] != 0 || p.map.c[1][0] != 0;
    const std::size_t vertical = !curve ? 3 : coupled ? 8 : 6;
    return pieces.size() * (2 + vertical + (every_domain_whole() ? 0 : 2));
}

bool FractalFunction::domains_are_unions_of_ranges(double tolerance) const {
    auto on_boundary = [&](double t) {
        for (const Piece& p : pieces)
            if (std::abs(p.lo - t) <= tolerance || std::abs(p.hi - t) <= tolerance) return true;
        return false;
    };
    return std::all_of(pieces.begin(), pieces.end(),
                       [&](const Piece& p) { return on_boundary(p.alpha) && on_boundary(p.beta); });
}

void set_range(Piece& p, double lo, double hi) {
    p.lo = lo;
    p.hi = hi;
    const double a = (hi - lo) / (p.beta - p.alpha);
    p.map.a = p.map.a < 0 ? -a : a;
    p.map.d = p.map.a < 0 ? hi - p.map.a * p.alpha : lo - p.map.a * p.alpha;
}

std::string make_consistent(FractalFunction& f, double tolerance) {
    if (f.pieces.empty()) return "no maps";
    for (Piece& p : f.pieces) {
        const double u = p.map.map_t(p.alpha), w = p.map.map_t(p.beta);
        p.lo = std::min(u, w);
        p.hi = std::max(u, w);
    }
    std::sort(f.pieces.begin(), f.pieces.end(), [](const Piece& p, const Piece& q) { return p.lo < q.lo; });
    std::vector<double> cut{f.t0};
    for (std::size_t i = 0; i + 1 < f.pieces.size(); ++i) {
        const double gap = f.pieces[i + 1].lo - f.pieces[i].hi;
        if (std::abs(gap) > tolerance)
            return fmt::format("the ranges [{:.4g}, {:.4g}] and [{:.4g}, {:.4g}] of two maps {} by {:.3g}",
                               f.pieces[i].lo, f.pieces[i].hi, f.pieces[i + 1].lo, f.pieces[i + 1].hi,
                               gap > 0 ? "leave a gap" : "overlap", std::abs(gap));
        cut.push_back((f.pieces[i].hi + f.pieces[i + 1].lo) / 2);
    }
    cut.push_back(f.t1);
    if (std::abs(f.pieces.front().lo - f.t0) > tolerance || std::abs(f.pieces.back().hi - f.t1) > tolerance)
        return fmt::format("the ranges of the maps cover [{:.4g}, {:.4g}], not the data's [{:.4g}, {:.4g}]",
                           f.pieces.front().lo, f.pieces.back().hi, f.t0, f.t1);
    for (std::size_t i = 0; i < f.pieces.size(); ++i) {
        Piece& p = f.pieces[i];
        if (!(cut[i + 1] > cut[i]) || !(p.beta > p.alpha)) return "a map with an empty range or domain";
        set_range(p, cut[i], cut[i + 1]);
        if (!(std::abs(p.map.a) < 1))
            return fmt::format("the map onto [{:.4g}, {:.4g}] does not contract in t (|a| = {:.4g})", p.lo,
                               p.hi, std::abs(p.map.a));
        if (!(p.map.vertical_norm(f.curve) < 1))
            return fmt::format("the map onto [{:.4g}, {:.4g}] does not contract vertically (scaling {:.4g})",
                               p.lo, p.hi, p.map.vertical_norm(f.curve));
    }
    return "";
}

namespace {

double peak_to_peak(const std::vector<double>& v) {
    const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
    return *hi - *lo;
}

double max_abs(const std::vector<double>& v) {
    double m = 0;
    for (double x : v) m = std::max(m, std::abs(x));
    return m;
}

// v rounded to 8 bits over [lo, hi]; a symmetric range has the levels -127..127, so 0 is exact.
double quantize(double v, double lo, double hi) {
    if (lo == -hi) {
        const double step = hi / 127;
        return std::clamp(std::round(v / step), -127.0, 127.0) * step;
    }
    const double step = (hi - lo) / 255;
    return lo + std::clamp(std::round((v - lo) / step), 0.0, 255.0) * step;
}

std::string number(double v) {
    return fmt::format("{}", v == 0 ? 0.0 : v); // no "-0"
}

} // namespace

FitError measure(const FractalFunction& f, const Samples& data) {
    FitError r;
    double sum = 0;
    for (std::size_t i = 0; i < data.size(); ++i) {
        const auto v = f(data.t[i]);
        const double dx = v[0] - data.x[i], dy = data.curve() ? v[1] - data.y[i] : 0;
        const double e2 = dx * dx + dy * dy;
        sum += e2;
        r.max_error = std::max(r.max_error, std::sqrt(e2));
    }
    r.mse = sum / double(data.size());
    double peak = peak_to_peak(data.x);
    if (data.curve()) peak = std::max(peak, peak_to_peak(data.y));
    r.psnr = r.mse > 0 ? 20 * std::log10(peak / std::sqrt(r.mse)) : std::numeric_limits<double>::infinity();
    return r;
}

void quantize8(FractalFunction& f, const Samples& data) {
    // Stored: each range's end, each domain's bounds, the orientation, and the vertical part; a and d follow
    // from the range and the domain.
    const double span = f.t1 - f.t0;
    double values = peak_to_peak(data.x), top = max_abs(data.x);
    if (data.curve()) {
        values = std::max(values, peak_to_peak(data.y));
        top = std::max(top, max_abs(data.y));
    }
    const double b_max = 4 * values / span,
                 e_max = 2 * top + b_max * std::max(std::abs(f.t0), std::abs(f.t1));
    const bool whole = f.every_domain_whole();
    for (std::size_t i = 0; i < f.pieces.size(); ++i) {
        Piece& p = f.pieces[i];
        if (i + 1 < f.pieces.size()) p.hi = quantize(p.hi, f.t0, f.t1);
        if (i > 0) p.lo = f.pieces[i - 1].hi;
        if (!whole) {
            p.alpha = quantize(p.alpha, f.t0, f.t1);
            p.beta = quantize(p.beta, f.t0, f.t1);
        }
        set_range(p, p.lo, p.hi);
        for (int k = 0; k < (f.curve ? 2 : 1); ++k) {
            p.map.b[k] = quantize(p.map.b[k], -b_max, b_max);
            p.map.e[k] = quantize(p.map.e[k], -e_max, e_max);
            for (int j = 0; j < (f.curve ? 2 : 1); ++j) p.map.c[k][j] = quantize(p.map.c[k][j], -1, 1);
        }
    }
}

std::string to_frac(const FractalFunction& f, const std::string& name, const std::string& comment,
                    std::size_t grid) {
    // The matrix of s, its t part (a, d) written as given.
    auto written = [&](const Shear& s, const std::string& a, const std::string& d) {
        if (!f.curve)
            return fmt::format("[[{}, 0, {}], [{}, {}, {}], [0, 0, 1]]", a, d, number(s.b[0]),
                               number(s.c[0][0]), number(s.e[0]));
        return fmt::format("[[{}, 0, 0, {}], [{}, {}, {}, {}], [{}, {}, {}, {}], [0, 0, 0, 1]]", a, d,
                           number(s.b[0]), number(s.c[0][0]), number(s.c[0][1]), number(s.e[0]),
                           number(s.b[1]), number(s.c[1][0]), number(s.c[1][1]), number(s.e[1]));
    };
    auto matrix = [&](const Shear& s) { return written(s, number(s.a), number(s.d)); };
    const char* space = f.curve ? "R3" : "R2";
    std::string out = comment;
    if (!f.every_domain_whole() && !f.domains_are_unions_of_ranges(1e-9 * (f.t1 - f.t0))) {
        // A PFIF: ends on the grid as exact fractions of it, the t part as the exact map of the domain
        // onto the range (orientation kept), so that the compiler finds the ranges tiling exactly.
        const double span = f.t1 - f.t0;
        const bool unit = f.t0 == 0 && f.t1 == 1;
        auto cells = [&](double v) -> std::optional<long long> { // v's grid index, if it is on the grid
            const double k = grid ? (v - f.t0) / span * static_cast<double>(grid) : 0.5;
            if (!grid || std::abs(k - std::round(k)) > 1e-9) return std::nullopt;
            return std::llround(k);
        };
        auto fraction = [](long long n, long long d) {
            const long long g = std::gcd(n, d) * (d < 0 ? -1 : 1);
            return d / g == 1 ? fmt::format("{}", n / g) : fmt::format("{}/{}", n / g, d / g);
        };
        auto end = [&](double v) {
            const auto k = cells(v);
            if (!k) return number(v);
            const auto g = static_cast<long long>(grid);
            if (unit) return fraction(*k, g);
            return fmt::format("({} + {} * ({} - {}))", number(f.t0), fraction(*k, g), number(f.t1),
                               number(f.t0));
        };
        out += fmt::format("fif {} {{\n", name);
        for (const Piece& p : f.pieces) {
            const bool forward = p.map.a > 0;
            const double from = forward ? p.lo : p.hi, to = forward ? p.hi : p.lo; // images of alpha, beta
            const auto ka = cells(p.alpha), kb = cells(p.beta), kf = cells(from), kt = cells(to);
            std::string a, d;
            if (unit && ka && kb && kf && kt) { // a = (to - from) / (beta - alpha), d = from - a alpha
                const auto g = static_cast<long long>(grid), width = *kb - *ka;
                a = fraction(*kt - *kf, width);
                d = fraction(*kf * width - (*kt - *kf) * *ka, g * width);
            } else {
                a = fmt::format("({} - {}) / ({} - {})", end(to), end(from), end(p.beta), end(p.alpha));
                d = fmt::format("{} - {} * {}", end(from), a, end(p.alpha));
            }
            out += fmt::format("    piece [{}, {}] {};\n", end(p.alpha), end(p.beta), written(p.map, a, d));
        }
        return out + "}\n";
    }
    // An RFIF: the state r_i is the graph over range i; its arcs lead to the states of the ranges that make
    // up its domain. The initial state is the whole graph, the union of the ranges.
    const double tolerance = 1e-9 * (f.t1 - f.t0);
    if (f.every_domain_whole()) {
        out += fmt::format("ifs {} in {} {{\n", name, space);
        for (std::size_t i = 0; i < f.pieces.size(); ++i)
            out += fmt::format("    T{} = {};\n", i + 1, matrix(f.pieces[i].map));
        return out + "}\n";
    }
    out += fmt::format("cifs {} {{\n    state graph", name);
    for (std::size_t i = 0; i < f.pieces.size(); ++i) out += fmt::format(", r{}", i + 1);
    out += fmt::format(" in {};\n", space);
    for (std::size_t i = 0; i < f.pieces.size(); ++i)
        out += fmt::format("    graph -> r{} : identity;\n", i + 1);
    for (std::size_t i = 0; i < f.pieces.size(); ++i) {
        const Piece& p = f.pieces[i];
        for (std::size_t j = 0; j < f.pieces.size(); ++j)
            if (f.pieces[j].lo >= p.alpha - tolerance && f.pieces[j].hi <= p.beta + tolerance)
                out +=
                    fmt::format("    r{} -> r{} : T{}_{} = {};\n", i + 1, j + 1, i + 1, j + 1, matrix(p.map));
    }
    return out + "    initial graph;\n}\n";
}

Samples sample(const FractalFunction& f, std::size_t count) {
    Samples s;
    for (std::size_t i = 0; i < count; ++i) {
        const double t = f.t0 + (f.t1 - f.t0) * double(i) / double(count - 1);
        const auto v = f(t);
        s.t.push_back(t);
        s.x.push_back(v[0]);
        if (f.curve) s.y.push_back(v[1]);
    }
    return s;
}

} // namespace frac::rt::fit
