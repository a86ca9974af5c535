// The interval operations of numeric/interval_kernels.hpp on four boxes at once (AVX2): a slot's four
// lower bounds in one vector, its four upper bounds in another. Bit for bit the scalar kernels' results,
// lane by lane: the same roundings (RD(f) = -RU(-f) under upward rounding), the same first-of-equal
// picks as std::min / std::max and their list forms (MINPD(b, a) is std::min(a, b)), empty operands
// giving the same empty results. tests/unit/llvm/test_flat_interpreter.cpp compares both.
//
// Every function is compiled for AVX2 and FMA alone (the target attribute); callers check the CPU
// first (lane_kernels::supported). Include only from files compiled with -frounding-math.
#pragma once

#if defined(__x86_64__) && defined(__GNUC__)
#define FRAC_LANE_KERNELS 1
#include <immintrin.h>

#include <cstdint>

namespace frac::interp::lane_kernels {

// Whether this CPU runs the kernels.
inline bool supported() {
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}

#define FRAC_LANES_TARGET __attribute__((target("avx2,fma"), always_inline)) inline

// Four intervals: lower bounds, upper bounds.
struct Quad {
    __m256d lo, hi;
};

// Hides a value from the optimiser (no instruction), so that -(RU(-x - y)) is not folded into x + y.
FRAC_LANES_TARGET __m256d opaque(__m256d x) {
    asm("" : "+x"(x));
    return x;
}
FRAC_LANES_TARGET __m256d negate(__m256d x) {
    return _mm256_xor_pd(x, _mm256_set1_pd(-0.0));
}
FRAC_LANES_TARGET __m256d inf() {
    return _mm256_set1_pd(__builtin_inf());
}
// Where `mask`, b; else a.
FRAC_LANES_TARGET __m256d pick(__m256d a, __m256d b, __m256d mask) {
    return _mm256_blendv_pd(a, b, mask);
}
// std::min(a, b) and std::max(a, b): b only when strictly smaller (larger).
FRAC_LANES_TARGET __m256d first_min(__m256d a, __m256d b) {
    return _mm256_min_pd(b, a);
}
FRAC_LANES_TARGET __m256d first_max(__m256d a, __m256d b) {
    return _mm256_max_pd(b, a);
}

FRAC_LANES_TARGET __m256d is_empty(const Quad& a) {
    return _mm256_cmp_pd(a.lo, a.hi, _CMP_NLE_UQ);
}
// Empty where `mask`, as Interval::empty() is: [inf, -inf].
FRAC_LANES_TARGET Quad empty_where(Quad r, __m256d mask) {
    return {pick(r.lo, inf(), mask), pick(r.hi, negate(inf()), mask)};
}
// Bounds that came out NaN widen to infinity (kernels::widen_nan).
FRAC_LANES_TARGET Quad widen_nan(__m256d lo, __m256d hi) {
    return {pick(lo, negate(inf()), _mm256_cmp_pd(lo, lo, _CMP_UNORD_Q)),
            pick(hi, inf(), _mm256_cmp_pd(hi, hi, _CMP_UNORD_Q))};
}

FRAC_LANES_TARGET __m256d add_down(__m256d x, __m256d y) {
    return negate(opaque(_mm256_sub_pd(opaque(negate(x)), y)));
}
FRAC_LANES_TARGET __m256d sub_down(__m256d x, __m256d y) {
    return negate(opaque(_mm256_add_pd(opaque(negate(x)), y)));
}
FRAC_LANES_TARGET __m256d mul_down(__m256d x, __m256d y) {
    return negate(opaque(_mm256_mul_pd(opaque(negate(x)), y)));
}
// Products in which a zero factor gives +0 (kernels::mul_up0, mul_down0).
FRAC_LANES_TARGET __m256d zero_factor(__m256d x, __m256d y) {
    const __m256d zero = _mm256_setzero_pd();
    return _mm256_or_pd(_mm256_cmp_pd(x, zero, _CMP_EQ_OQ), _mm256_cmp_pd(y, zero, _CMP_EQ_OQ));
}
FRAC_LANES_TARGET __m256d mul_up0(__m256d x, __m256d y) {
    return _mm256_andnot_pd(zero_factor(x, y), _mm256_mul_pd(x, y));
}
FRAC_LANES_TARGET __m256d mul_down0(__m256d x, __m256d y) {
    return _mm256_andnot_pd(zero_factor(x, y), mul_down(x, y));
}

FRAC_LANES_TARGET Quad add(const Quad& a, const Quad& b) {
    return empty_where(widen_nan(add_down(a.lo, b.lo), _mm256_add_pd(a.hi, b.hi)),
                       _mm256_or_pd(is_empty(a), is_empty(b)));
}

FRAC_LANES_TARGET Quad sub(const Quad& a, const Quad& b) {
    return empty_where(widen_nan(sub_down(a.lo, b.hi), _mm256_sub_pd(a.hi, b.lo)),
                       _mm256_or_pd(is_empty(a), is_empty(b)));
}

// The four corners in the scalar kernel's order, the first extreme of each list; a thin factor gives
// the same bits there (kernels::mul).
FRAC_LANES_TARGET Quad mul(const Quad& a, const Quad& b) {
    const __m256d lo =
        first_min(first_min(first_min(mul_down0(a.lo, b.lo), mul_down0(a.lo, b.hi)), mul_down0(a.hi, b.lo)),
                  mul_down0(a.hi, b.hi));
    const __m256d hi =
        first_max(first_max(first_max(mul_up0(a.lo, b.lo), mul_up0(a.lo, b.hi)), mul_up0(a.hi, b.lo)),
                  mul_up0(a.hi, b.hi));
    return empty_where({lo, hi}, _mm256_or_pd(is_empty(a), is_empty(b)));
}

FRAC_LANES_TARGET Quad neg(const Quad& a) {
    return {negate(a.hi), negate(a.lo)};
}

FRAC_LANES_TARGET Quad abs(const Quad& a) {
    const __m256d zero = _mm256_setzero_pd();
    const __m256d keep = _mm256_or_pd(is_empty(a), _mm256_cmp_pd(a.lo, zero, _CMP_GE_OQ));
    const __m256d negative = _mm256_cmp_pd(a.hi, zero, _CMP_LE_OQ);
    const Quad straddles{zero, first_max(negate(a.lo), a.hi)};
    const Quad r{pick(straddles.lo, negate(a.hi), negative), pick(straddles.hi, negate(a.lo), negative)};
    return {pick(r.lo, a.lo, keep), pick(r.hi, a.hi, keep)};
}

// [RD(m.lo^2), RU(m.hi^2)] for m = |a|; an empty operand is returned as it is.
FRAC_LANES_TARGET Quad sqr(const Quad& a) {
    const Quad m = abs(a);
    const __m256d empty = is_empty(a);
    return {pick(mul_down(m.lo, m.lo), a.lo, empty), pick(_mm256_mul_pd(m.hi, m.hi), a.hi, empty)};
}

FRAC_LANES_TARGET Quad sqrt(const Quad& a) {
    const __m256d lo = first_max(a.lo, _mm256_setzero_pd());
    const __m256d r = _mm256_sqrt_pd(lo); // RU(sqrt(lo))
    // r * r - lo is exact in the fma, so its sign says whether r overshoots; then r > 0 is finite or
    // infinite, and the double below it is its bits less one.
    const __m256d over = _mm256_cmp_pd(_mm256_fmadd_pd(r, r, negate(lo)), _mm256_setzero_pd(), _CMP_GT_OQ);
    const __m256d below =
        _mm256_castsi256_pd(_mm256_sub_epi64(_mm256_castpd_si256(r), _mm256_set1_epi64x(1)));
    return empty_where({pick(r, below, over), _mm256_sqrt_pd(a.hi)},
                       _mm256_or_pd(is_empty(a), _mm256_cmp_pd(a.hi, _mm256_setzero_pd(), _CMP_LT_OQ)));
}

FRAC_LANES_TARGET Quad min(const Quad& a, const Quad& b) {
    return empty_where({first_min(a.lo, b.lo), first_min(a.hi, b.hi)},
                       _mm256_or_pd(is_empty(a), is_empty(b)));
}

FRAC_LANES_TARGET Quad max(const Quad& a, const Quad& b) {
    return empty_where({first_max(a.lo, b.lo), first_max(a.hi, b.hi)},
                       _mm256_or_pd(is_empty(a), is_empty(b)));
}

#undef FRAC_LANES_TARGET

} // namespace frac::interp::lane_kernels

#endif
