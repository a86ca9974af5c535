// The run-time support of AOT-compiled models (docs/c-abi.md): the exported C wrappers that
// `frac compile` generates (backend/llvm/aot.cpp) call these with the address of a shape's generated
// batch function (codegen.hpp). They set the floating-point environment the generated code needs and
// restore the caller's. Built into libfrac_aot_runtime.a with the numeric core and the helpers
// (helpers.hpp); no LLVM here.
#pragma once

#include <cstdint>

extern "C" {

// A generated batch function: <name>_box or <name>_point (codegen.hpp).
using frac_aot_batch = void (*)(const double* in, std::int64_t n, double* out, std::uint64_t* stats);

// n boxes of `dims` intervals (lo, hi) -> n intervals. Sets upward rounding (and clears flush-to-zero
// and denormals-are-zero on x86) for the call and restores the caller's control word. A box with an
// empty coordinate (lo > hi or NaN) has an empty image: its result is the empty interval {+inf, -inf}.
void frac_aot_eval_boxes(frac_aot_batch fn, std::int64_t dims, const double* boxes, std::int64_t n,
                         double* out) noexcept;

// n points of `dims` coordinates -> n values, in round to nearest (set and restored like the above).
void frac_aot_eval_points(frac_aot_batch fn, const double* points, std::int64_t n, double* out) noexcept;
}
