// Interval arithmetic with guaranteed outward rounding; see interval.hpp for the contract.
//
// Everything after the utilities runs with the FPU rounding upward. An upper bound is the plain
// expression (rounded up); a lower bound is RD(f) = -RU(-f), computed by the *_down helpers. This file
// is compiled with -frounding-math, and `opaque` additionally hides the negated operands from the
// optimiser, so it cannot turn -((-x) - y) back into x + y.
#include "numeric/interval.hpp"

#include "numeric/interval_kernels.hpp"

#include "numeric/llvm_libc.hpp"

#include <algorithm>
#include <bit>
#include <cfenv>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace frac::num {
namespace {

// Keeps memory accesses and calls from moving across a rounding-mode change.
inline void barrier() {
    asm volatile("" ::: "memory");
}

using kernels::add_down;
using kernels::div_down;
using kernels::mul_down;
using kernels::mul_down0;
using kernels::mul_up0;
using kernels::next_down;
using kernels::next_up;
using kernels::sub_down;
using kernels::widen_nan;

constexpr double pi_lo = 0x1.921fb54442d18p+1; // RN(pi) < pi
constexpr double pi_hi = 0x1.921fb54442d19p+1;
constexpr double e_lo = 0x1.5bf0a8b145769p+1; // RN(e) < e
constexpr double e_hi = 0x1.5bf0a8b14576ap+1;
constexpr Interval two_over_pi{0x1.45f306dc9c882p-1, 0x1.45f306dc9c883p-1}; // RN(2/pi) > 2/pi

// Beyond 2^51 the quadrant bookkeeping of sin/cos/tan would need more than 53 bits; there the
// result is the whole range anyway (consecutive doubles are more than 2 pi apart from 2^53).
constexpr double trig_limit = 0x1p51;

// Whether the interval t (|t| < 2^52) contains an integer congruent to r modulo 4. With t an enclosure
// of x / (pi/2), that decides whether x may be an extremum or pole of sin, cos or tan.
bool hits_mod4(Interval t, int r) {
    auto n = static_cast<std::int64_t>(std::ceil(t.lo));
    n += ((r - n) % 4 + 4) % 4;
    return static_cast<double>(n) <= t.hi;
}

// The libc functions return RU(f(x)). For lower bounds the odd ones use RD(f(x)) = -RU(f(-x)); the
// others step one double down, which is < f(x) unless f(x) is a double: by Lindemann's theorem only
// at the exact points special-cased here.
double sin_down(double x) {
    return -crlibm::sin(-x);
}
double cos_down(double x) {
    return x == 0 ? 1.0 : std::max(-1.0, next_down(crlibm::cos(x)));
}
double tan_down(double x) {
    return -crlibm::tan(-x);
}
double exp_down(double x) {
    return x == 0 ? 1.0 : std::max(0.0, next_down(crlibm::exp(x)));
}
double log_down(double x) {
    return x == 1 ? 0.0 : next_down(crlibm::log(x));
}

// x^n for x >= 0 by repeated squaring; each step is monotone in its operands, so rounding every
// product in one direction bounds the exact power in that direction.
double pow_up(double x, std::uint64_t n) {
    double r = 1.0;
    for (double p = x;; p *= p) {
        if (n & 1) r *= p;
        if ((n >>= 1) == 0) return r;
    }
}
double pow_down(double x, std::uint64_t n) {
    double r = 1.0;
    for (double p = x;; p = mul_down(p, p)) {
        if (n & 1) r = mul_down(r, p);
        if ((n >>= 1) == 0) return r;
    }
}

// a^n for n >= 1.
Interval pow_positive(Interval a, std::uint64_t n) {
    if (n % 2 == 0) {
        const Interval m = abs(a);
        return {pow_down(m.lo, n), pow_up(m.hi, n)};
    }
    // Odd powers are increasing and odd: x^n = -((-x)^n).
    return {a.lo >= 0 ? pow_down(a.lo, n) : -pow_up(-a.lo, n),
            a.hi >= 0 ? pow_up(a.hi, n) : -pow_down(-a.hi, n)};
}

// Distance of a double to the nearest integer, rounded down / up (x - floor(x) can be inexact for
// negative x of small magnitude).
double dz_down(double x) {
    return std::min(sub_down(x, std::floor(x)), sub_down(std::ceil(x), x));
}
double dz_up(double x) {
    return std::min(x - std::floor(x), std::ceil(x) - x);
}

} // namespace

UpwardRounding::UpwardRounding() : saved_(std::fegetround()) {
    std::fesetround(FE_UPWARD);
    barrier();
}

UpwardRounding::~UpwardRounding() {
    barrier();
    std::fesetround(saved_);
}

bool rounding_is_upward() {
    return std::fegetround() == FE_UPWARD;
}

double width(Interval a) {
    if (a.is_empty()) return 0.0;
    if (rounding_is_upward()) return a.hi - a.lo;
    // Callable in any mode: switch to upward for the one subtraction (-frounding-math keeps it inside).
    const UpwardRounding upward;
    return a.hi - a.lo;
}

double midpoint(Interval a) {
    if (a.is_empty()) return std::numeric_limits<double>::quiet_NaN();
    if (a.lo == -inf && a.hi == inf) return 0.0;
    if (a.lo == -inf) return std::numeric_limits<double>::lowest();
    if (a.hi == inf) return std::numeric_limits<double>::max();
    // Halving first cannot overflow; the clamp guards against rounding of subnormal halves.
    return std::clamp(0.5 * a.lo + 0.5 * a.hi, a.lo, a.hi);
}

double magnitude(Interval a) {
    return a.is_empty() ? 0.0 : std::max(std::abs(a.lo), std::abs(a.hi));
}

Interval hull(Interval a, Interval b) {
    if (a.is_empty()) return b;
    if (b.is_empty()) return a;
    return {std::min(a.lo, b.lo), std::max(a.hi, b.hi)};
}

Interval intersect(Interval a, Interval b) {
    const Interval r{std::max(a.lo, b.lo), std::min(a.hi, b.hi)};
    return r.is_empty() ? Interval::empty() : r;
}

Interval add(Interval a, Interval b) {
    return kernels::add(a, b);
}

Interval sub(Interval a, Interval b) {
    return kernels::sub(a, b);
}

Interval mul(Interval a, Interval b) {
    return kernels::mul(a, b);
}

Interval div(Interval a, Interval b) {
    if (a.is_empty() || b.is_empty() || (b.lo == 0 && b.hi == 0)) return Interval::empty();
    if (b.lo > 0) {
        if (a.lo >= 0) return widen_nan(div_down(a.lo, b.hi), a.hi / b.lo);
        if (a.hi <= 0) return widen_nan(div_down(a.lo, b.lo), a.hi / b.hi);
        return widen_nan(div_down(a.lo, b.lo), a.hi / b.lo);
    }
    if (b.hi < 0) {
        if (a.lo >= 0) return widen_nan(div_down(a.hi, b.hi), a.lo / b.lo);
        if (a.hi <= 0) return widen_nan(div_down(a.hi, b.lo), a.lo / b.hi);
        return widen_nan(div_down(a.hi, b.hi), a.lo / b.hi);
    }
    // b contains 0: a / b is the hull of a / [b.lo, 0) and a / (0, b.hi].
    if (a.lo == 0 && a.hi == 0) return {0.0, 0.0};
    if (b.lo < 0 && b.hi > 0) return Interval::entire();
    if (a.lo >= 0) return b.lo == 0 ? widen_nan(div_down(a.lo, b.hi), inf) : widen_nan(-inf, a.lo / b.lo);
    if (a.hi <= 0) return b.lo == 0 ? widen_nan(-inf, a.hi / b.hi) : widen_nan(div_down(a.hi, b.lo), inf);
    return Interval::entire();
}

Interval neg(Interval a) {
    return kernels::neg(a);
}

Interval sqr(Interval a) {
    return kernels::sqr(a);
}

Interval powi(Interval a, std::int64_t n) {
    if (a.is_empty()) return a;
    if (n == 0) return {1.0, 1.0};
    // 0 - n in unsigned arithmetic is |n| even for the most negative n.
    if (n < 0) return div(Interval(1.0), pow_positive(a, 0 - static_cast<std::uint64_t>(n)));
    return pow_positive(a, static_cast<std::uint64_t>(n));
}

Interval pow(Interval a, Interval b) {
    if (a.is_empty() || b.is_empty()) return Interval::empty();
    if (b.is_thin() && std::trunc(b.lo) == b.lo) {
        if (std::abs(b.lo) < 0x1p62) return powi(a, static_cast<std::int64_t>(b.lo));
        // Doubles this large are even integers: a^b = |a|^b.
        a = abs(a);
    }
    const Interval base = intersect(a, {0.0, inf});
    if (base.is_empty()) return base;
    // 0^b is 0 for b > 0 and undefined otherwise; log(0) = -inf below already covers x -> 0.
    if (base.hi == 0) return b.hi > 0 ? Interval{0.0, 0.0} : Interval::empty();
    return exp(mul(b, log(base)));
}

Interval sqrt(Interval a) {
    return kernels::sqrt(a);
}

Interval abs(Interval a) {
    return kernels::abs(a);
}

Interval min(Interval a, Interval b) {
    return kernels::min(a, b);
}

Interval max(Interval a, Interval b) {
    return kernels::max(a, b);
}

Interval floor(Interval a) {
    return a.is_empty() ? a : Interval{std::floor(a.lo), std::floor(a.hi)};
}

Interval ceil(Interval a) {
    return a.is_empty() ? a : Interval{std::ceil(a.lo), std::ceil(a.hi)};
}

Interval mod1(Interval a) {
    if (a.is_empty()) return a;
    if (!std::isfinite(a.lo) || !std::isfinite(a.hi)) return {0.0, 1.0};
    const double f = std::floor(a.lo);
    if (std::floor(a.hi) != f) return {0.0, 1.0}; // wraps around at an integer
    return {sub_down(a.lo, f), a.hi - f};
}

Interval dz(Interval a) {
    if (a.is_empty()) return a;
    if (!(a.hi - a.lo < 1)) return {0.0, 0.5}; // a whole period, or unbounded
    // dz is monotone between consecutive integers and half-integers, where it is 0 and 1/2.
    double lo = std::min(dz_down(a.lo), dz_down(a.hi));
    double hi = std::max(dz_up(a.lo), dz_up(a.hi));
    if (std::ceil(a.lo) <= a.hi) lo = 0.0;
    // Smallest half-integer >= a.lo; beyond 2^52 none is a double and the rounding only overshoots.
    double half = std::floor(a.lo) + 0.5;
    if (half < a.lo) half += 1.0;
    if (half <= a.hi) hi = 0.5;
    return {lo, hi};
}

Interval sin(Interval a) {
    if (a.is_empty()) return a;
    if (!(magnitude(a) <= trig_limit)) return {-1.0, 1.0};
    // t encloses x / (pi/2): sin has its maxima at t = 1 (mod 4) and its minima at t = 3 (mod 4).
    const Interval t = mul(a, two_over_pi);
    if (t.hi - t.lo >= 4) return {-1.0, 1.0};
    // Extremes of a piecewise monotone function are at the endpoints or at critical points.
    const double lo = hits_mod4(t, 3) ? -1.0 : std::min(sin_down(a.lo), sin_down(a.hi));
    const double hi = hits_mod4(t, 1) ? 1.0 : std::max(crlibm::sin(a.lo), crlibm::sin(a.hi));
    return {lo, hi};
}

Interval cos(Interval a) {
    if (a.is_empty()) return a;
    if (!(magnitude(a) <= trig_limit)) return {-1.0, 1.0};
    // cos has its maxima at t = 0 (mod 4) and its minima at t = 2 (mod 4).
    const Interval t = mul(a, two_over_pi);
    if (t.hi - t.lo >= 4) return {-1.0, 1.0};
    const double lo = hits_mod4(t, 2) ? -1.0 : std::min(cos_down(a.lo), cos_down(a.hi));
    const double hi = hits_mod4(t, 0) ? 1.0 : std::max(crlibm::cos(a.lo), crlibm::cos(a.hi));
    return {lo, hi};
}

Interval tan(Interval a) {
    if (a.is_empty()) return a;
    if (!(magnitude(a) <= trig_limit)) return Interval::entire();
    // Poles at odd t; between two poles tan is increasing.
    const Interval t = mul(a, two_over_pi);
    if (t.hi - t.lo >= 2 || hits_mod4(t, 1) || hits_mod4(t, 3)) return Interval::entire();
    return {tan_down(a.lo), crlibm::tan(a.hi)};
}

Interval exp(Interval a) {
    if (a.is_empty()) return a;
    return {exp_down(a.lo), crlibm::exp(a.hi)};
}

Interval log(Interval a) {
    // The domain is x > 0, so [0, 0] (or anything <= 0) gives empty and a lower bound 0 gives -inf.
    if (a.is_empty() || a.hi <= 0) return Interval::empty();
    return {a.lo <= 0 ? -inf : log_down(a.lo), crlibm::log(a.hi)};
}

Interval atan2(Interval y, Interval x) {
    if (y.is_empty() || x.is_empty()) return Interval::empty();
    // A box in the closed upper half-plane (y >= 0) sees angles in [0, pi] only, continuously: on the
    // cut the real angle atan2(0, x < 0) is pi, which is what atan2(+0, x) gives for the corners.
    // (The closed lower half-plane has no such property: its points with y = 0, x < 0 have angle pi.)
    const bool upper = y.lo == 0 && y.hi >= 0;
    if (upper) {
        y.lo = 0.0; // +0, also for -0
        if (y.hi == 0) y.hi = 0.0;
    }
    if (upper && x.lo <= 0 && x.hi >= 0) return {0.0, pi_hi};
    // A box containing the origin, or meeting the branch cut (x < 0, y = 0), can see every angle.
    if (!upper && x.lo <= 0 && y.lo <= 0 && y.hi >= 0) return {-pi_hi, pi_hi};
    // Otherwise the box lies in an open half-plane of the cut plane, where the angle is continuous and
    // its extremes over a convex set are at vertices. glibc's atan2 is accurate to well under 1 ulp
    // (measured at <= 0.502 ulp in both nearest and upward mode; glibc documents at most 1 ulp), so
    // widening each corner by 4 ulps encloses the exact angles with a wide margin.
    const double corners[] = {std::atan2(y.lo, x.lo), std::atan2(y.lo, x.hi), std::atan2(y.hi, x.lo),
                              std::atan2(y.hi, x.hi)};
    double lo = *std::min_element(std::begin(corners), std::end(corners));
    double hi = *std::max_element(std::begin(corners), std::end(corners));
    for (int i = 0; i < 4; ++i) {
        lo = next_down(lo);
        hi = next_up(hi);
    }
    return {std::max(lo, -pi_hi), std::min(hi, pi_hi)};
}

Interval pi() {
    return {pi_lo, pi_hi};
}

Interval e() {
    return {e_lo, e_hi};
}

Interval from_decimal(const std::string& text) {
    // glibc's strtod rounds in the current mode, so two parses give the outward enclosure.
    const int saved = std::fegetround();
    char* end = nullptr;
    std::fesetround(FE_DOWNWARD);
    barrier();
    const double lo = std::strtod(text.c_str(), &end);
    std::fesetround(FE_UPWARD);
    barrier();
    const double hi = std::strtod(text.c_str(), nullptr);
    std::fesetround(saved);
    if (text.empty() || end != text.c_str() + text.size())
        throw std::invalid_argument("not a decimal number: '" + text + "'");
    return {lo, hi};
}

namespace point {

double dz(double x) {
    return std::min(x - std::floor(x), std::ceil(x) - x);
}

double mod1(double x) {
    return x - std::floor(x);
}

} // namespace point

} // namespace frac::num
