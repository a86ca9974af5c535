// Similarity dimensions of automata whose maps are similitudes.
//
// IFS (one state): Moran's equation sum r_i^s = 1. Graph-directed CIFS (Mauldin–Williams): the s where
// the spectral radius of M(s), M(s)[a][b] = sum over the arcs a -> b of r^s, equals 1. Only the
// strongly connected components reachable from the initial state have cycles; the dimension is the
// largest of their roots, and the arcs on no cycle (a projection onto control points, the first arc
// of the fern to its Sierpinski state) leave it unchanged when they are injective. This is the
// similarity dimension; it equals the Hausdorff dimension under the open set condition, which is not
// checked. Maps that are not similitudes get a clear refusal; box counting of a cover is the fallback.
#pragma once

#include "ir/automaton.hpp"
#include "numeric/interval.hpp"

#include <cstddef>
#include <string>
#include <vector>

namespace frac::rt {

// The ratio of an arc's map: r with |T x - T y| = r |x - y| on the direction spaces (R^d with its
// euclidean metric; bary(n) with the metric of R^n restricted to {sum v = 0}).
struct SimilarityRatio {
    bool similitude = false;
    bool exact = false; // decided on the exact matrix (else: consistent with its enclosure)
    num::Interval ratio{0.0, 0.0};
    std::string reason; // why not, when not
};

// Exact when the operator is exact: L^T G_from L = r^2 G_to with G the Gram matrix of the direction
// coordinates. Otherwise by enclosure: the map is taken as a similitude when some r^2 is consistent
// with every entry (the true matrix may differ within its enclosure).
SimilarityRatio similarity_ratio(const ir::Automaton& a, std::size_t arc);

struct SimilarityDimension {
    bool defined = false; // false: some map on a cycle is not a similitude (see reason)
    std::string reason;
    double value = 0;                    // the midpoint of the bracket
    num::Interval bracket{0.0, 0.0};     // proven: rho(M(lo)) > 1 > rho(M(hi)) (or [0, 0] for single cycles)
    std::vector<SimilarityRatio> ratios; // per arc (ratio of the arcs between reachable states)
    std::string method;                  // "Moran equation" or "Mauldin–Williams spectral radius"
};

// Bisection on s with the spectral radius of M(s) bracketed by Collatz–Wielandt quotients under
// outward rounding, until the bracket is narrower than `tolerance` or the arithmetic cannot decide.
// Throws std::invalid_argument on a structurally invalid automaton (run ir::check_automaton first).
SimilarityDimension similarity_dimension(const ir::Automaton& a, double tolerance = 1e-13);

// The box dimension of the graph of a fractal interpolation function (a `fif` over R2, frontend/fif.hpp)
// from its shears (t, x) -> (a t + d, b t + c x + e): Barnsley's theorem for a FIF (sum |c_i| a_i^(D-1)
// = 1) and its recurrent form for an RFIF (Barnsley, Elton, Hardin: the spectral radius of M(D),
// M(D)[i][m] = |c_i| a_i^(D-1) when the domain of piece i covers range m, equals 1). D = 1 when the
// interpolation points are collinear or when rho(M(1)) <= 1. The bracket is proven as for similarity
// dimensions (outward-rounded Collatz-Wielandt bounds). Curves (eq. 8/9) get defined = false: their
// dimension is found by box counting.
SimilarityDimension fif_box_dimension(const ir::Automaton& a, const std::vector<std::vector<double>>& points,
                                      double tolerance = 1e-13);

} // namespace frac::rt
