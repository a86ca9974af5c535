// Interval arithmetic with guaranteed outward rounding.
//
// Rounding discipline (see docs/design.md): every function here assumes the FPU rounds UPWARD.
// Callers set that mode once per evaluation with `UpwardRounding` (RAII), never per operation.
// Upper bounds are computed directly (rounded up); lower bounds are computed as the negation of
// an upward-rounded expression of negated operands, e.g. lo(a+b) = -((-a.lo) - b.lo). Only one
// rounding mode is used inside an expression, so compilers cannot merge an upward and a downward
// operation (GCC 12 and clang 14 do that under -frounding-math).
//
// Special values:
//  - The empty interval is {+inf, -inf}; every function maps an empty operand to empty.
//  - Unbounded intervals use +-inf endpoints; 0 * inf is taken as 0 (IEEE 1788 convention).
//  - Functions are evaluated on the part of the argument inside their domain: sqrt([-1, 4]) = [0, 2],
//    log([-1, 1]) = [-inf, 0]; an argument wholly outside the domain gives empty.
//  - Division by an interval containing 0 gives the hull of the two half-line results (often entire);
//    division by [0, 0] gives empty.
//  - NaN is never produced for a non-empty input: bounds that would be NaN are replaced by -inf/+inf.
#pragma once

#include <cstdint>
#include <limits>
#include <string>

namespace frac::num {

inline constexpr double inf = std::numeric_limits<double>::infinity();

struct Interval {
    double lo = 0.0;
    double hi = 0.0;

    constexpr Interval() = default;
    constexpr Interval(double v) : lo(v), hi(v) {} // NOLINT: a double is a thin interval
    constexpr Interval(double l, double h) : lo(l), hi(h) {}

    static constexpr Interval empty() { return {inf, -inf}; }
    static constexpr Interval entire() { return {-inf, inf}; }

    constexpr bool is_empty() const { return !(lo <= hi); }
    constexpr bool is_thin() const { return lo == hi; }
    constexpr bool contains(double v) const { return lo <= v && v <= hi; }
    constexpr bool contains(Interval o) const { return o.is_empty() || (lo <= o.lo && o.hi <= hi); }
    constexpr bool operator==(const Interval&) const = default;
};

// Sets the FPU to round upward for its lifetime and restores the previous mode afterwards.
class UpwardRounding {
public:
    UpwardRounding();
    ~UpwardRounding();
    UpwardRounding(const UpwardRounding&) = delete;
    UpwardRounding& operator=(const UpwardRounding&) = delete;

private:
    int saved_;
};

// True when the FPU currently rounds upward (used in debug checks and tests).
bool rounding_is_upward();

// Width hi - lo rounded up (inf for unbounded, 0 for empty), midpoint (finite for bounded intervals).
double width(Interval a);
double midpoint(Interval a);
// Largest absolute value of a member.
double magnitude(Interval a);
Interval hull(Interval a, Interval b);
Interval intersect(Interval a, Interval b);

// ---- Everything below requires upward rounding (UpwardRounding active). ----

Interval add(Interval a, Interval b);
Interval sub(Interval a, Interval b);
Interval mul(Interval a, Interval b);
Interval div(Interval a, Interval b);
Interval neg(Interval a);
Interval sqr(Interval a);
// a^n for any integer n (negative n: 1 / a^|n|; n = 0: [1, 1], also for a containing 0).
Interval powi(Interval a, std::int64_t n);
// a^b for real b: powi when b is a thin integer, else exp(b * log(a)) on the part a >= 0.
Interval pow(Interval a, Interval b);
Interval sqrt(Interval a);
Interval abs(Interval a);
Interval min(Interval a, Interval b);
Interval max(Interval a, Interval b);
Interval floor(Interval a);
Interval ceil(Interval a);
// x mod 1 = x - floor(x), in [0, 1): the paper's d_m.
Interval mod1(Interval a);
// Distance to the integers: dz(x) = min(x - floor(x), ceil(x) - x), in [0, 1/2].
Interval dz(Interval a);
Interval sin(Interval a);
Interval cos(Interval a);
Interval tan(Interval a);
Interval exp(Interval a);
Interval log(Interval a);
// Angle of the point (x, y) in [-pi, pi], like std::atan2(y, x).
Interval atan2(Interval y, Interval x);

// Outward enclosures of constants.
Interval pi();
Interval e();
// Outward enclosure of a decimal literal such as "0.1" (which no double equals).
Interval from_decimal(const std::string& text);

// Point (round-to-nearest) versions of the non-standard builtins, for point evaluation.
namespace point {
double dz(double x);
double mod1(double x);
} // namespace point

} // namespace frac::num
