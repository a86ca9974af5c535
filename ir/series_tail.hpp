// The tail of an infinite series after its terms up to index n, from the proven term bound
// t_i in (A + B i) gamma^i (frontend/series_bounds). Every engine encloses tails with this one
// definition. Requires upward rounding.
#pragma once

#include "ir/graph.hpp"

namespace frac::ir {

// Enclosure of the tail: for a sum, of sum_{i>n} t_i; for a min (max), of inf (sup) over i>n of t_i,
// which is <= 0 (>= 0) because the terms tend to 0. `has_b` is false when B is absent (zero).
Interval series_tail(Op kind, Interval a, Interval b, bool has_b, Interval gamma, std::int64_t n);

// Enclosure of the bound of the single term i: (A + B i) gamma^i, with gamma_i = gamma^i given.
Interval series_term_bound(Interval a, Interval b, bool has_b, Interval gamma_i, std::int64_t i);

// Combines a partial result with one more term (or with a tail).
Interval series_combine(Op kind, Interval acc, Interval term);
double series_combine_point(Op kind, double acc, double term);

} // namespace frac::ir
