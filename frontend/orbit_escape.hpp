// Escape certificates of orbit series (`p in orbit(p0, M) escape R`). The compiler proves, from the
// map's and the term's expressions, that an orbit leaving the ball |q| <= R never returns and that the
// later terms stay above a bound (below, for a max series) it can evaluate from the current orbit box.
//
// The proof, for an infinite min series whose term is t_k = D(q_k) * S(k):
//   1. |M(q)| >= a |q| - b for every q (Euclidean norm), by an abstract interpretation of M:
//      M(q) = diag(l) u(q) + c with constants l, c and |u(q)| >= alpha |q| + beta, where u is
//      recognised as a norm-preserving re-assembly of q (polar coordinates put back together,
//      (R cos f, R sin f) with R = |q|; or a signed permutation of the coordinates, abs included);
//   2. S(k) = scale0 / growth^k with growth >= 1 from powers c^(e0 + e1 k) of positive constants;
//   3. D(q) >= slope |q| + d0 for every q, slope >= 0, by the same affine-in-|q| interpretation;
//   4. a >= growth, a > 1 and (a - 1) R >= b.
// Then |q_j| - R >= a^(j-m) (|q_m| - R) for j >= m, and every term t_j (j >= m) is at least
// (slope (|q_m| - R) + min(0, slope R + d0)) * S(m) > 0 once |q_m| > R, so the tail of the min is
// bounded below by that value (ir/series_tail: escape_bound). A max series is the same with -t_k.
// Every step is a theorem applied to interval constants rounded outward, so an accepted certificate
// is sound; one that cannot be proven is a compile error saying which step failed.
#pragma once

#include "ir/graph.hpp"

#include <optional>
#include <string>
#include <vector>

namespace frac::front {

// `term`: the series body; `map`: the map's components (of State(level, c) nodes); `radius`: the
// claimed escape radius (a constant). Requires upward rounding. On failure returns nullopt and sets
// `why` to a sentence.
std::optional<ir::OrbitEscape> prove_orbit_escape(ir::Graph& g, ir::NodeId term,
                                                  const std::vector<ir::NodeId>& map, int level, ir::Op kind,
                                                  ir::Interval radius, std::string& why);

} // namespace frac::front
