// Limits on the work and memory of the runtime's computations (cells of a subdivision, triangles of a
// mesh): a computation that would pass one stops with a LimitError, before the memory is spent. Values
// past the range of doubles stop with a RangeError.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace frac::rt {

struct LimitError : std::runtime_error {
    LimitError(const std::string& message, double estimate, std::uint64_t limit)
        : std::runtime_error(message), estimate(estimate), limit(limit) {}
    double estimate;     // of the quantity the whole computation would reach
    std::uint64_t limit; // the limit it passes
};

// A computation whose values leave the range of doubles (an attractor beyond 1e308): a fault of the
// model, not of frac. An std::invalid_argument, so callers that take those as the user's still do.
struct RangeError : std::invalid_argument {
    using std::invalid_argument::invalid_argument;
};

} // namespace frac::rt
