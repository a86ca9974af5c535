#include "backend/llvm/helpers.hpp"

#include "ir/external.hpp"
#include "ir/graph.hpp"
#include "ir/semantics.hpp"
#include "ir/series_tail.hpp"
#include "numeric/interval.hpp"

#include <cmath>

using frac::jit::CInterval;
namespace num = frac::num;

namespace {
CInterval out(num::Interval v) {
    return {v.lo, v.hi};
}
// The certificate of ir::OrbitEscape from the helpers' arguments.
frac::ir::OrbitEscape escape_of(double radius, double slope, double offset, double scale0_lo,
                                double scale0_hi, double growth_lo, double growth_hi, double lipschitz = 0.0,
                                double map_lipschitz = 0.0) {
    frac::ir::OrbitEscape e;
    e.present = true;
    e.radius = radius;
    e.slope = slope;
    e.offset = offset;
    e.scale0 = {scale0_lo, scale0_hi};
    e.growth = {growth_lo, growth_hi};
    e.lipschitz = lipschitz;
    e.map_lipschitz = map_lipschitz;
    return e;
}
} // namespace

extern "C" {

CInterval frac_jit_div(double alo, double ahi, double blo, double bhi) noexcept {
    return out(num::div({alo, ahi}, {blo, bhi}));
}
CInterval frac_jit_pow(double alo, double ahi, double blo, double bhi) noexcept {
    return out(num::pow({alo, ahi}, {blo, bhi}));
}
CInterval frac_jit_atan2(double ylo, double yhi, double xlo, double xhi) noexcept {
    return out(num::atan2({ylo, yhi}, {xlo, xhi}));
}
CInterval frac_jit_sqrt(double lo, double hi) noexcept {
    return out(num::sqrt({lo, hi}));
}
CInterval frac_jit_sin(double lo, double hi) noexcept {
    return out(num::sin({lo, hi}));
}
CInterval frac_jit_cos(double lo, double hi) noexcept {
    return out(num::cos({lo, hi}));
}
CInterval frac_jit_tan(double lo, double hi) noexcept {
    return out(num::tan({lo, hi}));
}
CInterval frac_jit_exp(double lo, double hi) noexcept {
    return out(num::exp({lo, hi}));
}
CInterval frac_jit_log(double lo, double hi) noexcept {
    return out(num::log({lo, hi}));
}
CInterval frac_jit_powi(double lo, double hi, std::int64_t n) noexcept {
    return out(num::powi({lo, hi}, n));
}

CInterval frac_jit_external(const void* f, double alo, double ahi, double blo, double bhi, double clo,
                            double chi) noexcept {
    const num::Interval args[3] = {{alo, ahi}, {blo, bhi}, {clo, chi}};
    if (!f) return out(num::Interval::entire()); // a compiled model's function could not be rebuilt
    try {
        return out(static_cast<const frac::ir::ExternalFunction*>(f)->eval_box(args));
    } catch (...) {
        return out(num::Interval::entire()); // no exception crosses generated code: nothing is known
    }
}

double frac_jit_external_point(const void* f, double a, double b, double c) noexcept {
    const double args[3] = {a, b, c};
    if (!f) return std::nan("");
    try {
        return static_cast<const frac::ir::ExternalFunction*>(f)->eval_point(args);
    } catch (...) {
        return std::nan("");
    }
}

void frac_jit_vexternal(const void* f, const double* in, double* out, std::uint32_t mask,
                        int lanes) noexcept {
    for (int l = 0; l < lanes; ++l) {
        CInterval r{0.0, 0.0};
        if (mask >> l & 1)
            r = frac_jit_external(f, in[l], in[lanes + l], in[2 * lanes + l], in[3 * lanes + l],
                                  in[4 * lanes + l], in[5 * lanes + l]);
        out[l] = r.lo;
        out[lanes + l] = r.hi;
    }
}

void frac_jit_vop(int op, std::int64_t imm, const double* in, double* out, std::uint32_t mask,
                  int lanes) noexcept {
    const auto o = static_cast<frac::ir::Op>(op);
    const int arity = frac::ir::arity(o);
    for (int l = 0; l < lanes; ++l) {
        num::Interval r(0.0);
        if (mask >> l & 1) {
            num::Interval args[3];
            for (int k = 0; k < arity; ++k) args[k] = {in[2 * k * lanes + l], in[(2 * k + 1) * lanes + l]};
            r = frac::ir::apply_interval(o, args, imm);
        }
        out[l] = r.lo;
        out[lanes + l] = r.hi;
    }
}

void frac_jit_vtail(int kind, const double* in, const std::int64_t* n, double* out, int has_b,
                    double gamma_lo, double gamma_hi, std::uint32_t mask, int lanes) noexcept {
    const auto o = static_cast<frac::ir::Op>(kind);
    for (int l = 0; l < lanes; ++l) {
        num::Interval r(0.0);
        if (mask >> l & 1)
            r = frac::ir::series_tail(o, {in[l], in[lanes + l]}, {in[2 * lanes + l], in[3 * lanes + l]},
                                      has_b != 0, {gamma_lo, gamma_hi}, n[l]);
        out[l] = r.lo;
        out[lanes + l] = r.hi;
    }
}

void frac_jit_vescape(int kind, const double* in, const std::int64_t* n, double* out, int dims, double radius,
                      double slope, double offset, double scale0_lo, double scale0_hi, double growth_lo,
                      double growth_hi, double lipschitz, double map_lipschitz, const double* h,
                      std::uint32_t mask, int lanes) noexcept {
    const auto o = static_cast<frac::ir::Op>(kind);
    const frac::ir::OrbitEscape e = escape_of(radius, slope, offset, scale0_lo, scale0_hi, growth_lo,
                                              growth_hi, lipschitz, map_lipschitz);
    num::Interval state[frac::ir::max_state_components];
    for (int l = 0; l < lanes; ++l) {
        if (!(mask >> l & 1)) {
            out[l] = out[lanes + l] = o == frac::ir::Op::SeriesMax ? num::inf : -num::inf;
            continue;
        }
        for (int c = 0; c < dims; ++c) state[c] = {in[2 * c * lanes + l], in[(2 * c + 1) * lanes + l]};
        out[l] = frac::ir::escape_bound(o, e, state, dims, n[l]);
        out[lanes + l] = frac::ir::escape_bound_around(o, e, state, dims, n[l], h ? h[l] : 0.0);
    }
}

void frac_jit_vcentre(double* in, int dims, double* h, std::uint32_t mask, int lanes) noexcept {
    num::Interval state[frac::ir::max_state_components];
    for (int l = 0; l < lanes; ++l) {
        h[l] = 0.0;
        if (!(mask >> l & 1)) continue;
        for (int c = 0; c < dims; ++c) state[c] = {in[2 * c * lanes + l], in[(2 * c + 1) * lanes + l]};
        h[l] = frac::ir::lipschitz_centre(state, dims);
        for (int c = 0; c < dims; ++c) {
            in[2 * c * lanes + l] = state[c].lo;
            in[(2 * c + 1) * lanes + l] = state[c].hi;
        }
    }
}

void frac_jit_vfinish(int kind, double* io, const double* bound, const std::int64_t* n, const double* h,
                      double radius, double slope, double offset, double scale0_lo, double scale0_hi,
                      double growth_lo, double growth_hi, double lipschitz, double map_lipschitz,
                      std::uint32_t mask, int lanes) noexcept {
    const auto o = static_cast<frac::ir::Op>(kind);
    const frac::ir::OrbitEscape e = escape_of(radius, slope, offset, scale0_lo, scale0_hi, growth_lo,
                                              growth_hi, lipschitz, map_lipschitz);
    for (int l = 0; l < lanes; ++l) {
        num::Interval r(0.0);
        if (mask >> l & 1)
            r = frac::ir::lipschitz_finish(o, e, {io[l], io[lanes + l]},
                                           {io[2 * lanes + l], io[3 * lanes + l]}, bound[l], n[l], h[l]);
        io[l] = r.lo;
        io[lanes + l] = r.hi;
    }
}

int frac_jit_escape_point_done(int kind, double acc, const double* state, int dims, std::int64_t n,
                               double radius, double slope, double offset, double scale0_lo, double scale0_hi,
                               double growth_lo, double growth_hi) noexcept {
    const frac::ir::OrbitEscape e =
        escape_of(radius, slope, offset, scale0_lo, scale0_hi, growth_lo, growth_hi);
    return frac::ir::escape_point_done(static_cast<frac::ir::Op>(kind), e, acc, state, dims, n) ? 1 : 0;
}

double frac_jit_pow_point(double x, double y) noexcept {
    return std::pow(x, y);
}
double frac_jit_sin_point(double x) noexcept {
    return std::sin(x);
}
double frac_jit_cos_point(double x) noexcept {
    return std::cos(x);
}
double frac_jit_tan_point(double x) noexcept {
    return std::tan(x);
}
double frac_jit_exp_point(double x) noexcept {
    return std::exp(x);
}
double frac_jit_log_point(double x) noexcept {
    return std::log(x);
}
double frac_jit_atan2_point(double y, double x) noexcept {
    return std::atan2(y, x);
}

CInterval frac_jit_series_tail(int kind, double alo, double ahi, double blo, double bhi, int has_b,
                               double gamma_lo, double gamma_hi, std::int64_t n) noexcept {
    return out(frac::ir::series_tail(static_cast<frac::ir::Op>(kind), {alo, ahi}, {blo, bhi}, has_b != 0,
                                     {gamma_lo, gamma_hi}, n));
}

double frac_jit_point_series_end(int kind, double acc, double comp, double a_lo, double a_hi, double b_lo,
                                 double b_hi, int has_b, double gamma_lo, double gamma_hi,
                                 std::int64_t n) noexcept {
    return frac::ir::series_point_end(static_cast<frac::ir::Op>(kind), acc, comp, a_lo, a_hi, b_lo, b_hi,
                                      has_b != 0, {gamma_lo, gamma_hi}, n);
}

} // extern "C"

namespace frac::jit {

const std::vector<Helper>& helpers() {
#define FRAC_HELPER(fn)                                                                                      \
    Helper {                                                                                                 \
#fn, reinterpret_cast < void*>(&fn)                                                                  \
    }
    static const std::vector<Helper> list = {
        FRAC_HELPER(frac_jit_div),
        FRAC_HELPER(frac_jit_pow),
        FRAC_HELPER(frac_jit_atan2),
        FRAC_HELPER(frac_jit_sqrt),
        FRAC_HELPER(frac_jit_sin),
        FRAC_HELPER(frac_jit_cos),
        FRAC_HELPER(frac_jit_tan),
        FRAC_HELPER(frac_jit_exp),
        FRAC_HELPER(frac_jit_log),
        FRAC_HELPER(frac_jit_powi),
        FRAC_HELPER(frac_jit_pow_point),
        FRAC_HELPER(frac_jit_sin_point),
        FRAC_HELPER(frac_jit_cos_point),
        FRAC_HELPER(frac_jit_tan_point),
        FRAC_HELPER(frac_jit_exp_point),
        FRAC_HELPER(frac_jit_log_point),
        FRAC_HELPER(frac_jit_atan2_point),
        FRAC_HELPER(frac_jit_series_tail),
        FRAC_HELPER(frac_jit_point_series_end),
        FRAC_HELPER(frac_jit_vop),
        FRAC_HELPER(frac_jit_vtail),
        FRAC_HELPER(frac_jit_vescape),
        FRAC_HELPER(frac_jit_vcentre),
        FRAC_HELPER(frac_jit_vfinish),
        FRAC_HELPER(frac_jit_escape_point_done),
        FRAC_HELPER(frac_jit_external),
        FRAC_HELPER(frac_jit_external_point),
        FRAC_HELPER(frac_jit_vexternal),
    };
#undef FRAC_HELPER
    return list;
}

} // namespace frac::jit
