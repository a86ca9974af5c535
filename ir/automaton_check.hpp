// Compile-time checks of an automaton (ir/automaton.hpp), each a structured problem naming the state
// or arc it is about, so the frontend can point at the declaration:
//   - structure: arc ends, the initial state and the projection refer to existing states/sizes;
//   - sizes: an arc a -> b carries a coordinates(a) x coordinates(b) matrix;
//   - affine condition w_a^T T = w_b^T (barycentric columns sum to 1), exactly when the operator is
//     exact, by enclosure otherwise;
//   - probabilities: finite and non-negative, given for every arc of a state or for none;
//   - states without transitions (their attractor would be empty) are errors, states unreachable from
//     the initial state warnings;
//   - contractivity: a proof that the system has a unique attractor (see prove_contractive).
#pragma once

#include "ir/automaton.hpp"

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace frac::ir {

struct AutomatonProblem {
    enum class Severity { error, warning } severity = Severity::error;
    enum class Kind { structure, size, affine, probability, dead_end, unreachable, contractivity } kind{};
    std::optional<std::size_t> state; // the state the problem is about, when one is
    std::optional<std::size_t> arc;   // the arc, when one is
    std::string message;
};

struct ContractivityOptions {
    int max_length = 12;               // longest paths tried
    std::size_t max_products = 400000; // matrix products over all lengths tried
    // The same budget in arithmetic: products times d^3 for the largest direction dimension d, so
    // that systems of bary(16) spaces stop at shorter paths than plane IFS (a refusal stays quick).
    double max_work = 5e7;
};

// How contraction was proven, or why not.
//
// Method: each state's space gets the euclidean norm of its direction coordinates (R^d: the first d
// coordinates; bary(n): the first n - 1 weights, the basis e_i - e_n of {sum v = 0}). For paths of
// length L, M_L[a][b] is an outward-rounded upper bound of the Lipschitz constant of the composite
// linear part, maximised over the paths a -> ... -> b of length L (2-norm bounded by Gershgorin on
// P^T P, or the Frobenius norm). When the spectral radius of M_L is < 1 (bounded above by the
// Collatz–Wielandt quotient of a positive vector, per strongly connected component) the L-th power
// of the Hutchinson operator contracts a weighted sup of Hausdorff distances, so the system has a
// unique attractor. L = 1 is the classical spectral radius of the matrix of Lipschitz bounds; longer
// L handle maps whose single-step norm exceeds 1 (B-spline subdivision matrices).
struct ContractivityResult {
    bool proven = false;
    double bound = 0;    // proven: rho(M_L) <= bound < 1
    double per_step = 0; // bound^(1/L): the contraction per transition
    int length = 0;      // L
    std::string method;  // one line: what was bounded and how
    // When not proven: the cycle (arcs, in path order) with the slowest contraction found, and its
    // estimated spectral radius per step (>= 1: it does not contract at all).
    std::vector<std::size_t> cycle;
    double cycle_rate = 0;
    std::string message; // the proof (bound, length) or the refusal naming the cycle
    double work = 0;     // what it spent of ContractivityOptions::max_work
};

// Needs a structurally valid automaton whose arcs pass the size and affine checks (as check_automaton
// ensures before calling it); throws std::invalid_argument otherwise. Only arcs between states
// reachable from the initial state count.
ContractivityResult prove_contractive(const Automaton& a, const ContractivityOptions& options = {});

// All checks; the contractivity proof runs when nothing else is an error, and is stored in *proof
// when given.
std::vector<AutomatonProblem> check_automaton(const Automaton& a, const ContractivityOptions& options = {},
                                              ContractivityResult* proof = nullptr);

// ---- Helpers shared with the runtime (dimension, tree, chaos game). ----

// The arc's label, or "#k" for arc k when it has none.
std::string arc_name(const Automaton& a, std::size_t arc);
// "a -T1-> a -T0-> b": the states along the arcs (which must form a path).
std::string path_text(const Automaton& a, const std::vector<std::size_t>& arcs);
// A basis of the direction space {v : w^T v = 0} as columns (coordinates x dimension), and the left
// inverse mapping a direction vector to its coordinates in that basis (dimension x coordinates).
num::Matrix<num::Rational> direction_basis(Space s);
num::Matrix<num::Rational> direction_coordinates(Space s);
// The linear part of an arc's operator in those coordinates: dimension(from) x dimension(to).
num::Matrix<num::Interval> linear_part(const Automaton& a, std::size_t arc);
std::optional<num::Matrix<num::Rational>> exact_linear_part(const Automaton& a, std::size_t arc);
// The states reachable from the initial state (following arcs from -> to).
std::vector<bool> reachable_states(const Automaton& a);
// Strongly connected components over the arcs between states where `keep` holds (all when empty):
// component index per state (-1 where not kept); components are numbered in reverse topological order.
std::vector<int> strongly_connected_components(const Automaton& a, const std::vector<bool>& keep,
                                               int* count = nullptr);
// Bracket of the spectral radius of a non-negative interval matrix (entries >= 0): the
// Collatz–Wielandt quotients min (Mx)_i / x_i and max (Mx)_i / x_i of an approximate Perron vector
// x > 0, outward rounded. The upper end is always valid; the lower end is tight for irreducible M.
num::Interval spectral_radius_bracket(const num::Matrix<num::Interval>& m);
// Upper bound of the spectral 2-norm of an interval matrix (needs no particular rounding mode).
double norm2_upper(const num::Matrix<num::Interval>& m);

} // namespace frac::ir
