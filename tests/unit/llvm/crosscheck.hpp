// JIT against the interpreter on one tape: bit-identical box enclosures, point values and series term
// counts, box by box, point by point and in batches.
#pragma once

#include "engines.hpp"

namespace frac::test {

struct CrossCheckResult {
    std::size_t boxes = 0, points = 0, box_mismatches = 0, point_mismatches = 0, stat_mismatches = 0;
    std::string first; // description of the first mismatch
};

// A configuration with LLVM's unoptimised machine code generation (the tiered engine's first compile).
inline jit::JitConfig fast_codegen(jit::JitConfig c) {
    c.fast_codegen = true;
    return c;
}

// The code generator's variants: the host's default and each rounding form at several widths, and
// the fast machine code generation of the default and of the portable form.
inline std::vector<jit::JitConfig> jit_configs() {
    using R = jit::JitConfig::Rounding;
    std::vector<jit::JitConfig> c = {jit::codegen_config(R::automatic, 0),
                                     jit::codegen_config(R::constrained, 1),
                                     jit::codegen_config(R::constrained, 4)};
    if (jit::host_has_avx512()) {
        c.push_back(jit::codegen_config(R::avx512, 1));
        c.push_back(jit::codegen_config(R::constrained, 8));
    }
    c.push_back(fast_codegen(jit::codegen_config(R::automatic, 0)));
    c.push_back(fast_codegen(jit::codegen_config(R::constrained, 4)));
    return c;
}

inline std::string describe(const jit::JitConfig& c) {
    const char* r = c.rounding == jit::JitConfig::Rounding::automatic     ? "automatic"
                    : c.rounding == jit::JitConfig::Rounding::constrained ? "constrained"
                                                                          : "avx512";
    return std::string(r) + " x" + std::to_string(c.lanes) + (c.fast_codegen ? " fast codegen" : "");
}

// Whether the tape has an operation whose inline kernel encloses more loosely than the numeric core
// (sin, cos, exp, tan, log, atan2, pow with an exponent that may not be an integer: a few ulps,
// backend/llvm/box_kernels.cpp); sqrt's kernel is exact. The tiered engine relies on the others
// agreeing bit for bit, which cross_check verifies on them with the JIT's own kernels.
inline bool has_loose_kernel(const ir::Tape& tape) {
    return !jit::tiers_exactly(tape);
}

// Whether `outer` contains `inner` up to `ulps` steps of a double at each end: a kernel a few ulps
// wider at one operation can make a later one tighter (atan2(+0, x) is exactly 0 where an interval
// with a lower bound a few subnormals below 0 gives -0x0.0000000000004p-1022, a select or a
// comparison can flip on a bound), so the interpreter's enclosure may poke out by that much.
inline bool contains_within_ulps(Interval outer, Interval inner, int ulps) {
    double lo = outer.lo, hi = outer.hi;
    for (int k = 0; k < ulps; ++k) {
        lo = std::nextafter(lo, -num::inf);
        hi = std::nextafter(hi, num::inf);
    }
    return Interval{lo, hi}.contains(inner);
}

// Tapes with a loose kernel: the JIT with the core's calls agrees bit for bit (cross_check), and the
// JIT with the inline kernels contains the interpreter's enclosure on every box up to 4 ulps at each
// end (contains_within_ulps), unless a series decides its term count from enclosure widths (then the
// results are not nested). The MPFI suites (tests/soundness) check the kernels' soundness itself.
inline void check_loose_kernels(const ir::Tape& tape, const std::vector<Interval>& all, std::size_t count,
                                const ir::EvalOptions& options, const jit::JitConfig& config,
                                CrossCheckResult& r) {
    if (!has_loose_kernel(tape) || !tape.series.empty()) return;
    auto in = interp::make_interpreter(tape, options);
    auto jt = jit::make_jit(tape, options, config);
    std::vector<Interval> oi(count), oj(count);
    in->eval_boxes(all.data(), count, oi.data());
    jt->eval_boxes(all.data(), count, oj.data());
    for (std::size_t n = 0; n < count; ++n) {
        ++r.boxes;
        if (!contains_within_ulps(oj[n], oi[n], 4) || std::isnan(oj[n].lo) || std::isnan(oj[n].hi)) {
            ++r.box_mismatches;
            if (r.first.empty())
                r.first = "inline kernels, box " + std::to_string(n) + ": interp " + hex(oi[n]) + ", jit " +
                          hex(oj[n]) + " does not contain it";
        }
    }
}

inline CrossCheckResult cross_check(const ir::Tape& tape, const std::vector<Interval>& range,
                                    std::uint64_t seed, std::size_t count,
                                    const ir::EvalOptions& options = {}, bool with_empty = true,
                                    const jit::JitConfig& config = {}) {
    CrossCheckResult r;
    auto in = interp::make_interpreter(tape, options);
    auto jt = has_loose_kernel(tape) ? make_jit_exact_calls(tape, options, config)
                                     : jit::make_jit(tape, options, config);
    const int d = tape.inputs;
    BoxMaker mk(seed);
    std::vector<Interval> all;
    std::vector<double> all_points;
    auto note = [&](const std::string& what) {
        if (r.first.empty()) r.first = what;
    };
    for (std::size_t n = 0; n < count; ++n) {
        std::vector<Interval> b = mk.box(range);
        if (with_empty && d > 0 && mk.pick(64) == 0)
            b[static_cast<std::size_t>(mk.pick(d))] = Interval::empty();
        all.insert(all.end(), b.begin(), b.end());
        in->stats = {};
        jt->stats = {};
        const Interval ri = in->eval_box(b.data());
        const Interval rj = jt->eval_box(b.data());
        ++r.boxes;
        if (!same(ri, rj)) {
            ++r.box_mismatches;
            note("box " + hex_box(b.data(), d) + ": interp " + hex(ri) + ", jit " + hex(rj));
        }
        if (in->stats.series_terms != jt->stats.series_terms ||
            in->stats.series_capped != jt->stats.series_capped || in->stats.calls != jt->stats.calls) {
            ++r.stat_mismatches;
            note("box " + hex_box(b.data(), d) + ": terms interp " + std::to_string(in->stats.series_terms) +
                 " jit " + std::to_string(jt->stats.series_terms) + ", capped " +
                 std::to_string(in->stats.series_capped) + " / " + std::to_string(jt->stats.series_capped));
        }
        const std::vector<double> p = mk.point(range);
        all_points.insert(all_points.end(), p.begin(), p.end());
        in->stats = {};
        jt->stats = {};
        const double pi = in->eval_point(p.data());
        const double pj = jt->eval_point(p.data());
        ++r.points;
        if (!same(pi, pj)) {
            ++r.point_mismatches;
            std::string at;
            for (double v : p) at += hex(v) + " ";
            note("point " + at + ": interp " + hex(pi) + ", jit " + hex(pj));
        }
        if (in->stats.series_terms != jt->stats.series_terms ||
            in->stats.series_capped != jt->stats.series_capped) {
            ++r.stat_mismatches;
            note("point: terms differ");
        }
    }
    // The same boxes and points as one batch each.
    std::vector<Interval> oi(count), oj(count);
    in->stats = {};
    jt->stats = {};
    in->eval_boxes(all.data(), count, oi.data());
    jt->eval_boxes(all.data(), count, oj.data());
    for (std::size_t n = 0; n < count; ++n)
        if (!same(oi[n], oj[n])) {
            ++r.box_mismatches;
            note("batch box " + std::to_string(n) + ": interp " + hex(oi[n]) + ", jit " + hex(oj[n]));
        }
    if (in->stats.series_terms != jt->stats.series_terms ||
        in->stats.series_capped != jt->stats.series_capped || in->stats.calls != jt->stats.calls) {
        ++r.stat_mismatches;
        note("batch: stats differ");
    }
    std::vector<double> pi(count), pj(count);
    in->eval_points(all_points.data(), count, pi.data());
    jt->eval_points(all_points.data(), count, pj.data());
    for (std::size_t n = 0; n < count; ++n)
        if (!same(pi[n], pj[n])) {
            ++r.point_mismatches;
            note("batch point " + std::to_string(n) + ": interp " + hex(pi[n]) + ", jit " + hex(pj[n]));
        }
    check_loose_kernels(tape, all, count, options, config, r);
    return r;
}

// cross_check for every code generator variant (the box and point counts are split among them).
inline CrossCheckResult cross_check_all(const ir::Tape& tape, const std::vector<Interval>& range,
                                        std::uint64_t seed, std::size_t count,
                                        const ir::EvalOptions& options = {}) {
    CrossCheckResult total;
    const auto configs = jit_configs();
    for (std::size_t k = 0; k < configs.size(); ++k) {
        // The default variant gets the most boxes; the others a share each.
        const std::size_t n = k == 0 ? count : std::max<std::size_t>(count / 4, 16);
        const CrossCheckResult r = cross_check(tape, range, seed + 7919 * k, n, options, true, configs[k]);
        total.boxes += r.boxes;
        total.points += r.points;
        total.box_mismatches += r.box_mismatches;
        total.point_mismatches += r.point_mismatches;
        total.stat_mismatches += r.stat_mismatches;
        if (total.first.empty() && !r.first.empty()) total.first = describe(configs[k]) + ": " + r.first;
    }
    return total;
}

#define FRAC_REQUIRE_IDENTICAL(result)                                                                       \
    do {                                                                                                     \
        const auto& r_ = (result);                                                                           \
        INFO(r_.first);                                                                                      \
        CHECK(r_.box_mismatches == 0);                                                                       \
        CHECK(r_.point_mismatches == 0);                                                                     \
        CHECK(r_.stat_mismatches == 0);                                                                      \
    } while (0)

} // namespace frac::test
