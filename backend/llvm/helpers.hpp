// The functions generated code calls for the operations it does not inline: thin extern "C" wrappers
// of the numeric core (interval forms, called under upward rounding) and of the C library (point forms,
// called in round to nearest), exactly as the interpreter calls them. No LLVM here.
#pragma once

#include <cstdint>
#include <vector>

namespace frac::jit {

// Interval results come back as a C struct of two doubles (returned in two registers on x86-64 and
// AArch64, which is how the generated code declares them: { double, double }).
struct CInterval {
    double lo, hi;
};

struct Helper {
    const char* name;
    void* address;
};
// Every helper, for registering their addresses with the JIT.
const std::vector<Helper>& helpers();

} // namespace frac::jit

extern "C" {
// Interval operations (upward rounding active): a = [alo, ahi], b = [blo, bhi].
frac::jit::CInterval frac_jit_div(double alo, double ahi, double blo, double bhi) noexcept;
frac::jit::CInterval frac_jit_pow(double alo, double ahi, double blo, double bhi) noexcept;
frac::jit::CInterval frac_jit_atan2(double ylo, double yhi, double xlo, double xhi) noexcept;
frac::jit::CInterval frac_jit_sqrt(double lo, double hi) noexcept;
frac::jit::CInterval frac_jit_sin(double lo, double hi) noexcept;
frac::jit::CInterval frac_jit_cos(double lo, double hi) noexcept;
frac::jit::CInterval frac_jit_tan(double lo, double hi) noexcept;
frac::jit::CInterval frac_jit_exp(double lo, double hi) noexcept;
frac::jit::CInterval frac_jit_log(double lo, double hi) noexcept;
frac::jit::CInterval frac_jit_powi(double lo, double hi, std::int64_t n) noexcept;
// Op::External: the ir::ExternalFunction at `f` (a pointer the JIT embeds as a constant; a compiled
// model's getter returns it, codegen.hpp) over the box [alo, ahi] x [blo, bhi] x [clo, chi] (upward
// rounding active); entire if it throws or `f` is null.
frac::jit::CInterval frac_jit_external(const void* f, double alo, double ahi, double blo, double bhi,
                                       double clo, double chi) noexcept;
// Its point value (round to nearest); NaN if it throws or `f` is null.
double frac_jit_external_point(const void* f, double a, double b, double c) noexcept;
// frac_jit_external per lane of `mask`, laid out as for frac_jit_vop (three operands).
void frac_jit_vexternal(const void* f, const double* in, double* out, std::uint32_t mask, int lanes) noexcept;
// Vector code: ir::apply_interval(op, args, imm) for each lane l < lanes whose bit is set in `mask`.
// in: for each operand k, lanes lower bounds then lanes upper bounds (in[2 k lanes + l], in[(2 k + 1) lanes +
// l]); out: lanes lower bounds, then lanes upper bounds (lanes outside the mask get 0).
void frac_jit_vop(int op, std::int64_t imm, const double* in, double* out, std::uint32_t mask,
                  int lanes) noexcept;
// ir::series_tail per lane: in holds A.lo, A.hi, B.lo, B.hi (lanes each), n the index of each lane.
void frac_jit_vtail(int kind, const double* in, const std::int64_t* n, double* out, int has_b,
                    double gamma_lo, double gamma_hi, std::uint32_t mask, int lanes) noexcept;
// ir::escape_bound per lane: in holds, for each orbit component c, lanes lower bounds then lanes upper
// bounds (in[2 c lanes + l], in[(2 c + 1) lanes + l]); n the index of each lane's orbit point; the
// certificate's fields as arguments. Lanes outside the mask get the "no bound" value.
// out[lanes + l]: ir::escape_bound_around with radius h[l] (h null: 0).
void frac_jit_vescape(int kind, const double* in, const std::int64_t* n, double* out, int dims, double radius,
                      double slope, double offset, double scale0_lo, double scale0_hi, double growth_lo,
                      double growth_hi, double lipschitz, double map_lipschitz, const double* h,
                      std::uint32_t mask, int lanes) noexcept;
// ir::lipschitz_centre per lane, in place on `in` (laid out as for frac_jit_vescape); h out.
void frac_jit_vcentre(double* in, int dims, double* h, std::uint32_t mask, int lanes) noexcept;
// ir::lipschitz_finish per lane: io holds acc lo, acc hi, tail lo, tail hi (lanes each) and gets the
// result's lo, hi; bound, n, h one per lane.
void frac_jit_vfinish(int kind, double* io, const double* bound, const std::int64_t* n, const double* h,
                      double radius, double slope, double offset, double scale0_lo, double scale0_hi,
                      double growth_lo, double growth_hi, double lipschitz, double map_lipschitz,
                      std::uint32_t mask, int lanes) noexcept;
// ir::escape_point_done for the orbit point state[0..dims) (round to nearest): 1 when done.
int frac_jit_escape_point_done(int kind, double acc, const double* state, int dims, std::int64_t n,
                               double radius, double slope, double offset, double scale0_lo, double scale0_hi,
                               double growth_lo, double growth_hi) noexcept;
// Point operations (round to nearest), the C library's functions as the interpreter calls them.
double frac_jit_pow_point(double x, double y) noexcept;
double frac_jit_sin_point(double x) noexcept;
double frac_jit_cos_point(double x) noexcept;
double frac_jit_tan_point(double x) noexcept;
double frac_jit_exp_point(double x) noexcept;
double frac_jit_log_point(double x) noexcept;
double frac_jit_atan2_point(double y, double x) noexcept;
// ir::series_tail(kind, A, B, has_b, gamma, n) (upward rounding active).
frac::jit::CInterval frac_jit_series_tail(int kind, double alo, double ahi, double blo, double bhi, int has_b,
                                          double gamma_lo, double gamma_hi, std::int64_t n) noexcept;
// The end of a series in point evaluation after index n: ir::series_point_end, from the bounds of A
// and B at the point (it sets and restores upward rounding itself).
double frac_jit_point_series_end(int kind, double acc, double comp, double a_lo, double a_hi, double b_lo,
                                 double b_hi, int has_b, double gamma_lo, double gamma_hi,
                                 std::int64_t n) noexcept;
}
