#include "ir/series_tail.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace frac::ir {

using namespace frac::num;

namespace {
constexpr double inf = std::numeric_limits<double>::infinity();
}

Interval series_term_bound(Interval a, Interval b, bool has_b, Interval gamma_i, std::int64_t i) {
    const Interval coeff = has_b ? add(a, mul(b, Interval(static_cast<double>(i)))) : a;
    return mul(coeff, gamma_i);
}

namespace {

bool tends_to_zero(Interval a, Interval b) {
    return std::isfinite(a.lo) && std::isfinite(a.hi) && std::isfinite(b.lo) && std::isfinite(b.hi);
}

} // namespace

Interval series_tail(Op kind, Interval a, Interval b, bool has_b, Interval gamma, std::int64_t n) {
    const Interval g1 = powi(gamma, n + 1); // gamma^(n+1)
    const Interval one_minus = sub(Interval(1.0), gamma);
    const Interval s0 = div(g1, one_minus); // sum_{i>n} gamma^i
    // sum_{i>n} i gamma^i = gamma^(n+1) ((n+1) - n gamma) / (1 - gamma)^2
    const auto nd = static_cast<double>(n);
    const Interval s1 = has_b
                            ? div(mul(g1, sub(Interval(nd + 1.0), mul(Interval(nd), gamma))), sqr(one_minus))
                            : Interval(0.0);
    switch (kind) {
    case Op::SeriesSum: return has_b ? add(mul(a, s0), mul(b, s1)) : mul(a, s0);
    case Op::SeriesMin: {
        const Interval first = series_term_bound(a, b, has_b, g1, n + 1);
        double lo;
        if (!has_b) {
            lo = std::fmin(0.0, mul(a, g1).lo); // gamma^i decreases: the first tail term is the lowest
        } else {
            const Interval neg_part =
                add(mul(Interval(std::fmax(0.0, -a.lo)), s0), mul(Interval(std::fmax(0.0, -b.lo)), s1));
            lo = std::fmin(0.0, -neg_part.hi);
        }
        // The infimum of terms tending to 0 is <= 0; they tend to 0 when A and B are bounded.
        return {lo, tends_to_zero(a, b) ? std::fmin(0.0, first.hi) : first.hi};
    }
    case Op::SeriesMax: {
        const Interval first = series_term_bound(a, b, has_b, g1, n + 1);
        double hi;
        if (!has_b) {
            hi = std::fmax(0.0, mul(a, g1).hi);
        } else {
            const Interval pos_part =
                add(mul(Interval(std::fmax(0.0, a.hi)), s0), mul(Interval(std::fmax(0.0, b.hi)), s1));
            hi = std::fmax(0.0, pos_part.hi);
        }
        return {tends_to_zero(a, b) ? std::fmax(0.0, first.lo) : first.lo, hi};
    }
    default: break;
    }
    throw std::logic_error("series_tail: not a series op");
}

namespace {

Interval norm_of(const Interval* state, int dims) {
    Interval norm2(0.0);
    for (int c = 0; c < dims; ++c) norm2 = add(norm2, sqr(state[c]));
    return sqrt(norm2);
}

double escape_bound_of_norm(Op kind, const OrbitEscape& e, Interval norm, std::int64_t n) {
    const double none = kind == Op::SeriesMax ? inf : -inf;
    if (!(norm.lo > e.radius)) return none; // not provably outside the ball (NaN included)
    // (slope (|q| - radius) + offset) * scale0 / growth^n, enclosed over the box; its lower end.
    const Interval excess = add(mul(Interval(e.slope), sub(norm, Interval(e.radius))), Interval(e.offset));
    const Interval bound = mul(excess, div(e.scale0, powi(e.growth, n)));
    if (!(bound.lo > -inf)) return none;
    return kind == Op::SeriesMax ? -bound.lo : bound.lo;
}

} // namespace

double escape_bound(Op kind, const OrbitEscape& e, const Interval* state, int dims, std::int64_t n) {
    return escape_bound_of_norm(kind, e, norm_of(state, dims), n);
}

bool escape_stalls(Op kind, double now, double prev, Interval acc) {
    // "Worse" beyond rounding noise: by more than 2^-30 of the previous bound (upward rounding).
    const double slack = escape_stall_slack * std::fabs(prev);
    if (kind == Op::SeriesMax) return now < inf && (now <= acc.hi || now > prev + slack);
    return now > -inf && (now >= acc.lo || now < prev - slack);
}

double lipschitz_centre(Interval* init, int dims) {
    for (int c = 0; c < dims; ++c)
        if (!(std::isfinite(init[c].lo) && std::isfinite(init[c].hi) && init[c].lo <= init[c].hi)) return 0.0;
    Interval h2(0.0);
    for (int c = 0; c < dims; ++c) {
        const double m = midpoint(init[c]);
        const Interval d = sub(init[c], Interval(m)); // [lo - m, hi - m], outward
        h2 = add(h2, Interval(std::fmax(-d.lo, d.hi) * std::fmax(-d.lo, d.hi)));
        init[c] = Interval(m);
    }
    return sqrt(h2).hi;
}

double escape_bound_around(Op kind, const OrbitEscape& e, const Interval* state, int dims, std::int64_t n,
                           double h) {
    const Interval norm = norm_of(state, dims);
    if (h == 0) return escape_bound_of_norm(kind, e, norm, n);
    // |q_n(p) - q_n(c)| <= map_lipschitz^n |p - c|
    const double spread = mul(powi(Interval(e.map_lipschitz), n), Interval(h)).hi;
    return escape_bound_of_norm(kind, e, sub(norm, Interval(0.0, spread)), n);
}

Interval lipschitz_finish(Op kind, const OrbitEscape& e, Interval acc, Interval tail, double bound,
                          std::int64_t n, double h) {
    if (h > 0) {
        // Terms 0..n move by at most lipschitz (map_lipschitz / growth)^k h <= that at k = n (ratio >= 1).
        const Interval ratio = div(Interval(e.map_lipschitz), Interval(e.growth.lo));
        const Interval spread =
            mul(mul(Interval(e.lipschitz), powi(Interval(std::fmax(1.0, ratio.hi)), n)), Interval(h));
        acc = add(acc, Interval(-spread.hi, spread.hi));
    }
    return series_combine(kind, acc, escape_tighten(kind, tail, bound));
}

Interval escape_tighten(Op kind, Interval tail, double bound) {
    if (kind == Op::SeriesMax) {
        const double hi = bound < tail.hi ? bound : tail.hi;
        return {hi < tail.lo ? hi : tail.lo, hi};
    }
    const double lo = bound > tail.lo ? bound : tail.lo;
    return {lo, lo > tail.hi ? lo : tail.hi};
}

bool escape_point_done(Op kind, const OrbitEscape& e, double acc, const double* state, int dims,
                       std::int64_t n) {
    double norm2 = 0.0;
    for (int c = 0; c < dims; ++c) norm2 += state[c] * state[c];
    const double norm = std::sqrt(norm2);
    if (!(norm > e.radius)) return false;
    const double bound = (e.slope * (norm - e.radius) + e.offset) *
                         (e.scale0.lo / std::pow(e.growth.lo, static_cast<double>(n)));
    const double slack = point_stop_ratio * std::fabs(acc);
    return kind == Op::SeriesMax ? -bound <= acc + slack : bound >= acc - slack;
}

void compensated_add(double& acc, double& comp, double term) {
    const double t = acc + term;
    // The low-order bits the rounded sum lost; none to keep once the sum is not finite.
    if (std::isfinite(t)) comp += std::fabs(acc) >= std::fabs(term) ? (acc - t) + term : (term - t) + acc;
    acc = t;
}

double point_magnitude(double lo, double hi) {
    if (std::isnan(lo) || std::isnan(hi)) return inf;
    return std::fmax(std::fabs(lo), std::fabs(hi));
}

double series_point_end(Op kind, double acc, double comp, double a_lo, double a_hi, double b_lo, double b_hi,
                        bool has_b, Interval gamma, std::int64_t n) {
    if (std::isnan(a_lo) || std::isnan(a_hi) || (has_b && (std::isnan(b_lo) || std::isnan(b_hi))))
        return acc + comp;
    // Bounds rounded to nearest may cross by an ulp: order them.
    const Interval a{std::fmin(a_lo, a_hi), std::fmax(a_lo, a_hi)};
    const Interval b = has_b ? Interval{std::fmin(b_lo, b_hi), std::fmax(b_lo, b_hi)} : Interval(0.0);
    Interval tail;
    {
        num::UpwardRounding up;
        tail = series_tail(kind, a, b, has_b, gamma, n);
    }
    // A tail unbounded on one side tells nothing about the value: keep the partial result.
    if (!std::isfinite(tail.lo) || !std::isfinite(tail.hi)) return acc + comp;
    if (kind == Op::SeriesSum) return acc + (comp + num::midpoint(tail));
    return series_combine_point(kind, acc, num::midpoint(tail));
}

Interval series_combine(Op kind, Interval acc, Interval term) {
    switch (kind) {
    case Op::SeriesSum: return add(acc, term);
    case Op::SeriesMin: return min(acc, term);
    case Op::SeriesMax: return max(acc, term);
    default: break;
    }
    throw std::logic_error("series_combine: not a series op");
}

double series_combine_point(Op kind, double acc, double term) {
    switch (kind) {
    case Op::SeriesSum: return acc + term;
    case Op::SeriesMin: return std::fmin(acc, term);
    case Op::SeriesMax: return std::fmax(acc, term);
    default: break;
    }
    throw std::logic_error("series_combine_point: not a series op");
}

} // namespace frac::ir
