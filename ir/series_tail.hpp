// The tail of an infinite series after its terms up to index n, from the proven term bound
// t_i in (A + B i) gamma^i (frontend/series_bounds). Every engine encloses tails with this one
// definition. Requires upward rounding.
#pragma once

#include "ir/graph.hpp"

#include <string>

namespace frac::ir {

// The stopping rules' constants, for every engine (interpreter, JIT point and box code):
//  - a box series stops when a term is no narrower than `term_resolution` of its static bound (the box
//    is too wide for later terms to resolve anything);
//  - a box series stops when the tail's width is below `box_stop_ratio` of the partial result;
//  - a point series stops when a bound of the tail is below `point_stop_ratio` of the partial result
//    (a quarter of an ulp: later terms cannot change the rounded sum);
//  - an escape bound that gets worse by more than `escape_stall_slack` of the previous one stalls.
inline constexpr double term_resolution = 0.75;
inline constexpr double box_stop_ratio = 0x1p-52;
inline constexpr double point_stop_ratio = 0x1p-54;
inline constexpr double escape_stall_slack = 0x1p-30;

// Enclosure of the tail: for a sum, of sum_{i>n} t_i; for a min (max), of inf (sup) over i>n of t_i,
// which is <= 0 (>= 0) because the terms tend to 0. `has_b` is false when B is absent (zero).
Interval series_tail(Op kind, Interval a, Interval b, bool has_b, Interval gamma, std::int64_t n);

// Enclosure of the bound of the single term i: (A + B i) gamma^i, with gamma_i = gamma^i given.
Interval series_term_bound(Interval a, Interval b, bool has_b, Interval gamma_i, std::int64_t i);

// Escape certificates of orbit series (ir::OrbitEscape). `escape_bound` is the bound of every term
// after index n - 1 given the orbit point q_n (`state`, `dims` components, as a box): a lower bound for
// a min series, an upper bound for a max series; -inf (+inf) when the box does not lie outside the
// escape ball. `escape_tighten` intersects a tail enclosure with it; every engine uses these two.
double escape_bound(Op kind, const OrbitEscape& e, const Interval* state, int dims, std::int64_t n);
Interval escape_tighten(Op kind, Interval tail, double bound);

// Lipschitz enclosures (OrbitEscape::lipschitz > 0). `lipschitz_centre` replaces the initial point's
// box by its centre (thin) and returns the radius h of the box around it (rounded up); with an
// unbounded or empty component it leaves the box and returns 0. The series then runs on the centre;
// `escape_bound_around` is escape_bound for every orbit point within map_lipschitz^n h of `state`,
// and `lipschitz_finish` turns the centre's partial result `acc` (terms up to index n) and its tail
// bounds into an enclosure over the whole box. With h = 0 both reduce to the plain forms.
double lipschitz_centre(Interval* init, int dims);
// A stopping rule of series with an escape certificate: stop when the bound from the orbit box, `now`,
// reaches the partial result's bound or gets worse than the previous one (`prev`): from there on the
// orbit box only widens (the wrapping of boxes through rotations) and later terms lose more than they
// add.
bool escape_stalls(Op kind, double now, double prev, Interval acc);
double escape_bound_around(Op kind, const OrbitEscape& e, const Interval* state, int dims, std::int64_t n,
                           double h);
Interval lipschitz_finish(Op kind, const OrbitEscape& e, Interval acc, Interval tail, double bound,
                          std::int64_t n, double h);
// Point evaluation (round to nearest, no enclosure): true when the terms after index n - 1, bounded by
// the certificate from the orbit point q_n, cannot move the partial result `acc` by more than its
// last bit; the point value is then `acc`.
bool escape_point_done(Op kind, const OrbitEscape& e, double acc, const double* state, int dims,
                       std::int64_t n);

// Point evaluation of a series (round to nearest). A sum is accumulated with Neumaier's compensated
// summation (`compensated_add`: `acc` plus the rounding error `comp` it lost), so that its value is
// within about an ulp of the exact sum however many terms it takes; an enclosure of the same point is
// that tight too, and a point value off by several ulps would lie outside it. `point_magnitude` is
// max(|lo|, |hi|) of the bounds of A or B at the point (TapeSeries::point_tail), +inf when one is NaN
// or missing. `series_point_end` is the value after the terms up to index n: acc + comp plus the
// midpoint of the tail's enclosure, or without it when the tail is unbounded.
void compensated_add(double& acc, double& comp, double term);
double point_magnitude(double lo, double hi);
double series_point_end(Op kind, double acc, double comp, double a_lo, double a_hi, double b_lo, double b_hi,
                        bool has_b, Interval gamma, std::int64_t n);

// Combines a partial result with one more term (or with a tail).
Interval series_combine(Op kind, Interval acc, Interval term);
double series_combine_point(Op kind, double acc, double term);

} // namespace frac::ir
