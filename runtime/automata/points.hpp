// Points of attractors that every evaluation needs: the point at address 0^infinity of a state (the
// fixed point of the cycle reached by always taking a state's first arc), and the map from the
// initial state's space to the picture's euclidean coordinates (through the projection when the
// initial state is barycentric).
#pragma once

#include "ir/automaton.hpp"

#include <cstddef>
#include <optional>
#include <vector>

namespace frac::rt {

// Throws std::invalid_argument unless the initial state exists and every arc connects existing
// states with an operator of their sizes (what evaluation needs; ir::check_automaton says more).
void require_well_formed(const ir::Automaton& a);

// The homogeneous column (in the space of `state`) of phi(0^infinity): follow the first arc of each
// state until a state repeats, take the fixed point of the cycle's composite operator (exactly when
// its operators are exact) and map it back along the path. Throws std::invalid_argument when a state
// on the way has no arc, or when the cycle's operator has no unique fixed point (it does not contract).
std::vector<double> attractor_point(const ir::Automaton& a, std::size_t state);

// The homogeneous column (in the space of the first arc's source state) of the point at the
// eventually periodic address path[0] ... path[k - 1] (path[k] ... path[n - 1])^infinity, k =
// cycle_start < n: the fixed point of the cycle's composite mapped back along the prefix. Exact (then
// rounded) when every operator on the path is exact. nullopt when the cycle has no unique fixed point.
std::optional<std::vector<double>>
periodic_point(const ir::Automaton& a, const std::vector<std::size_t>& path, std::size_t cycle_start);
// The same point in exact rationals; nullopt also when an operator on the path is not exact.
std::optional<num::Matrix<num::Rational>>
exact_periodic_point(const ir::Automaton& a, const std::vector<std::size_t>& path, std::size_t cycle_start);

// Homogeneous column of the initial state's space -> euclidean coordinates of the output space
// (Automaton::output_dimension() of them), through the projection when there is one.
std::vector<double> output_point(const ir::Automaton& a, const std::vector<double>& column);

// The projection as a double matrix (output coordinates + 1) x (initial coordinates): the
// projection's nearest doubles, or the identity of the initial space when there is none.
num::Matrix<double> output_matrix(const ir::Automaton& a);

} // namespace frac::rt
