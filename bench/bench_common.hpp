// Pieces the benchmark programs share: wall-clock timing and a compiled shape.
#pragma once

#include "ir/tape.hpp"

#include <chrono>
#include <string>
#include <vector>

namespace frac::bench {

using Clock = std::chrono::steady_clock;
inline double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

// A shape of a compiled model: its tape and default box.
struct Shape {
    std::string name;
    int dimension;
    std::vector<ir::Interval> box;
    ir::Tape tape;
};

} // namespace frac::bench
