#include "backend/llvm/aot_runtime.hpp"

#include "numeric/interval.hpp"

#include <cfenv>
#include <cstring>

#if defined(__x86_64__) || defined(__SSE2__)
#include <xmmintrin.h>
#define FRAC_AOT_HAVE_MXCSR 1
#endif

namespace {

// The floating-point environment of one call: the rounding direction asked for and IEEE subnormals
// (a caller built with -ffast-math may run with flush-to-zero, which would break the enclosures and
// the bit-for-bit agreement with the JIT). The caller's mode comes back on destruction.
class CallEnvironment {
public:
    explicit CallEnvironment(int rounding) : saved_rounding_(std::fegetround()) {
#ifdef FRAC_AOT_HAVE_MXCSR
        saved_csr_ = _mm_getcsr();
        constexpr unsigned flush_to_zero = 1u << 15, denormals_are_zero = 1u << 6;
        _mm_setcsr(saved_csr_ & ~(flush_to_zero | denormals_are_zero));
#endif
        std::fesetround(rounding);
    }
    ~CallEnvironment() {
        std::fesetround(saved_rounding_);
#ifdef FRAC_AOT_HAVE_MXCSR
        _mm_setcsr(saved_csr_);
#endif
    }
    CallEnvironment(const CallEnvironment&) = delete;
    CallEnvironment& operator=(const CallEnvironment&) = delete;

private:
    int saved_rounding_;
#ifdef FRAC_AOT_HAVE_MXCSR
    unsigned saved_csr_ = 0;
#endif
};

bool has_empty(const double* box, std::int64_t dims) {
    for (std::int64_t k = 0; k < dims; ++k)
        if (!(box[2 * k] <= box[2 * k + 1])) return true;
    return false;
}

} // namespace

extern "C" {

void frac_aot_eval_boxes(frac_aot_batch fn, std::int64_t dims, const double* boxes, std::int64_t n,
                         double* out) noexcept {
    CallEnvironment env(FE_UPWARD);
    std::uint64_t stats[3] = {0, 0, 0}; // ir::EvalStats; per call, so concurrent calls share nothing
    // The generated code assumes non-empty coordinates, as in the JIT (jit.cpp): runs of boxes
    // without empty coordinates go to it, the others get the empty image.
    std::int64_t i = 0;
    while (i < n) {
        std::int64_t j = i;
        while (j < n && !has_empty(boxes + 2 * dims * j, dims)) ++j;
        if (j > i) fn(boxes + 2 * dims * i, j - i, out + 2 * i, stats);
        if (j < n) {
            out[2 * j] = frac::num::Interval::empty().lo;
            out[2 * j + 1] = frac::num::Interval::empty().hi;
            ++j;
        }
        i = j;
    }
}

void frac_aot_eval_points(frac_aot_batch fn, const double* points, std::int64_t n, double* out) noexcept {
    if (n <= 0) return;
    CallEnvironment env(FE_TONEAREST);
    std::uint64_t stats[3] = {0, 0, 0};
    fn(points, n, out, stats);
}

} // extern "C"
