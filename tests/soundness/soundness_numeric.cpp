// Soundness of the numeric core against the MPFI oracle, and proof that the oracle can fail.
//
// FRAC_SOUNDNESS_PAIRS overrides the number of (expression, box) pairs of the main check.
#include "tests/soundness/oracle.hpp"

#include <catch2/catch.hpp>
#include <mpfr.h>

#include <algorithm>
#include <cfenv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

namespace num = frac::num;
namespace oracle = frac::oracle;
using num::Interval;
using oracle::Expr;
using oracle::Op;

namespace {

constexpr int kVars = 3;

std::uint64_t pairs_from_env(std::uint64_t fallback) {
    const char* s = std::getenv("FRAC_SOUNDNESS_PAIRS");
    return s ? std::strtoull(s, nullptr, 10) : fallback;
}

oracle::Report run(const char* title, std::uint64_t pairs, std::uint64_t seed, const oracle::Enclosure& f,
                   const oracle::Options& options = {}) {
    const auto start = std::chrono::steady_clock::now();
    oracle::Report report = oracle::check_soundness(pairs, seed, kVars, f, options);
    const std::chrono::duration<double> took = std::chrono::steady_clock::now() - start;
    std::printf("== %s: %.1f s\n%s\n", title, took.count(), report.summary().c_str());
    std::fflush(stdout);
    return report;
}

// ---- A deliberately unsound evaluator: textbook interval arithmetic in round-to-nearest. ----

Interval naive(const Expr& e, const Interval* box);

Interval naive_mul(Interval a, Interval b) {
    const double p[] = {a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi};
    return {*std::min_element(p, p + 4), *std::max_element(p, p + 4)};
}

Interval naive_div(Interval a, Interval b) {
    if (b.lo <= 0 && b.hi >= 0) return Interval::entire();
    return naive_mul(a, {1 / b.hi, 1 / b.lo});
}

Interval naive_powi(Interval a, std::int64_t n) {
    Interval r{1, 1};
    for (std::uint64_t m = n < 0 ? 0 - static_cast<std::uint64_t>(n) : n; m != 0;
         m >>= 1, a = naive_mul(a, a))
        if (m & 1) r = naive_mul(r, a);
    return n < 0 ? naive_div({1, 1}, r) : r;
}

// Endpoint values plus the extrema at phase + k pi (k even: max 1, odd: min -1), all in nearest.
Interval naive_sincos(Interval a, double (*f)(double), double phase) {
    if (!(a.hi - a.lo < 2 * M_PI) || num::magnitude(a) > 1e15) return {-1, 1};
    double lo = std::min(f(a.lo), f(a.hi)), hi = std::max(f(a.lo), f(a.hi));
    for (double k = std::ceil((a.lo - phase) / M_PI); phase + k * M_PI <= a.hi; ++k)
        (std::fmod(k, 2) == 0 ? hi : lo) = std::fmod(k, 2) == 0 ? 1 : -1;
    return {lo, hi};
}

Interval naive(const Expr& e, const Interval* box) {
    auto arg = [&](int i) { return naive(e.args[i], box); };
    switch (e.op) {
    case Op::Const: return e.value;
    case Op::Var: return box[e.var];
    case Op::Add: {
        const Interval a = arg(0), b = arg(1);
        return {a.lo + b.lo, a.hi + b.hi};
    }
    case Op::Sub: {
        const Interval a = arg(0), b = arg(1);
        return {a.lo - b.hi, a.hi - b.lo};
    }
    case Op::Mul: return naive_mul(arg(0), arg(1));
    case Op::Div: return naive_div(arg(0), arg(1));
    case Op::Neg: return num::neg(arg(0));
    case Op::Sqr: return num::abs(naive_mul(arg(0), arg(0)));
    case Op::PowInt: return naive_powi(arg(0), e.n);
    case Op::Pow: {
        const Interval a = num::intersect(arg(0), {0, num::inf}), b = arg(1);
        if (b.is_thin() && std::trunc(b.lo) == b.lo)
            return naive_powi(arg(0), static_cast<std::int64_t>(b.lo));
        if (a.is_empty()) return a;
        const Interval l = naive_mul(b, {std::log(a.lo), std::log(a.hi)});
        return {std::exp(l.lo), std::exp(l.hi)};
    }
    case Op::Sqrt: {
        const Interval a = arg(0);
        return a.hi < 0 ? Interval::empty() : Interval{std::sqrt(std::max(a.lo, 0.0)), std::sqrt(a.hi)};
    }
    case Op::Abs: return num::abs(arg(0));
    case Op::Min: return num::min(arg(0), arg(1));
    case Op::Max: return num::max(arg(0), arg(1));
    case Op::Floor: return num::floor(arg(0));
    case Op::Ceil: return num::ceil(arg(0));
    case Op::Mod1: return num::mod1(arg(0));
    case Op::Dz: return num::dz(arg(0));
    case Op::Sin:
        return naive_sincos(
            arg(0), [](double x) { return std::sin(x); }, M_PI / 2);
    case Op::Cos:
        return naive_sincos(
            arg(0), [](double x) { return std::cos(x); }, 0);
    case Op::Tan: {
        const Interval a = arg(0);
        const double k = std::ceil((a.lo - M_PI / 2) / M_PI);
        if (M_PI / 2 + k * M_PI <= a.hi) return Interval::entire();
        return {std::tan(a.lo), std::tan(a.hi)};
    }
    case Op::Exp: {
        const Interval a = arg(0);
        return {std::exp(a.lo), std::exp(a.hi)};
    }
    case Op::Log: {
        const Interval a = arg(0);
        return a.hi <= 0 ? Interval::empty() : Interval{std::log(std::max(a.lo, 0.0)), std::log(a.hi)};
    }
    case Op::Atan2: {
        const Interval y = arg(0), x = arg(1);
        if (x.lo <= 0 && y.lo <= 0 && y.hi >= 0) return {-M_PI, M_PI};
        const double c[] = {std::atan2(y.lo, x.lo), std::atan2(y.lo, x.hi), std::atan2(y.hi, x.lo),
                            std::atan2(y.hi, x.hi)};
        return {*std::min_element(c, c + 4), *std::max_element(c, c + 4)};
    }
    }
    return Interval::entire();
}

} // namespace

TEST_CASE("the numeric core is sound on random expressions and boxes", "[soundness]") {
    oracle::Options options;
    options.points_per_pair = 6;
    const oracle::Report report = run(
        "numeric core vs MPFI", pairs_from_env(1'000'000), 20240601,
        [](const Expr& e, const Interval* box) {
            const num::UpwardRounding upward;
            return oracle::eval_reference(e, box);
        },
        options);
    INFO(report.summary());
    CHECK(report.violations == 0);
    CHECK(report.covered()); // every builtin checked at some point, most points defined
}

TEST_CASE("the oracle catches naive round-to-nearest interval arithmetic", "[soundness]") {
    const oracle::Report report = run("naive evaluator (must fail)", 20'000, 7, naive);
    CHECK(report.violations > 0);
}

TEST_CASE("the oracle catches the numeric core run without UpwardRounding", "[soundness]") {
    const oracle::Report report =
        run("core in round-to-nearest (must fail)", 20'000, 8, oracle::eval_reference);
    CHECK(report.violations > 0);
}

TEST_CASE("the oracle catches an evaluator that leaks its rounding mode", "[soundness]") {
    const oracle::Report report =
        oracle::check_soundness(100, 9, kVars, [](const Expr& e, const Interval* box) {
            std::fesetround(FE_UPWARD);
            return oracle::eval_reference(e, box);
        });
    CHECK(std::fegetround() == FE_TONEAREST);
    CHECK(report.bad_enclosures == 100);
    CHECK(report.violations >= 100);
}

TEST_CASE("elementary functions at points are tight enclosures of the MPFR value", "[soundness]") {
    // Thin arguments across the exponent range: LLVM libc must round correctly under FE_UPWARD, so every
    // enclosure is at most 2 doubles wide (atan2: 9, glibc's result widened by 4 ulps each way).
    std::mt19937_64 rng(99);
    const Op ops[] = {Op::Sin, Op::Cos, Op::Tan, Op::Exp, Op::Log, Op::Sqrt, Op::Atan2};
    for (Op op : ops) {
        std::uint64_t checked = 0, loose = 0, misses = 0;
        for (int i = 0; i < 20000; ++i) {
            const double m = std::uniform_real_distribution<double>(1, 2)(rng);
            int exponent = std::uniform_int_distribution<int>(-60, 60)(rng);
            if (op == Op::Exp) exponent = std::min(exponent, 9);
            // Beyond about 2^30 the double enclosure of x * 2/pi may straddle a quadrant boundary, which
            // loosens (soundly) the result; the random boxes cover those arguments.
            if (op == Op::Sin || op == Op::Cos || op == Op::Tan) exponent = std::min(exponent, 30);
            const double sign = op == Op::Log || op == Op::Sqrt || rng() % 2 ? 1.0 : -1.0;
            const double x = sign * std::ldexp(m, exponent);
            const double y = std::ldexp(std::uniform_real_distribution<double>(-2, 2)(rng), exponent / 2);
            Expr e{op, 0, 0, 0, {Expr{Op::Var, 0, 0, 0, {}}}};
            if (op == Op::Atan2) e.args.push_back(Expr{Op::Var, 1, 0, 0, {}});
            const double point[] = {x, y};
            const Interval box[] = {x, y};
            const std::optional<oracle::PointValue> exact = oracle::eval_mpfi(e, point, 160);
            if (!exact) continue;
            Interval enc;
            {
                const num::UpwardRounding upward;
                enc = oracle::eval_reference(e, box);
            }
            ++checked;
            if (!enc.contains(exact->outer)) ++misses;
            double limit = enc.lo;
            const int ulps = op == Op::Atan2 ? 9 : 2;
            for (int k = 0; k < ulps; ++k) limit = std::nextafter(limit, num::inf);
            if (enc.hi > limit) ++loose;
        }
        std::printf("%s: %llu thin points, %llu misses, %llu wider than expected\n", oracle::op_name(op),
                    static_cast<unsigned long long>(checked), static_cast<unsigned long long>(misses),
                    static_cast<unsigned long long>(loose));
        INFO(oracle::op_name(op));
        CHECK(checked > 10000);
        CHECK(misses == 0);
        CHECK(loose == 0);
    }
}

TEST_CASE("the enclosures of pi and e are correct", "[soundness]") {
    mpfr_t x;
    mpfr_init2(x, 256);
    mpfr_const_pi(x, MPFR_RNDN);
    CHECK(mpfr_cmp_d(x, num::pi().lo) > 0);
    CHECK(mpfr_cmp_d(x, num::pi().hi) < 0);
    mpfr_set_ui(x, 1, MPFR_RNDN);
    mpfr_exp(x, x, MPFR_RNDN);
    CHECK(mpfr_cmp_d(x, num::e().lo) > 0);
    CHECK(mpfr_cmp_d(x, num::e().hi) < 0);
    mpfr_clear(x);
}
