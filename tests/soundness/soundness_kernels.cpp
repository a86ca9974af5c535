// Soundness and tightness of the JIT's inline interval kernels (sqrt, sin, cos, exp, tan, log, pow, atan2;
// backend/llvm/box_kernels.cpp) against the exact range computed with MPFR: for random intervals of many
// widths and magnitudes, and the hard cases (near multiples of pi/2, huge arguments, tiny and thin intervals,
// zeros, infinities, NaN and empty intervals), the JIT's enclosure [L, H] of f over [lo, hi] must satisfy L
// <= RD(min f) and H >= RU(max f), where RD and RU round the exact extremes to doubles (correctly rounded by
// MPFR, and decided exactly: extremes inside the interval from the quadrant of lo and hi at enough bits of
// pi).
//
//   soundness_kernels [intervals per kernel = 1200000]
//
// Each code variant (the host's default, the portable vector and scalar forms, AVX-512 scalar) gets the
// same intervals; with the default count every kernel has more than 10^6 checked (interval, range)
// pairs per variant (the rest are empty or NaN arguments, whose result must be empty, and sin/cos of
// {inf}, and for atan2 the origin alone). Prints the enclosures' widths against the exact range's (median and
// worst ratio).
#include "backend/interp/interpreter.hpp"
#include "backend/llvm/jit.hpp"
#include "ir/graph.hpp"
#include "ir/tape.hpp"
#include "numeric/interval.hpp"

#include <gmp.h>
#include <mpfr.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>
#include <tuple>
#include <vector>

using namespace frac;
using num::Interval;

namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

// ---- random intervals ----
class IntervalMaker {
public:
    explicit IntervalMaker(std::uint64_t seed) : rng_(seed) {}

    Interval next() {
        switch (pick(16)) {
        case 0:
        case 1:
        case 2:
        case 3: return around(signed_magnitude(-8, 8)); // ordinary magnitudes, any width
        case 4:
        case 5:
        case 6: return near_half_pi_multiple();
        case 7: return thin(signed_magnitude(-30, 30));
        case 8: return around(signed_magnitude(20, 1020)); // huge arguments (the kernels' fallback)
        case 9: return zeros();
        case 10: return unbounded();
        case 11: return not_an_interval();
        case 12: return around(signed_magnitude(-1074, -300)); // tiny and subnormal
        case 13: // around the limits of the fast paths: 2^30 (sin, cos, tan), 700 (exp; overflow past
                 // 709.78), 1 and the normal range's ends (log)
            switch (pick(4)) {
            case 0: return around(signed_magnitude(25, 35));
            case 1: return around((pick(2) ? 1 : -1) * (690 + 60 * unit()));
            case 2: return around(1 + signed_magnitude(-60, -1));
            default: return around(std::ldexp(1.0 + unit(), pick(2) ? -1022 - pick(4) : 1020 + pick(4)));
            }
        default: return uniform(-10, 10);
        }
    }

    // A positive interval of any magnitude, subnormal to huge, of any width.
    Interval positive() {
        const double c = std::ldexp(1.0 + unit(), pick(2098) - 1074);
        Interval a = around(c);
        if (!(a.lo > 0)) a.lo = c;
        return a;
    }
    // An exponent: ordinary, thin integers (powi's path), around 0, large.
    Interval exponent() {
        switch (pick(5)) {
        case 0: return thin(static_cast<double>(pick(41) - 20));
        case 1: return around(signed_magnitude(-30, 3));
        case 2: return around(signed_magnitude(3, 12));
        case 3: return pick(8) == 0 ? not_an_interval() : uniform(-4, 4);
        default: return around(signed_magnitude(-3, 3));
        }
    }

    // A (y, x) box for atan2: intervals of every kind, and boxes on or across the axes, around the
    // origin, across the cut (y around 0, x < 0), small ones near the axes.
    std::pair<Interval, Interval> plane_box() {
        switch (pick(5)) {
        case 0: return {zeros(), next()};
        case 1: return {next(), zeros()};
        case 2: return {zeros(), zeros()};
        case 3: return {around(signed_magnitude(-40, 5)), around(signed_magnitude(-40, 5))};
        default: return {next(), next()};
        }
    }

private:
    std::mt19937_64 rng_;
    int pick(int n) { return static_cast<int>(rng_() % static_cast<std::uint64_t>(n)); }
    double unit() { return std::uniform_real_distribution<double>(0, 1)(rng_); }
    double signed_magnitude(int e_lo, int e_hi) {
        const int e = e_lo + pick(e_hi - e_lo + 1);
        const double m = std::ldexp(1.0 + unit(), e);
        return pick(2) ? m : -m;
    }
    static Interval ordered(double a, double b) { return a <= b ? Interval{a, b} : Interval{b, a}; }
    // An interval near c of a random width: thin, a few ulps, relative 2^-k or absolute 10^-k.
    Interval around(double c) {
        double w;
        switch (pick(5)) {
        case 0: return thin(c);
        case 1: {
            double h = c;
            for (int n = 1 + pick(4); n-- > 0;) h = std::nextafter(h, inf);
            return ordered(c, h);
        }
        case 2: w = std::ldexp(std::fabs(c), -pick(60)); break;
        case 3: w = std::pow(10.0, -pick(17)); break;
        default: w = std::fabs(c) * 4 * unit(); break;
        }
        const double f = unit();
        return ordered(c - w * f, c + w * (1 - f));
    }
    Interval thin(double c) { return {c, c}; }
    // Multiples k pi/2 (|k| < 2^34) and their neighbours: the quadrant boundaries and the extrema.
    Interval near_half_pi_multiple() {
        const double k = std::floor(std::ldexp(unit(), pick(35))) * (pick(2) ? 1 : -1);
        double c = k * 0x1.921fb54442d18p+0;
        for (int n = pick(5) - 2; n != 0; n += n > 0 ? -1 : 1) c = std::nextafter(c, n > 0 ? inf : -inf);
        if (pick(3) == 0) return thin(c);
        return around(c);
    }
    Interval zeros() {
        const double x = std::ldexp(1.0 + unit(), pick(40) - 30);
        switch (pick(6)) {
        case 0: return {-0.0, 0.0};
        case 1: return {0.0, 0.0};
        case 2: return {0.0, x};
        case 3: return {-x, 0.0};
        case 4: return {-x, x};
        default: return {-0.0, 0x1p-1074};
        }
    }
    Interval unbounded() {
        const double x = signed_magnitude(-5, 40);
        switch (pick(4)) {
        case 0: return {-inf, x};
        case 1: return {x, inf};
        case 2: return {-inf, inf};
        default: return {inf, inf};
        }
    }
    Interval not_an_interval() {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        switch (pick(4)) {
        case 0: return {1.0, 0.0};
        case 1: return {nan, 1.0};
        case 2: return {nan, nan};
        default: return Interval::empty();
        }
    }
    Interval uniform(double a, double b) {
        const double x = a + (b - a) * unit();
        return around(x);
    }
};

// ---- the exact range, rounded outward to doubles ----
// RD(min f) and RU(max f) over [lo, hi]; `defined` false where f has no value on any point of it
// (sqrt of a negative interval, {inf}).
struct ExactRange {
    bool defined = true;
    double lo = 0, hi = 0;
};

class Mpfr {
public:
    explicit Mpfr(mpfr_prec_t p = 53) { mpfr_init2(v, p); }
    ~Mpfr() { mpfr_clear(v); }
    Mpfr(const Mpfr&) = delete;
    Mpfr& operator=(const Mpfr&) = delete;
    mpfr_t v;
};

// The range of an increasing function over [lo, hi]: [RD(f(lo)), RU(f(hi))] (MPFR rounds correctly).
using MpfrFunction = int (*)(mpfr_ptr, mpfr_srcptr, mpfr_rnd_t);
ExactRange increasing_range(MpfrFunction f, double lo, double hi) {
    Mpfr x, r;
    ExactRange e;
    mpfr_set_d(x.v, lo, MPFR_RNDN);
    f(r.v, x.v, MPFR_RNDD);
    e.lo = mpfr_get_d(r.v, MPFR_RNDD);
    mpfr_set_d(x.v, hi, MPFR_RNDN);
    f(r.v, x.v, MPFR_RNDU);
    e.hi = mpfr_get_d(r.v, MPFR_RNDU);
    return e;
}

ExactRange log_range(double lo, double hi) {
    if (hi <= 0) return {false};                              // the result must be empty
    return increasing_range(mpfr_log, std::max(lo, 0.0), hi); // log 0 = -inf
}

ExactRange sqrt_range(double lo, double hi) {
    if (hi < 0) return {false}; // the result must be empty
    return increasing_range(mpfr_sqrt, std::max(lo, 0.0), hi);
}

// ceil (up = true) or floor of x / (pi/2), decided exactly: x is a double, so x / (pi/2) is an integer
// only for x = 0, and enough bits of pi separate it from the integers (precision grows with |x|).
void quadrant_bound(mpz_t out, double x, bool up) {
    if (x == 0) {
        mpz_set_si(out, 0);
        return;
    }
    const int ex = std::ilogb(x);
    for (mpfr_prec_t p = std::max(128, ex + 128);; p *= 2) {
        Mpfr half_pi(p), t_down(p), t_up(p), xv(p);
        mpfr_set_d(xv.v, x, MPFR_RNDN);
        // x / (pi/2) rounded down and up: x > 0 divides by an upper bound of pi/2 for the lower value.
        Mpfr pi_d(p), pi_u(p);
        mpfr_const_pi(pi_d.v, MPFR_RNDD);
        mpfr_const_pi(pi_u.v, MPFR_RNDU);
        mpfr_div_2ui(pi_d.v, pi_d.v, 1, MPFR_RNDD);
        mpfr_div_2ui(pi_u.v, pi_u.v, 1, MPFR_RNDU);
        mpfr_div(t_down.v, xv.v, x > 0 ? pi_u.v : pi_d.v, MPFR_RNDD);
        mpfr_div(t_up.v, xv.v, x > 0 ? pi_d.v : pi_u.v, MPFR_RNDU);
        Mpfr a(p), b(p);
        if (up) {
            mpfr_ceil(a.v, t_down.v);
            mpfr_ceil(b.v, t_up.v);
        } else {
            mpfr_floor(a.v, t_down.v);
            mpfr_floor(b.v, t_up.v);
        }
        if (mpfr_equal_p(a.v, b.v)) {
            mpfr_get_z(out, a.v, MPFR_RNDN);
            return;
        }
    }
}

// Whether some integer congruent to m mod 4 lies in [n_lo, n_hi].
bool holds_residue(const mpz_t n_lo, const mpz_t n_hi, int m) {
    mpz_t n, r;
    mpz_init(n);
    mpz_init(r);
    mpz_set(n, n_lo);
    mpz_sub_ui(r, n, static_cast<unsigned long>(m));
    const unsigned long d = (4 - mpz_fdiv_ui(r, 4)) % 4; // steps from n_lo up to the residue m
    mpz_add_ui(n, n, d);
    const bool in = mpz_cmp(n, n_hi) <= 0;
    mpz_clear(n);
    mpz_clear(r);
    return in;
}

ExactRange sincos_range(double lo, double hi, bool is_cos) {
    if (std::isinf(lo) || std::isinf(hi)) {
        if (lo == hi) return {false}; // {+inf} or {-inf}: no value
        return {true, -1.0, 1.0};
    }
    // Extremes at t = x / (pi/2) integer: sin max at 1, min at 3 (mod 4); cos max at 0, min at 2.
    mpz_t n_lo, n_hi;
    mpz_init(n_lo);
    mpz_init(n_hi);
    quadrant_bound(n_lo, lo, true);
    quadrant_bound(n_hi, hi, false);
    const int max_at = is_cos ? 0 : 1;
    const bool has_max = mpz_cmp(n_lo, n_hi) <= 0 && holds_residue(n_lo, n_hi, max_at);
    const bool has_min = mpz_cmp(n_lo, n_hi) <= 0 && holds_residue(n_lo, n_hi, max_at + 2);
    mpz_clear(n_lo);
    mpz_clear(n_hi);
    auto f = [&](double x, mpfr_rnd_t rnd) {
        Mpfr xv, r;
        mpfr_set_d(xv.v, x, MPFR_RNDN);
        if (is_cos)
            mpfr_cos(r.v, xv.v, rnd);
        else
            mpfr_sin(r.v, xv.v, rnd);
        return mpfr_get_d(r.v, rnd);
    };
    ExactRange e;
    e.lo = has_min ? -1.0 : std::min(f(lo, MPFR_RNDD), f(hi, MPFR_RNDD));
    e.hi = has_max ? 1.0 : std::max(f(lo, MPFR_RNDU), f(hi, MPFR_RNDU));
    return e;
}

ExactRange tan_range(double lo, double hi) {
    if (std::isinf(lo) || std::isinf(hi)) {
        if (lo == hi) return {false}; // {+inf} or {-inf}: no value
        return {true, -inf, inf};
    }
    // Poles at odd t = x / (pi/2); between them tan increases.
    mpz_t n_lo, n_hi;
    mpz_init(n_lo);
    mpz_init(n_hi);
    quadrant_bound(n_lo, lo, true);
    quadrant_bound(n_hi, hi, false);
    const bool pole =
        mpz_cmp(n_lo, n_hi) <= 0 && (holds_residue(n_lo, n_hi, 1) || holds_residue(n_lo, n_hi, 3));
    mpz_clear(n_lo);
    mpz_clear(n_hi);
    if (pole) return {true, -inf, inf};
    return increasing_range(mpfr_tan, lo, hi);
}

// Widens e to RD(f(a, b)) and RU(f(a, b)) (MPFR rounds correctly).
using MpfrFunction2 = int (*)(mpfr_ptr, mpfr_srcptr, mpfr_srcptr, mpfr_rnd_t);
void extend_by(ExactRange& e, MpfrFunction2 f, double a, double b) {
    Mpfr av, bv, r;
    mpfr_set_d(av.v, a, MPFR_RNDN);
    mpfr_set_d(bv.v, b, MPFR_RNDN);
    f(r.v, av.v, bv.v, MPFR_RNDD);
    e.lo = std::min(e.lo, mpfr_get_d(r.v, MPFR_RNDD));
    f(r.v, av.v, bv.v, MPFR_RNDU);
    e.hi = std::max(e.hi, mpfr_get_d(r.v, MPFR_RNDU));
}

// x^y over a box with x > 0: monotone in x for each y and in y for each x, so the extremes are at the
// corners (MPFR's pow, correctly rounded down and up).
ExactRange pow_range(Interval x, Interval y) {
    ExactRange e{true, inf, -inf};
    for (const double a : {x.lo, x.hi})
        for (const double b : {y.lo, y.hi}) extend_by(e, mpfr_pow, a, b);
    return e;
}

// atan2 over a (y, x) box: the angle in (-pi, pi] is continuous on the closed upper half-plane less the
// origin (values in [0, pi]) and on the open lower one (in (-pi, 0)), and on each part of the box monotone
// along each axis. So its infimum and supremum over each part are at the part's corners other than the
// origin, the lower part's top edge taken as y = -0 (its limits: -pi for x < 0) and infinite ends as
// limits (MPFR's atan2 has C's special values). `defined` false when the box is the origin alone.
ExactRange atan2_range(Interval y, Interval x) {
    ExactRange e{true, inf, -inf};
    auto corners = [&](double y_lo, double y_hi) {
        for (const double b : {y_lo, y_hi})
            for (const double a : {x.lo, x.hi})
                if (b != 0 || a != 0) extend_by(e, mpfr_atan2, b, a);
    };
    if (y.hi >= 0) corners(y.lo > 0 ? y.lo : 0.0, y.hi > 0 ? y.hi : 0.0);
    if (y.lo < 0) corners(y.lo, y.hi < 0 ? y.hi : -0.0);
    if (e.lo > e.hi) return {false};
    return e;
}

// ---- the check ----
struct Kernel {
    const char* name;
    ir::Op op;
};

struct Tally {
    std::uint64_t pairs = 0, checked = 0, violations = 0, empty_ok = 0, exact = 0, outside_domain = 0;
    // width / exact width in the kernel's domain (|lo|, |hi| <= 2^30; exp: 700): all, and exact width >=
    // 2^-20
    std::vector<double> ratios, cell_ratios;
    std::string first;
};

std::string hex(double x) {
    char b[64];
    std::snprintf(b, sizeof b, "%a", x);
    return b;
}

Tally check(const Kernel& k, const std::vector<Interval>& in, const std::vector<Interval>& out,
            const std::vector<ExactRange>& exact) {
    Tally t;
    for (std::size_t i = 0; i < in.size(); ++i) {
        ++t.pairs;
        const Interval a = in[i], r = out[i];
        auto fail = [&](const std::string& why) {
            ++t.violations;
            if (t.first.empty())
                t.first = std::string(k.name) + "([" + hex(a.lo) + ", " + hex(a.hi) + "]) = [" + hex(r.lo) +
                          ", " + hex(r.hi) + "]: " + why;
        };
        if (a.is_empty()) { // (NaN bounds make an interval empty; the engines pass it on)
            if (r.is_empty())
                ++t.empty_ok;
            else
                fail("an empty argument gives a non-empty result");
            continue;
        }
        if (std::isnan(r.lo) || std::isnan(r.hi)) {
            fail("NaN bound");
            continue;
        }
        const ExactRange& x = exact[i];
        if (!x.defined) {
            // sqrt and log of a negative interval are empty; sin, cos and tan of {inf} have nothing to
            // contain.
            if (k.op == ir::Op::Sqrt || k.op == ir::Op::Log) {
                ++t.checked;
                ++t.outside_domain;
                if (!r.is_empty()) fail("an interval outside the domain does not give an empty result");
            }
            continue;
        }
        ++t.checked;
        if (!(r.lo <= x.lo && x.hi <= r.hi)) {
            fail("the exact range is [" + hex(x.lo) + ", " + hex(x.hi) + "] (outward rounded)");
            continue;
        }
        if (r.lo == x.lo && r.hi == x.hi) ++t.exact;
        const double w = x.hi - x.lo;
        // Tightness within the kernels' own domain (beyond it the numeric core answers).
        const double domain = k.op == ir::Op::Exp ? 700 : k.op == ir::Op::Log ? 0x1p1023 : 0x1p30;
        const bool in_domain = k.op == ir::Op::Log ? a.lo >= 0x1p-1022 : std::fabs(a.lo) <= domain;
        if (w > 0 && std::isfinite(w) && in_domain && std::fabs(a.hi) <= domain) {
            const double ratio = (r.hi - r.lo) / w;
            t.ratios.push_back(ratio);
            if (w >= 0x1p-20 * std::max({1.0, std::fabs(x.lo), std::fabs(x.hi)}))
                t.cell_ratios.push_back(ratio);
        }
    }
    return t;
}

std::string ratio_summary(std::vector<double> v) {
    if (v.empty()) return "-";
    std::sort(v.begin(), v.end());
    char b[96];
    std::snprintf(b, sizeof b, "median %.9g, worst %.9g", v[v.size() / 2], v.back());
    return b;
}

struct Outcome {
    int passed = 0, failed = 0;
    std::uint64_t total_checked = 0;
};
using Variants = std::vector<std::pair<std::string, jit::JitConfig>>;

// A binary kernel (pow, atan2) on the boxes (boxes[2i], boxes[2i + 1]) in every variant: each result
// must contain the exact range and the numeric core's enclosure, and an empty argument give an empty
// result (boxes with no value, the origin for atan2, are not counted). Then the check must be able to fail:
// the interpreter's enclosures narrowed by one double at each end are rejected.
void check_binary(const Kernel& k, const std::vector<Interval>& boxes, const std::vector<ExactRange>& exact,
                  const Variants& variants, Outcome& outcome) {
    const std::size_t count = exact.size();
    struct BoxTally {
        std::uint64_t checked = 0, empty = 0, undefined = 0, violations = 0;
        std::vector<double> ratios, cell_ratios;
        std::string first;
    };
    auto tally = [&](const std::vector<Interval>& out) {
        BoxTally t;
        for (std::size_t i = 0; i < count; ++i) {
            const Interval a = boxes[2 * i], b = boxes[2 * i + 1], r = out[i];
            const ExactRange& x = exact[i];
            std::string why;
            if (a.is_empty() || b.is_empty()) {
                ++t.empty;
                if (!r.is_empty()) why = "an empty argument gives a non-empty result";
            } else if (!x.defined) {
                ++t.undefined;
                continue;
            } else if (!(r.lo <= x.lo && x.hi <= r.hi)) {
                why = "the exact range is [" + hex(x.lo) + ", " + hex(x.hi) + "] (outward rounded)";
            } else if (const double w = x.hi - x.lo; w > 0 && std::isfinite(w)) {
                t.ratios.push_back((r.hi - r.lo) / w);
                if (w >= 0x1p-20 * std::max({1.0, std::fabs(x.lo), std::fabs(x.hi)}))
                    t.cell_ratios.push_back(t.ratios.back());
            }
            ++t.checked;
            if (why.empty()) continue;
            ++t.violations;
            if (t.first.empty())
                t.first = std::string(k.name) + "([" + hex(a.lo) + ", " + hex(a.hi) + "], [" + hex(b.lo) +
                          ", " + hex(b.hi) + "]) = [" + hex(r.lo) + ", " + hex(r.hi) + "]: " + why;
        }
        return t;
    };
    ir::Graph g;
    const ir::Tape tape = ir::build_tape(g, g.op(k.op, g.var(0), g.var(1)), 2);
    auto interp = interp::make_interpreter(tape);
    std::vector<Interval> core(count);
    interp->eval_boxes(boxes.data(), count, core.data());
    for (const auto& [label, config] : variants) {
        auto e = jit::make_jit(tape, {}, config);
        std::vector<Interval> out(count);
        e->eval_boxes(boxes.data(), count, out.data());
        const BoxTally t = tally(out);
        // The engines' cross-checks also rely on the kernel containing the numeric core's enclosure.
        std::uint64_t misses_core = 0;
        for (std::size_t i = 0; i < count; ++i) misses_core += !out[i].contains(core[i]);
        outcome.total_checked += t.checked;
        std::printf(
            "%-5s %-15s %llu boxes checked (%llu empty), %llu violations, %llu not containing the core's "
            "enclosure; width / exact width: %s; exact width >= 2^-20 max(1, |f|): %s\n",
            k.name, label.c_str(), static_cast<unsigned long long>(t.checked),
            static_cast<unsigned long long>(t.empty), static_cast<unsigned long long>(t.violations),
            static_cast<unsigned long long>(misses_core), ratio_summary(t.ratios).c_str(),
            ratio_summary(t.cell_ratios).c_str());
        if (t.violations == 0 && misses_core == 0 && t.checked + t.undefined == count &&
            t.checked > count / 2) {
            ++outcome.passed;
        } else {
            ++outcome.failed;
            std::printf("FAIL: %s %s: %s\n", k.name, label.c_str(), t.first.c_str());
        }
    }
    std::vector<Interval> narrowed = core;
    for (Interval& r : narrowed)
        if (!r.is_empty() && std::isfinite(r.lo) && std::isfinite(r.hi) && r.lo < r.hi)
            r = {std::nextafter(r.lo, inf), std::nextafter(r.hi, -inf)};
    if (tally(narrowed).violations > 0) {
        ++outcome.passed;
    } else {
        ++outcome.failed;
        std::printf("FAIL: %s: the check did not catch narrowed enclosures\n", k.name);
    }
}

} // namespace

int main(int argc, char** argv) {
    const std::uint64_t pairs = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 1200000;
    std::string why;
    if (!jit::jit_available(&why)) {
        std::printf("FAIL: the JIT cannot be used on this machine: %s\n0 passed, 1 failed\n", why.c_str());
        return 1;
    }
    if (const char* v = std::getenv("FRAC_JIT_EXACT_CALLS"); v && std::string(v) == "1")
        std::printf("note: FRAC_JIT_EXACT_CALLS=1, the kernels are the numeric core's calls\n");
    using R = jit::JitConfig::Rounding;
    Variants variants = {{"default", jit::codegen_config(R::automatic, 0)},
                         {"constrained x4", jit::codegen_config(R::constrained, 4)},
                         {"constrained x1", jit::codegen_config(R::constrained, 1)}};
    if (jit::host_has_avx512()) variants.push_back({"avx512 x1", jit::codegen_config(R::avx512, 1)});
    const Kernel kernels[] = {{"sqrt", ir::Op::Sqrt}, {"sin", ir::Op::Sin}, {"cos", ir::Op::Cos},
                              {"exp", ir::Op::Exp},   {"tan", ir::Op::Tan}, {"log", ir::Op::Log}};

    Outcome outcome;
    std::uint64_t seed = 20261202;
    for (const Kernel& k : kernels) {
        IntervalMaker maker(seed++);
        std::vector<Interval> in(pairs);
        std::vector<ExactRange> exact(pairs);
        for (std::uint64_t i = 0; i < pairs; ++i) {
            in[i] = maker.next();
            if (in[i].is_empty()) continue;
            exact[i] = k.op == ir::Op::Sqrt  ? sqrt_range(in[i].lo, in[i].hi)
                       : k.op == ir::Op::Exp ? increasing_range(mpfr_exp, in[i].lo, in[i].hi)
                       : k.op == ir::Op::Tan ? tan_range(in[i].lo, in[i].hi)
                       : k.op == ir::Op::Log ? log_range(in[i].lo, in[i].hi)
                                             : sincos_range(in[i].lo, in[i].hi, k.op == ir::Op::Cos);
        }
        ir::Graph g;
        const ir::Tape tape = ir::build_tape(g, g.op(k.op, g.var(0)), 1);
        for (const auto& [label, config] : variants) {
            auto e = jit::make_jit(tape, {}, config);
            std::vector<Interval> out(in.size());
            e->eval_boxes(in.data(), in.size(), out.data());
            const Tally t = check(k, in, out, exact);
            outcome.total_checked += t.checked;
            std::printf("%-4s %-15s %llu pairs, %llu checked, %llu correctly rounded, %llu violations; "
                        "width / exact width (kernel domain): %s; exact width >= 2^-20 max(1, |f|): %s\n",
                        k.name, label.c_str(), static_cast<unsigned long long>(t.pairs),
                        static_cast<unsigned long long>(t.checked), static_cast<unsigned long long>(t.exact),
                        static_cast<unsigned long long>(t.violations), ratio_summary(t.ratios).c_str(),
                        ratio_summary(t.cell_ratios).c_str());
            const bool ok = t.violations == 0 && t.checked > pairs / 2;
            // sqrt is exact: directed rounding gives the correctly rounded range on every pair with a value.
            const bool tight = k.op != ir::Op::Sqrt || t.exact + t.outside_domain == t.checked;
            if (ok && tight) {
                ++outcome.passed;
            } else {
                ++outcome.failed;
                std::printf("FAIL: %s %s: %s\n", k.name, label.c_str(),
                            t.first.empty() ? "sqrt not correctly rounded" : t.first.c_str());
            }
        }
        // The check must be able to fail: the interpreter's correctly rounded enclosures, one double
        // narrower at each end, are rejected.
        {
            auto interp = interp::make_interpreter(tape);
            std::vector<Interval> narrowed(in.size());
            interp->eval_boxes(in.data(), in.size(), narrowed.data());
            for (Interval& r : narrowed)
                if (!r.is_empty() && std::isfinite(r.lo) && std::isfinite(r.hi))
                    r = {std::nextafter(r.lo, inf), std::nextafter(r.hi, -inf)};
            const Tally t = check(k, in, narrowed, exact);
            if (t.violations > 0) {
                ++outcome.passed;
            } else {
                ++outcome.failed;
                std::printf("FAIL: %s: the check did not catch narrowed enclosures\n", k.name);
            }
        }
    }
    // pow(x, y): positive bases, exponents of every kind.
    {
        IntervalMaker maker(seed++);
        std::vector<Interval> boxes(2 * pairs);
        std::vector<ExactRange> exact(pairs);
        for (std::uint64_t i = 0; i < pairs; ++i) {
            boxes[2 * i] = maker.positive();
            boxes[2 * i + 1] = maker.exponent();
            if (!boxes[2 * i + 1].is_empty()) exact[i] = pow_range(boxes[2 * i], boxes[2 * i + 1]);
        }
        check_binary({"pow", ir::Op::Pow}, boxes, exact, variants, outcome);
    }
    // atan2(y, x): boxes of every kind, on and across the axes, around the origin, across the cut.
    {
        IntervalMaker maker(seed++);
        std::vector<Interval> boxes(2 * pairs);
        std::vector<ExactRange> exact(pairs);
        for (std::uint64_t i = 0; i < pairs; ++i) {
            std::tie(boxes[2 * i], boxes[2 * i + 1]) = maker.plane_box();
            if (!boxes[2 * i].is_empty() && !boxes[2 * i + 1].is_empty())
                exact[i] = atan2_range(boxes[2 * i], boxes[2 * i + 1]);
        }
        check_binary({"atan2", ir::Op::Atan2}, boxes, exact, variants, outcome);
    }
    std::printf("%llu (interval, kernel, variant) checks\n%d passed, %d failed\n",
                static_cast<unsigned long long>(outcome.total_checked), outcome.passed, outcome.failed);
    return outcome.failed ? 1 : 0;
}
