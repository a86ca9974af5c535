// Fractal interpolation functions and curves (seed 001 sec. 2): a `fif` declaration (ast.hpp FifDecl)
// expanded after parsing into the states and arcs of a cifs, so everything an automaton does (render,
// tree, chaos, tabulation, dimension, mesh as a curve) works on it.
//
// Piece i (1..N) is the shear of eq. 1 (eq. 8/9 for a curve (t, x, y)) that maps the graph over its
// domain [t_j, t_k] onto the graph over [t_(i-1), t_i]: T_i(P_j) = P_(i-1), T_i(P_k) = P_i. Its entries
// are written as expressions of the points and the scaling, so exact points give exact operators:
//   a = (t_i - t_(i-1)) / (t_k - t_j),  d = t_(i-1) - a t_j,
//   b = (X_i - X_(i-1) - C (X_k - X_j)) / (t_k - t_j),  e = X_(i-1) - C X_j - b t_j,
// with X the value (x, or (x, y) for a curve) and C the vertical scaling (c, diag(cx, cy) for eq. 8, a
// 2 x 2 matrix for eq. 9). Every domain (0, N) (the default): one state, a FIF. Other domains: an RFIF,
// a state per range r_i whose arcs lead to the ranges its domain covers, and an initial state that is
// their union. A fif of `piece [alpha, beta] MATRIX` statements is a PFIF (sec. 2.3): the graph over an
// interval is the union of the pieces' maps of the graphs over the preimages of its parts in their
// ranges, so the states are the intervals generated from the whole one, exactly in rationals, until none
// is new (at most max_fif_pieces: a PFIF whose domain ends do not close up is no finite automaton).
// Contraction is proven by the metric of eq. 2 when lowering (lower.cpp).
#pragma once

#include "frontend/ast.hpp"
#include "frontend/diagnostics.hpp"

#include <filesystem>

namespace frac::front {

// Most pieces a fif may have (points from a data file included; 10,000 pieces compile in about 1.5 s
// and 290 MB), and most arcs (an RFIF has one per range a domain covers).
inline constexpr std::size_t max_fif_pieces = 10000;
inline constexpr std::size_t max_fif_arcs = 100000;

// Fills `it.automaton`'s states and arcs from its FifDecl, reading a `data` file relative to `dir`.
// Reports what is wrong (located) and leaves the automaton without arcs then.
void expand_fif(Item& it, const std::filesystem::path& dir, std::size_t max_file_bytes, Diagnostics& d);

} // namespace frac::front
