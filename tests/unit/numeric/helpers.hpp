// Shared helpers for the numeric-core unit tests.
#pragma once

#include "numeric/interval.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <ostream>

namespace frac::num {
// Lets Catch print intervals in failure messages, in hex so that every bit shows.
inline std::ostream& operator<<(std::ostream& os, Interval a) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "[%a, %a]", a.lo, a.hi);
    return os << buf;
}
} // namespace frac::num

namespace frac::num::test {

inline double up(double x) {
    return std::nextafter(x, inf);
}
inline double down(double x) {
    return std::nextafter(x, -inf);
}

// Whether a contains the real v given in extended precision; long double carries 11 more bits than
// double, which suffices for the well-separated reference values used here.
inline bool encloses(Interval a, long double v) {
    return a.lo <= v && v <= a.hi;
}

// A non-thin enclosure of v at most `ulps` doubles wide.
inline bool tight(Interval a, long double v, int ulps = 2) {
    if (!encloses(a, v) || a.is_thin()) return false;
    double hi = a.lo;
    for (int i = 0; i < ulps; ++i) hi = up(hi);
    return a.hi <= hi;
}

} // namespace frac::num::test

// What every numeric test file uses.
#include <limits>
namespace num = frac::num;
using frac::num::test::down;
using frac::num::test::encloses;
using frac::num::test::tight;
using frac::num::test::up;
using num::inf;
using num::Interval;
using num::UpwardRounding;

namespace {
constexpr double dmax = std::numeric_limits<double>::max();
const Interval E = Interval::empty();
const Interval R = Interval::entire();
} // namespace
