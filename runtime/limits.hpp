// Limits on the work and memory of the runtime's computations (cells of a subdivision, triangles of a
// mesh): a computation that would pass one stops with a LimitError, before the memory is spent.
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

} // namespace frac::rt
