// Differential analysis of barycentric automata (seed 002 sec. 3.2, seed 004 sec. 4): the spectrum of
// each subdivision operator (an arc from a barycentric state to itself), verified, and what it says
// about the curve at the operator's fixed point.
//
// A subdivision operator T of bary(n) has columns summing to 1, so 1^T T = 1^T: 1 is an eigenvalue, its
// eigenvector normalised to sum 1 is the fixed point (an end of the curve, or the junction point of
// seed 004's T^i), and every other eigenvector v has 1^T v = 0 — it lies in the direction space of
// the barycentric hyperplane. The eigenvalues on that hyperplane, by decreasing modulus, decide the
// behaviour near the fixed point: the sub-dominant one λ2 (when |λ2| > |λ3|) positive real gives a
// half-tangent along v2 (G1 possible), negative real an oscillation (no tangent), a complex pair a
// spiral in the plane of its two real eigenvectors.
//
// Every eigenpair is verified by a Krawczyk test on (v, λ) with a normalisation c^T v = 1 (complex
// pairs on their real and imaginary parts): success proves that for every matrix inside the operator's
// interval enclosure there is exactly one eigenpair in the returned boxes, computed with outward
// rounding. When the operator is exact, the characteristic polynomial is computed over the rationals,
// rational eigenvalues are recognised exactly, with their multiplicities and exact eigenvectors
// (which covers the double eigenvalues a Krawczyk test cannot enclose).
#pragma once

#include "ir/automaton.hpp"

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace frac::rt {

struct Eigenpair {
    double re = 0, im = 0;                           // the computed (double) eigenvalue
    num::Interval value_re, value_im;                // verified enclosure (entire when not verified)
    std::vector<num::Interval> vector_re, vector_im; // the eigenvector, normalised (see `verified`)
    bool verified = false;                           // the Krawczyk test succeeded
    std::optional<num::Rational> exact;              // a rational eigenvalue, checked on the exact polynomial
    int multiplicity = 1;                            // algebraic (exact operators), else 1
    int geometric = 1;                               // the dimension of its eigenspace (exact operators)
    std::optional<std::vector<num::Rational>> exact_vector; // eigenvector of an exact eigenvalue
    bool is_complex() const { return !exact && (verified ? value_im.lo > 0 : im != 0); }
    // Enclosure of the modulus (the exact value's when known).
    num::Interval modulus() const;
};

enum class Behaviour {
    tangent,     // λ2 real positive and strictly dominant: half-tangent along v2
    oscillation, // λ2 real negative and strictly dominant: no tangent
    spiral,      // a complex pair strictly dominant
    point,       // no sub-dominant eigenvalue (bary(1)), or every one is 0
    undecided,   // the enclosures do not separate |λ2| from the next modulus, or λ2 may be 0
};
const char* behaviour_name(Behaviour b);

struct OperatorAnalysis {
    std::size_t arc = 0, state = 0;
    std::string label; // the arc's label, or "arc N"
    Eigenpair fixed;   // the eigenvalue 1; vector_re is the fixed point (sum 1)
    std::optional<std::vector<num::Rational>> exact_fixed;
    // The other eigenvalues by decreasing modulus; a complex pair once (positive imaginary part).
    std::vector<Eigenpair> others;
    // The characteristic polynomial det(x I - T), lowest degree first (exact operators).
    std::optional<std::vector<num::Rational>> characteristic;
    // Every eigenvalue enclosed and the enclosures pairwise disjoint: the spectrum is proven simple.
    bool separated = false;
    Behaviour behaviour = Behaviour::undecided;
    std::string reason; // what decided the behaviour, with the numbers
    // Seed 002's C1 condition at a vertex: the eigenvalue whose eigenvector is an edge e_(j+1) - e_j of
    // the control polygon is real, positive and at least the modulus of every other sub-dominant
    // eigenvalue (λ ≥ (1 - μ)/2 for its C1 edge). Unset when no such eigenvector is proven, or when the
    // enclosures do not decide.
    std::optional<std::size_t> edge; // index into `others`
    std::size_t edge_from = 0;       // j
    std::optional<bool> c1_condition;
    num::Interval c1_rival;                      // the largest other modulus (0: none), enclosed
    std::optional<num::Rational> c1_exact_rival; // the same, exactly, when every eigenvalue is exact
    // Seed 004, sec. 4: the arcs from this state to others place copies of their curves, whose control
    // polygons are the arcs' columns; a copy approaches the fixed point along v2 when a column has a
    // non-zero component w2^T p on v2 (w2: the left eigenvector). Analysed for a half-tangent only.
    struct Copy {
        std::size_t arc = 0;
        enum class Along { yes, no, undecided } along = Along::undecided;
    };
    std::vector<Copy> copies;
};

// Two pieces T_i(A) and T_j(A) of a curve meet where T_i x_j = T_j x_i (x_k the fixed point of T_k).
// Their tangents there are T_i v_j and T_j v_i (v_k the sub-dominant eigenvector at x_k): the curve is
// G1 at the meeting point, and at all its images, when those are collinear (seed 002's adjacency
// constraint on half-tangents).
struct JunctionAnalysis {
    std::size_t left = 0, right = 0; // the pieces T_i, T_j (indices into AutomatonAnalysis::operators)
    std::size_t left_end = 0, right_end = 0; // p, q: the meeting point is T_i x_p = T_j x_q
    bool meet_exact = false;                 // T_i x_j == T_j x_i over the rationals
    std::vector<num::Interval> point;        // enclosure of T_i x_j
    enum class Tangents { collinear, not_collinear, undecided, no_tangent } tangents = Tangents::no_tangent;
    std::string reason;
};

struct AutomatonAnalysis {
    std::vector<OperatorAnalysis> operators;
    std::vector<JunctionAnalysis> junctions;
};

// The largest bary(n) whose exact operators also get the exact characteristic polynomial (its
// Faddeev–LeVerrier cost grows as n^4 rational operations on growing numbers); larger ones are
// analysed on their enclosures alone.
inline constexpr std::size_t exact_spectrum_limit = 16;

// Analyses every arc from a barycentric state to itself. Throws std::invalid_argument when the automaton
// has none.
AutomatonAnalysis analyze(const ir::Automaton& a);

// Verifies one eigenpair of the square interval matrix t from the approximation (re + i im, v): the
// Krawczyk test described above; `normalise_sum` uses c = (1, ..., 1) (the fixed point), else the unit
// vector of v's largest entry. Exposed for the soundness tests.
Eigenpair verify_eigenpair(const num::Matrix<num::Interval>& t, double re, double im,
                           const std::vector<double>& v_re, const std::vector<double>& v_im,
                           bool normalise_sum);

// det(x I - t) over the rationals, coefficients lowest degree first (Faddeev–LeVerrier).
std::vector<num::Rational> characteristic_polynomial(const num::Matrix<num::Rational>& t);

} // namespace frac::rt
