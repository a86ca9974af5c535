// Interval kernels of box code computed inline in vector form instead of calling the numeric core lane
// by lane (see box_gen.hpp): sqrt with directed rounding, sin and cos by range reduction and
// polynomials with a proven error bound, exp and log likewise, tan from the sin and cos enclosures, atan2
// from two corners of the box. Lanes a kernel cannot handle call the core.
#include "backend/llvm/box_gen.hpp"

#include <iterator>

namespace frac::jit::box {

SlotState BoxGen::op_sqrt(const SlotState& a) {
    // numeric/interval.cpp: empty when a is empty or a.hi < 0, else [RD(sqrt(max(a.lo, 0))), RU(sqrt(a.hi))].
    Value* e = lor(empty_of(a), lt(a.v.hi, cst(0.0)));
    const IV r{sqrt_down(std_max(a.v.lo, cst(0.0))), sqrt_up(a.v.hi)};
    return result(guard(e, r, empty()), true);
}

namespace {

// Fast lanes have |x| <= trig_fast_limit at both ends (and the other lanes call the core). Then
// k = round(x * 2/pi) has |k| < 2^30, and the reduction below is exact up to the terms of the bound.
constexpr double trig_fast_limit = 0x1p30;

// pi/2 = C1 + C2 + C3 with C1 = RN(pi/2), C2 = RN(pi/2 - C1), |C3| < 2^-109 (C3 = -1.4974e-33).
constexpr double half_pi_1 = 0x1.921fb54442d18p+0;
constexpr double half_pi_2 = 0x1.1a62633145c07p-54;
constexpr double two_over_pi_lo = 0x1.45f306dc9c882p-1; // < 2/pi
constexpr double two_over_pi_hi = 0x1.45f306dc9c883p-1; // > 2/pi

// Taylor coefficients RN(+-1/n!): sin r = r + r z S(z), cos r = 1 + z C(z), z = r^2, highest first.
constexpr double sin_coeffs[] = {0x1.952c77030ad4ap-49,  -0x1.ae7f3e733b81fp-41, 0x1.6124613a86d09p-33,
                                 -0x1.ae64567f544e4p-26, 0x1.71de3a556c734p-19,  -0x1.a01a01a01a01ap-13,
                                 0x1.1111111111111p-7,   -0x1.5555555555555p-3}; // 1/17! .. -1/3!
constexpr double cos_coeffs[] = {-0x1.6827863b97d97p-53, 0x1.ae7f3e733b81fp-45,  -0x1.93974a8c07c9dp-37,
                                 0x1.1eed8eff8d898p-29,  -0x1.27e4fb7789f5cp-22, 0x1.a01a01a01a01ap-16,
                                 -0x1.6c16c16c16c17p-10, 0x1.5555555555555p-5,   -0x1p-1}; // -1/18! .. -1/2!

// The error bound of an endpoint value v (docs/design.md, "Vector interval kernels"): |v - f(x)| <=
// rel_bound |v| + |k| abs_per_k + abs_floor.
constexpr double rel_bound = 0x1p-48;
constexpr double abs_per_k = 0x1p-100;
constexpr double abs_floor = 0x1p-1060;

// exp: fast lanes have -700 <= lo <= hi <= 700, so every value and 2^k are normal doubles.
constexpr double exp_fast_limit = 700;
// ln 2 = L1 + L2 + L3, L1 = RN(ln 2), L2 = RN(ln 2 - L1), |L3| < 2^-110.
constexpr double ln2_1 = 0x1.62e42fefa39efp-1;
constexpr double ln2_2 = 0x1.abc9e3b39803fp-56;
constexpr double inv_ln2 = 0x1.71547652b82fep+0;
// Taylor coefficients RN(1/n!), n = 14 .. 0.
constexpr double exp_coeffs[] = {0x1.93974a8c07c9dp-37,
                                 0x1.6124613a86d09p-33,
                                 0x1.1eed8eff8d898p-29,
                                 0x1.ae64567f544e4p-26,
                                 0x1.27e4fb7789f5cp-22,
                                 0x1.71de3a556c734p-19,
                                 0x1.a01a01a01a01ap-16,
                                 0x1.a01a01a01a01ap-13,
                                 0x1.6c16c16c16c17p-10,
                                 0x1.1111111111111p-7,
                                 0x1.5555555555555p-5,
                                 0x1.5555555555555p-3,
                                 0x1p-1,
                                 0x1p+0,
                                 0x1p+0};
// |v - exp(x)| <= exp_rel_bound v (docs/design.md, "Vector interval kernels").
constexpr double exp_rel_bound = 0x1p-46;

// log: fast lanes have 2^-1022 <= lo <= hi < inf (positive normal doubles). ln 2 = H + L with H =
// 0x1.62e42feep-1 (its last 21 bits zero, so e H is exact for |e| <= 1024) and L = RN(ln 2 - H),
// |ln 2 - H - L| < 2^-80.
constexpr double log_fast_min = 0x1p-1022;
constexpr double ln2_hi = 0x1.62e42feep-1;
constexpr double ln2_lo = 0x1.a39ef35793c76p-33;
constexpr double sqrt2 = 0x1.6a09e667f3bcdp+0;
// log m = 2 s P(s^2), P(z) = sum z^n / (2n + 1): coefficients RN(1/(2n + 1)), n = 10 .. 0.
constexpr double log_coeffs[] = {1.0 / 21, 1.0 / 19, 1.0 / 17, 1.0 / 15, 1.0 / 13, 1.0 / 11,
                                 1.0 / 9,  1.0 / 7,  1.0 / 5,  1.0 / 3,  1.0};
// |v - log(x)| <= log_rel_bound |v| + abs_floor (docs/design.md, "Vector interval kernels").
constexpr double log_rel_bound = 0x1p-47;

// atan2: t = min(|y|, |x|) / max(|y|, |x|) in [0, 1], c = k/4 nearest t (k = 0 .. 4), atan t = atan c +
// atan u with u = (t - c) / (1 + t c), |u| <= 0.1251; atan c = hi + lo (|residue| < 2^-109).
constexpr double atan_quarter_hi[] = {0.0, 0x1.f5b75f92c80ddp-3, 0x1.dac670561bb4fp-2, 0x1.4978fa3269ee1p-1,
                                      0x1.921fb54442d18p-1};
constexpr double atan_quarter_lo[] = {0.0, 0x1.8ab6e3cf7afbdp-57, 0x1.a2b7f222f65e2p-56,
                                      0x1.2419a87f2a458p-56, 0x1.1a62633145c07p-55};
// atan u = u Q(u^2), Q(z) = sum (-1)^n z^n / (2n + 1): coefficients RN(+-1/(2n + 1)), n = 9 .. 0.
constexpr double atan_coeffs[] = {-1.0 / 19, 1.0 / 17, -1.0 / 15, 1.0 / 13, -1.0 / 11,
                                  1.0 / 9,   -1.0 / 7, 1.0 / 5,   -1.0 / 3, 1.0};
// The error bound of a corner's angle v: |v - atan2(y, x)| <= atan2_rel_bound |v| + abs_floor. Each
// operation errs by less than 2^-52 relative (one ulp, any rounding direction); u = 2^-52:
//  - t: 1u; through atan (slope 1 / (1 + t^2), atan t >= t pi/4 on [0, 1]) at most 1.28u atan t;
//  - u: the difference, 1 + t c (an fma) and the quotient, 3u relative; slope <= 1: 3u |atan u|;
//  - Q: truncation |u|^21 / 21 < 2^-64 |u| (alternating series, z <= 0.0157); Horner with fma and
//    rounded coefficients below 1.6u (each step's error damped by z), the product u Q 1u: in all
//    atan u within 6.1u |u| (|u| <= 1.006 |atan u|);
//  - r = hi + (lo + p) for atan t: for k = 0 exactly p (relative 6.2u); for k >= 1, atan t >= 0.124,
//    and the errors 6.1u 0.1251 + 0.127u + 1u atan t stay below 10u atan t; with t's 1.28u: 11.3u;
//  - pi/2 - r (|y| > |x|, r <= 0.786, result >= 0.785): (H1 - r) + H2, two roundings of 1.571u each
//    plus 11.3u 0.786, below 12.1u absolute, 15.4u of the result; pi - r (x < 0, r <= pi/2, result
//    >= pi/2): r's 12.1u and two roundings of 3.15u each, 18.4u absolute, below 11.8u of the result.
// Below 16u |v| = 2^-48 |v| to first order; the bound doubles it for the second-order terms.
// Subnormal t (or u Q) adds a few 2^-1074, within abs_floor.
constexpr double atan2_rel_bound = 0x1p-47;
constexpr double pi_up = 0x1.921fb54442d19p+1; // RU(pi), the core's bound of the range

} // namespace

Value* BoxGen::exp_value(Value* x) {
    // k = an integer near x / ln 2; r = x - k ln 2 with |r| < 0.347; exp(x) = 2^k exp(r).
    Value* k = floor(add(mul(x, cst(inv_ln2)), cst(0.5)));
    Value* nk = neg(k);
    Value* r = fma(nk, cst(ln2_2), fma(nk, cst(ln2_1), x)); // the inner fma is exact
    Value* p = cst(exp_coeffs[0]);
    for (std::size_t i = 1; i < std::size(exp_coeffs); ++i) p = fma(p, r, cst(exp_coeffs[i]));
    // 2^k from its bits (|k| <= 1010: a normal double); the product is exact.
    Value* bits =
        b_.CreateShl(b_.CreateAdd(b_.CreateFPToSI(k, vi64_), llvm::ConstantInt::get(vi64_, 1023)), 52);
    return mul(p, b_.CreateBitCast(bits, vt_));
}

IV BoxGen::exp_bounds(const IV& x) {
    // exp is increasing: the lower bound at lo, the upper one at hi.
    Value* at_lo = exp_value(x.lo);
    Value* at_hi = exp_value(x.hi);
    // exp 0 = 1 is exact (r = 0, the polynomial gives 1), and kept thin as in sincos_point.
    auto err = [&](Value* at, Value* arg) {
        return sel(eq(arg, cst(0.0)), cst(0.0), mul(at, cst(exp_rel_bound)));
    };
    return {std_max(sub_down(at_lo, err(at_lo, x.lo)), cst(0.0)), add(at_hi, err(at_hi, x.hi))};
}

SlotState BoxGen::op_exp(const SlotState& a) {
    const IV& x = a.v;
    Value* fast = land(le(x.lo, x.hi), land(ge(x.lo, cst(-exp_fast_limit)), le(x.hi, cst(exp_fast_limit))));
    return result(with_fallback(fast, exp_bounds(x), Op::Exp, {&a}), a.f.maybe_empty);
}

IV BoxGen::sincos_point(Value* x, int shift) {
    // k = an integer near x / (pi/2); r = x - k pi/2 with |r| < 0.786.
    Value* k = floor(add(mul(x, cst(two_over_pi_hi)), cst(0.5)));
    Value* nk = neg(k);
    Value* r1 = fma(nk, cst(half_pi_1), x); // exact: see the bound's derivation
    Value* r = fma(nk, cst(half_pi_2), r1);
    Value* z = mul(r, r);
    Value* s = cst(sin_coeffs[0]);
    for (std::size_t i = 1; i < std::size(sin_coeffs); ++i) s = fma(s, z, cst(sin_coeffs[i]));
    s = fma(mul(r, z), s, r);
    Value* c = cst(cos_coeffs[0]);
    for (std::size_t i = 1; i < std::size(cos_coeffs); ++i) c = fma(c, z, cst(cos_coeffs[i]));
    c = fma(z, c, cst(1.0));
    // The quadrant q = k + shift mod 4 (exact in doubles): f(x) = s, c, -s, -c for q = 0, 1, 2, 3.
    Value* q = add(k, cst(static_cast<double>(shift)));
    q = sub(q, mul(cst(4.0), floor(mul(q, cst(0.25)))));
    Value* odd = b_.CreateOr(eq(q, cst(1.0)), eq(q, cst(3.0)));
    Value* v = sel(odd, c, s);
    v = sel(ge(q, cst(2.0)), neg(v), v);
    Value* err = add(add(mul(fabs(v), cst(rel_bound)), mul(fabs(k), cst(abs_per_k))), cst(abs_floor));
    // At x = 0 the values 0 and 1 are exact (r = z = 0); elsewhere sin x and cos x are transcendental
    // (Lindemann), never a double. Keeping sin 0 and cos 0 thin keeps what depends on thinness (pow's
    // integer exponents, equality) as the interpreter has it.
    err = sel(eq(x, cst(0.0)), cst(0.0), err);
    return {sub_down(v, err), add(v, err)};
}

SlotState BoxGen::op_sincos(const SlotState& a, bool is_cos) {
    const IV& x = a.v;
    // Non-empty lanes with both ends within the limit (NaN compares false).
    Value* fast = land(le(x.lo, x.hi),
                       land(le(fabs(x.lo), cst(trig_fast_limit)), le(fabs(x.hi), cst(trig_fast_limit))));
    // As numeric/interval.cpp: t encloses x / (pi/2); sin has its maxima at t = 1 and its minima at
    // t = 3 (mod 4), cos at 0 and 2; a t-range of 4 or more is a whole period.
    Value* t_lo = mul_down(x.lo, sel(ge(x.lo, cst(0.0)), cst(two_over_pi_lo), cst(two_over_pi_hi)));
    Value* t_hi = mul(x.hi, sel(ge(x.hi, cst(0.0)), cst(two_over_pi_hi), cst(two_over_pi_lo)));
    Value* whole = ge(sub(t_hi, t_lo), cst(4.0));
    // Whether [t_lo, t_hi] holds an integer congruent to m mod 4 (all integers here are exact).
    Value* n = ceil(t_lo);
    Value* n_mod4 = sub(n, mul(cst(4.0), floor(mul(n, cst(0.25)))));
    auto hits = [&](double m) {
        Value* d = sub(cst(m), n_mod4);
        d = sel(lt(d, cst(0.0)), add(d, cst(4.0)), d);
        return le(add(n, d), t_hi);
    };
    const double max_at = is_cos ? 0.0 : 1.0;
    const int shift = is_cos ? 1 : 0;
    const IV at_lo = sincos_point(x.lo, shift);
    const IV at_hi = sincos_point(x.hi, shift);
    Value* lo = std_max(std_min(at_lo.lo, at_hi.lo), cst(-1.0));
    Value* hi = std_min(std_max(at_lo.hi, at_hi.hi), cst(1.0));
    lo = sel(b_.CreateOr(whole, hits(max_at + 2.0)), cst(-1.0), lo);
    hi = sel(b_.CreateOr(whole, hits(max_at)), cst(1.0), hi);
    return result(with_fallback(fast, {lo, hi}, is_cos ? Op::Cos : Op::Sin, {&a}), a.f.maybe_empty);
}

SlotState BoxGen::op_tan(const SlotState& a) {
    const IV& x = a.v;
    Value* fast = land(le(x.lo, x.hi),
                       land(le(fabs(x.lo), cst(trig_fast_limit)), le(fabs(x.hi), cst(trig_fast_limit))));
    // As numeric/interval.cpp: t encloses x / (pi/2), poles at odd t; a t-range of 2 or more holds one.
    // Between poles tan is increasing.
    Value* t_lo = mul_down(x.lo, sel(ge(x.lo, cst(0.0)), cst(two_over_pi_lo), cst(two_over_pi_hi)));
    Value* t_hi = mul(x.hi, sel(ge(x.hi, cst(0.0)), cst(two_over_pi_hi), cst(two_over_pi_lo)));
    Value* n = ceil(t_lo); // the least integer >= t_lo: an odd one within [t_lo, t_hi] is a pole
    Value* odd = sel(eq(sub(n, mul(cst(2.0), floor(mul(n, cst(0.5))))), cst(0.0)), add(n, cst(1.0)), n);
    Value* pole = lor(ge(sub(t_hi, t_lo), cst(2.0)), le(odd, t_hi));
    // tan at an end lies in S / C, S and C the proven enclosures of sin and cos there; C holds no 0 away
    // from the poles, except within its bound of one, where the lane calls the core.
    auto quotient = [&](Value* at) {
        const IV s = sincos_point(at, 0), c = sincos_point(at, 1);
        Value* positive = gt(c.lo, cst(0.0));
        // With C < 0, S / C = (-S) / (-C).
        const IV num{sel(positive, s.lo, neg(s.hi)), sel(positive, s.hi, neg(s.lo))};
        const IV den{sel(positive, c.lo, neg(c.hi)), sel(positive, c.hi, neg(c.lo))};
        const IV q{div_down(num.lo, sel(ge(num.lo, cst(0.0)), den.hi, den.lo)),
                   div(num.hi, sel(ge(num.hi, cst(0.0)), den.lo, den.hi))};
        return std::pair{q, lor(positive, lt(c.hi, cst(0.0)))};
    };
    const auto [at_lo, lo_ok] = quotient(x.lo);
    const auto [at_hi, hi_ok] = quotient(x.hi);
    const IV r{sel(pole, cst(-inf), at_lo.lo), sel(pole, cst(inf), at_hi.hi)};
    fast = land(fast, lor(pole, land(lo_ok, hi_ok)));
    return result(with_fallback(fast, r, Op::Tan, {&a}), a.f.maybe_empty);
}

Value* BoxGen::log_value(Value* x) {
    // x = 2^e m with m in [sqrt(2)/2, sqrt(2)); log x = e ln 2 + log m, log m = 2 atanh(s) with
    // s = (m - 1) / (m + 1), |s| <= 0.1716 (docs/design.md, "Vector interval kernels").
    Value* bits = b_.CreateBitCast(x, vi64_);
    Value* e =
        b_.CreateSIToFP(b_.CreateSub(b_.CreateLShr(bits, 52), llvm::ConstantInt::get(vi64_, 1023)), vt_);
    Value* m =
        b_.CreateBitCast(b_.CreateOr(b_.CreateAnd(bits, llvm::ConstantInt::get(vi64_, 0x000FFFFFFFFFFFFFULL)),
                                     llvm::ConstantInt::get(vi64_, 0x3FF0000000000000ULL)),
                         vt_);
    Value* big = gt(m, cst(sqrt2));
    m = sel(big, mul(m, cst(0.5)), m); // exact
    e = sel(big, add(e, cst(1.0)), e);
    Value* f = sub(m, cst(1.0)); // exact (Sterbenz)
    Value* s = div(f, add(f, cst(2.0)));
    Value* z = mul(s, s);
    Value* p = cst(log_coeffs[0]);
    for (std::size_t i = 1; i < std::size(log_coeffs); ++i) p = fma(p, z, cst(log_coeffs[i]));
    Value* log_m = mul(add(s, s), p);
    return fma(e, cst(ln2_hi), fma(e, cst(ln2_lo), log_m)); // e H is exact
}

IV BoxGen::log_bounds(const IV& x) {
    Value* at_lo = log_value(x.lo);
    Value* at_hi = log_value(x.hi);
    // log 1 = 0 is exact (s = 0, e = 0) and kept thin.
    auto err = [&](Value* at, Value* arg) {
        return sel(eq(arg, cst(1.0)), cst(0.0), add(mul(fabs(at), cst(log_rel_bound)), cst(abs_floor)));
    };
    return {sub_down(at_lo, err(at_lo, x.lo)), add(at_hi, err(at_hi, x.hi))};
}

// Lanes whose ends are positive normal doubles.
Value* BoxGen::positive_normal(const IV& x) {
    return land(le(x.lo, x.hi), land(ge(x.lo, cst(log_fast_min)), lt(x.hi, cst(inf))));
}

SlotState BoxGen::op_log(const SlotState& a) {
    // numeric/interval.cpp: empty when a is empty or a.hi <= 0, a lower bound <= 0 gives -inf; those
    // lanes call the core.
    return result(with_fallback(positive_normal(a.v), log_bounds(a.v), Op::Log, {&a}), true);
}

Value* BoxGen::atan2_value(Value* y, Value* x) {
    // For finite (y, x) != (0, 0); y = -0 counts as +0 (the core's corners see -0 only where it does not
    // matter or after making it +0).
    Value* ay = fabs(y);
    Value* ax = fabs(x);
    Value* steep = gt(ay, ax);
    Value* t = div(sel(steep, ax, ay), sel(steep, ay, ax));
    Value* k = floor(add(mul(t, cst(4.0)), cst(0.5)));
    Value* c = mul(k, cst(0.25));
    Value* u = div(sub(t, c), fma(t, c, cst(1.0)));
    Value* z = mul(u, u);
    Value* q = cst(atan_coeffs[0]);
    for (std::size_t i = 1; i < std::size(atan_coeffs); ++i) q = fma(q, z, cst(atan_coeffs[i]));
    Value* base_hi = cst(0.0);
    Value* base_lo = cst(0.0);
    for (std::size_t i = 1; i < std::size(atan_quarter_hi); ++i) {
        Value* is_k = eq(k, cst(static_cast<double>(i)));
        base_hi = sel(is_k, cst(atan_quarter_hi[i]), base_hi);
        base_lo = sel(is_k, cst(atan_quarter_lo[i]), base_lo);
    }
    Value* r = add(base_hi, add(base_lo, mul(u, q))); // atan t
    r = sel(steep, add(sub(cst(half_pi_1), r), cst(half_pi_2)), r);
    r = sel(lt(x, cst(0.0)), add(sub(cst(2 * half_pi_1), r), cst(2 * half_pi_2)), r);
    return sel(lt(y, cst(0.0)), neg(r), r);
}

SlotState BoxGen::op_atan2(const SlotState& a, const SlotState& b) {
    const IV& y = a.v;
    const IV& x = b.v;
    // numeric/interval.cpp: a box in the closed upper half-plane (y.lo = 0) meeting x = 0 gives [0, pi];
    // otherwise one containing the origin or meeting the cut (x < 0, y = 0), [-pi, pi].
    Value* upper = land(eq(y.lo, cst(0.0)), ge(y.hi, cst(0.0)));
    Value* half_range = land(upper, land(le(x.lo, cst(0.0)), ge(x.hi, cst(0.0))));
    Value* whole_range =
        land(lnot(upper), land(le(x.lo, cst(0.0)), land(le(y.lo, cst(0.0)), ge(y.hi, cst(0.0)))));
    // Elsewhere the angle is continuous on the box, its extremes at corners: above the x axis it falls
    // with x, below it rises, on the right half-plane it rises with y; along y it rises where x > 0 and
    // falls where x < 0. So the least angle is at x.hi (y >= 0) or x.lo, the greatest at x.hi (y < 0)
    // or x.lo, each with the y end that x's sign picks.
    Value* x_min = sel(ge(y.lo, cst(0.0)), x.hi, x.lo);
    Value* y_min = sel(ge(x_min, cst(0.0)), y.lo, y.hi);
    Value* x_max = sel(lt(y.hi, cst(0.0)), x.hi, x.lo);
    Value* y_max = sel(ge(x_max, cst(0.0)), y.hi, y.lo);
    Value* at_min = atan2_value(y_min, x_min);
    Value* at_max = atan2_value(y_max, x_max);
    auto err = [&](Value* v) { return add(mul(fabs(v), cst(atan2_rel_bound)), cst(abs_floor)); };
    Value* lo = std_max(sub_down(at_min, err(at_min)), cst(-pi_up));
    Value* hi = std_min(add(at_max, err(at_max)), cst(pi_up));
    lo = sel(half_range, cst(0.0), sel(whole_range, cst(-pi_up), lo));
    hi = sel(b_.CreateOr(half_range, whole_range), cst(pi_up), hi);
    // Infinite ends (and NaN) call the core; empty lanes give the empty interval.
    Value* finite = land(land(is_finite(y.lo), is_finite(y.hi)), land(is_finite(x.lo), is_finite(x.hi)));
    Value* e = lor(empty_of(a), empty_of(b));
    Value* fast = lor(e, b_.CreateOr(b_.CreateOr(half_range, whole_range), finite));
    const IV r = guard(e, {lo, hi}, empty());
    return result(with_fallback(fast, r, Op::Atan2, {&a, &b}), a.f.maybe_empty || b.f.maybe_empty);
}

SlotState BoxGen::op_pow(const SlotState& a, const SlotState& b) {
    // numeric/interval.cpp: a thin integer exponent takes powi; otherwise exp(b log(a n [0, inf])). Fast
    // lanes: a positive normal base, a finite exponent that is not a thin integer, |b log a| <= 700.
    const IV& x = a.v;
    const IV& y = b.v;
    Value* integer = land(eq(y.lo, y.hi), eq(floor(y.lo), y.lo));
    Value* finite = land(le(y.lo, y.hi), land(gt(y.lo, cst(-inf)), lt(y.hi, cst(inf))));
    const IV l = log_bounds(x);
    // y l, outward: the extremes among the four products (all finite here).
    Value* p_lo = std_min(std_min(mul_down(y.lo, l.lo), mul_down(y.lo, l.hi)),
                          std_min(mul_down(y.hi, l.lo), mul_down(y.hi, l.hi)));
    Value* p_hi =
        std_max(std_max(mul(y.lo, l.lo), mul(y.lo, l.hi)), std_max(mul(y.hi, l.lo), mul(y.hi, l.hi)));
    Value* fast = land(land(positive_normal(x), land(finite, lnot(integer))),
                       land(ge(p_lo, cst(-exp_fast_limit)), le(p_hi, cst(exp_fast_limit))));
    return result(with_fallback(fast, exp_bounds({p_lo, p_hi}), Op::Pow, {&a, &b}), true);
}

} // namespace frac::jit::box
