// The interval operations the interpreters run per instruction (add, sub, mul, neg, sqr, sqrt, abs,
// min, max), inline, with the rounding helpers they use. numeric/interval.cpp defines num::add and the
// others with them, so the inlined and the called forms are one code.
//
// Include only from files compiled with -frounding-math -fno-fast-math (the libraries of numeric/,
// ir/ and backend/interp/, bench/carpet_handwritten.cpp): the upper bounds are plain expressions that must
// round upward at run time, which the optimiser may not assume of code compiled without it. They require
// upward rounding (num::UpwardRounding) like the rest of interval.hpp's operations.
#pragma once

#include "numeric/interval.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

namespace frac::num::kernels {

// Pins a value in a register the optimiser knows nothing about; emits no instruction.
inline double opaque(double x) {
#if defined(__x86_64__)
    asm("" : "+x"(x));
#elif defined(__aarch64__)
    asm("" : "+w"(x));
#else
    asm("" : "+g"(x));
#endif
    return x;
}

// Neighbouring doubles, exact in any rounding mode (glibc's nextafter is much slower).
inline double next_up(double x) {
    if (std::isnan(x) || x == inf) return x;
    if (x == 0) return std::numeric_limits<double>::denorm_min();
    const auto bits = std::bit_cast<std::uint64_t>(x);
    return std::bit_cast<double>(x > 0 ? bits + 1 : bits - 1);
}
inline double next_down(double x) {
    return -next_up(-x);
}

// Bounds that came out NaN (inf - inf on degenerate [inf, inf] operands) widen to infinity.
inline Interval widen_nan(double lo, double hi) {
    return {std::isnan(lo) ? -inf : lo, std::isnan(hi) ? inf : hi};
}

// Rounded-down operations via RD(f) = -RU(-f); valid only under upward rounding.
inline double add_down(double x, double y) {
    return -opaque(opaque(-x) - y);
}
inline double sub_down(double x, double y) {
    return -opaque(opaque(-x) + y);
}
inline double mul_down(double x, double y) {
    return -opaque(opaque(-x) * y);
}
inline double div_down(double x, double y) {
    return -opaque(opaque(-x) / y);
}

// Products in which a zero factor beats an infinite one (0 * inf = 0, IEEE 1788).
inline double mul_up0(double x, double y) {
    return x == 0 || y == 0 ? 0.0 : x * y;
}
inline double mul_down0(double x, double y) {
    return x == 0 || y == 0 ? 0.0 : mul_down(x, y);
}

inline Interval add(Interval a, Interval b) {
    if (a.is_empty() || b.is_empty()) return Interval::empty();
    return widen_nan(add_down(a.lo, b.lo), a.hi + b.hi);
}

inline Interval sub(Interval a, Interval b) {
    if (a.is_empty() || b.is_empty()) return Interval::empty();
    return widen_nan(sub_down(a.lo, b.hi), a.hi - b.lo);
}

// Inlined into the interpreters' loops even though it is long: a call there costs a third of it.
[[gnu::always_inline]] inline Interval mul(Interval a, Interval b) {
    if (a.is_empty() || b.is_empty()) return Interval::empty();
    if (a.lo == a.hi || b.lo == b.hi) {
        // A thin factor (a constant): the four corners below are two equal pairs, and the first of the
        // smallest (largest) is the one at y.lo unless the one at y.hi is strictly smaller (larger).
        const double x = b.lo == b.hi ? b.lo : a.lo;
        const Interval y = b.lo == b.hi ? a : b;
        const double p = mul_down0(y.lo, x), q = mul_down0(y.hi, x);
        const double P = mul_up0(y.lo, x), Q = mul_up0(y.hi, x);
        return {q < p ? q : p, P < Q ? Q : P};
    }
    // The product is bilinear, so its extremes are at the corners.
    return {std::min(
                {mul_down0(a.lo, b.lo), mul_down0(a.lo, b.hi), mul_down0(a.hi, b.lo), mul_down0(a.hi, b.hi)}),
            std::max({mul_up0(a.lo, b.lo), mul_up0(a.lo, b.hi), mul_up0(a.hi, b.lo), mul_up0(a.hi, b.hi)})};
}

inline Interval neg(Interval a) {
    return {-a.hi, -a.lo};
}

inline Interval abs(Interval a) {
    if (a.is_empty() || a.lo >= 0) return a;
    if (a.hi <= 0) return kernels::neg(a);
    return {0.0, std::max(-a.lo, a.hi)};
}

// [RD(m.lo^2), RU(m.hi^2)] for m = |a|: the bounds of powi(a, 2), one product each.
inline Interval sqr(Interval a) {
    if (a.is_empty()) return a;
    const Interval m = kernels::abs(a);
    return {mul_down(m.lo, m.lo), m.hi * m.hi};
}

inline Interval sqrt(Interval a) {
    if (a.is_empty() || a.hi < 0) return Interval::empty();
    const double lo = std::max(a.lo, 0.0);
    const double r = std::sqrt(lo); // RU(sqrt(lo))
    // r * r - lo is exact in the fma, so its sign says whether r overshoots.
    return {std::fma(r, r, -lo) > 0 ? next_down(r) : r, std::sqrt(a.hi)};
}

inline Interval min(Interval a, Interval b) {
    if (a.is_empty() || b.is_empty()) return Interval::empty();
    return {std::min(a.lo, b.lo), std::min(a.hi, b.hi)};
}

inline Interval max(Interval a, Interval b) {
    if (a.is_empty() || b.is_empty()) return Interval::empty();
    return {std::max(a.lo, b.lo), std::max(a.hi, b.hi)};
}

} // namespace frac::num::kernels
