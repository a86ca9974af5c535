// Directed-rounding helpers shared by the construction of attractor distances (distance.cpp) and
// their queries (distance_query.cpp, which compiled models link on their own). Private to
// runtime/automata.
#pragma once

#include "numeric/interval.hpp"

#include <vector>

namespace frac::rt::bounds {

using num::Interval;

// All arithmetic below runs under upward rounding (callers hold num::UpwardRounding); lower bounds come
// from the interval operations' lo, which they round downward by negation.
inline double up_mul(double a, double b) {
    return num::mul(Interval(a), Interval(b)).hi;
}
inline double up_add(double a, double b) {
    return num::add(Interval(a), Interval(b)).hi;
}
inline double down_sub(double a, double b) {
    return num::sub(Interval(a), Interval(b)).lo;
}

// An upper bound of the Frobenius norm of every matrix inside `m` (hence of its spectral norm).
inline double frobenius_upper(const std::vector<Interval>& m) {
    Interval s(0.0);
    for (const Interval& v : m) s = num::add(s, num::sqr(v));
    return num::sqrt(s).hi;
}

} // namespace frac::rt::bounds
