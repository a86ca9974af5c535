// Address maps and tabulation of projected attractors (seed 003 sec. 2.2-2.4).
//
// With N arcs per state, a word sigma_1 sigma_2 ... picks at each state its sigma-th arc (model
// order) and addresses the point phi(sigma) = lim T_sigma1 ... T_sigman x. A curve is parameterised
// by s = sum sigma_i / N^i; at s = i / N^p the expansion ends in 0^infinity, so
//   F(i / N^p) = P T_sigma1 ... T_sigmap phi_q(0^infinity),
// q the state reached after p arcs and phi_q(0^infinity) its attractor point (the fixed point of the
// cycle of first arcs, runtime/automata/points.hpp): p compositions per value, no limit taken.
// Surfaces use N^2 arcs per state indexed (sigma, tau) -> sigma * N + tau and s, t in base N.
#pragma once

#include "ir/automaton.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace frac::rt {

// The p base-N digits of i (most significant first), i < N^p.
std::vector<std::size_t> address_digits(std::uint64_t i, std::size_t base, int p);

// phi at the address digits followed by 0^infinity, in output coordinates (through the projection).
// Throws std::invalid_argument when a digit has no arc at the state it is read in.
std::vector<double> address_point(const ir::Automaton& a, const std::vector<std::size_t>& digits);

struct Tabulation {
    std::size_t base = 0; // N
    int p = 0;
    int dimension = 0; // output coordinates per value
    // Curves: N^p values F(i / N^p), i = 0 .. N^p - 1. Surfaces: N^p x N^p values, index i * N^p + j
    // for F(i / N^p, j / N^p). Each value has `dimension` coordinates.
    std::vector<std::vector<double>> values;
};

// Every state reachable from the initial state must have the same number N of arcs (curves) or
// N^2 (surfaces); std::invalid_argument names the state that does not. p in [0, 24], and N^p (N^2p
// for surfaces) at most 2^26 values.
Tabulation tabulate(const ir::Automaton& a, int p);
Tabulation tabulate_surface(const ir::Automaton& a, int p);

} // namespace frac::rt
