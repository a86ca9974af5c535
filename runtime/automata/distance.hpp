// Distance from a point or a box to the attractor of an automaton (seed 000, sec. 2.3): branch and
// bound over the evaluation tree with proven bounding balls.
//
// A node of the tree is a path e1..ek from the initial state to a state b; it stands for the set
// M(A_b), M = P T_e1 ... T_ek (P the projection, or the identity). With a ball B(c_b, r_b) that holds
// A_b, M(A_b) lies in the ball B(M c_b, lip(M) r_b), which gives a lower bound of the distance to the
// node's part of the attractor; a point known to lie near A_b (a witness) mapped by M gives an upper
// bound of the distance to the attractor. Nodes are expanded best first (least lower bound), and a
// node whose lower bound exceeds the best upper bound is pruned: the paper's greedy upper bound and
// pruning, with outward rounding everywhere, so [lower, upper] is proven.
//
// Norms: the euclidean norm of the output space R^d; in a state's space the euclidean norm of its
// coordinates (R^d: x; bary(n): the n weights). An operator's Lipschitz bound is the spectral norm of
// its linear part restricted to differences of points (last coordinate 0 for R^d, weights summing
// to 0 for bary(n)), bounded from above with a verified (interval Cholesky) certificate.
#pragma once

#include "ir/automaton.hpp"
#include "numeric/interval.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace frac::rt {

using num::Interval;

// A ball in a state's space holding its attractor, and a point near the attractor.
struct StateBall {
    std::vector<double> centre; // homogeneous coordinates (exactly on the space's hyperplane w = 1)
    double radius = 0;          // A_s lies in B(centre, radius), proven
    // Some point of A_s lies within witness_radius of some point of the box `witness` (an interval
    // enclosure of one point on the hyperplane), proven.
    std::vector<Interval> witness;
    double witness_radius = 0;
};

// Proven bounding balls for every state (empty balls, radius -1, for states with an empty
// attractor: no path from them reaches a cycle). Throws std::invalid_argument when the operators
// are not affine, or when no bounding balls are found (the system does not contract in these norms).
std::vector<StateBall> bounding_balls(const ir::Automaton& a);

// Upper bound of the spectral norm of every real matrix inside `m` (rows x cols, row-major), proven:
// a power-iteration estimate certified by an interval Cholesky factorisation of mu I - m^T m, or the
// Frobenius norm when that fails.
double spectral_norm_upper(const std::vector<Interval>& m, std::size_t rows, std::size_t cols);

struct DistanceOptions {
    double epsilon = 1e-6;            // stop when upper - lower <= epsilon (for a box: see eval_box)
    std::uint64_t max_nodes = 200000; // nodes expanded per query; the result stays proven, only wider
    // For a box of diagonal D the lower end is refined to max(epsilon, box_tolerance * D) only: the
    // upper end exceeds the minimum by up to D anyway (subdivision narrows boxes instead).
    double box_tolerance = 0.125;
};

struct DistanceResult {
    Interval distance;        // [lower, upper]
    std::uint64_t nodes = 0;  // nodes expanded
    std::uint64_t pruned = 0; // children dropped by the bound
    bool converged = false;   // epsilon reached (false: the node budget stopped it)
};

// Eq. (2) brute force: the level-k images of the balls' centres; the distance to the attractor lies
// within `error` of `estimate` (error = the largest leaf radius). Round-to-nearest, not proven.
struct BruteForceResult {
    double estimate = 0;
    double error = 0;
    std::uint64_t leaves = 0;
};

// Immutable after construction: every query is const and may run on any thread. Construction is in
// distance.cpp; the queries and serialization (distance_query.cpp) need only the numeric core, so
// compiled models link them alone (libfrac_aot_automata.a).
class AttractorDistance {
public:
    // Throws std::invalid_argument as bounding_balls does, when the initial state's attractor is
    // empty, or for a bad epsilon / node budget.
    AttractorDistance(const ir::Automaton& a, DistanceOptions options = {});

    // Dimension of the points and boxes (the automaton's output dimension).
    int dimension() const { return dim_; }
    const DistanceOptions& options() const { return options_; }
    const std::vector<StateBall>& balls() const { return balls_; }

    // A box of the output space holding the attractor (around its proven bounding ball), outward:
    // a default box for pictures and covers.
    std::vector<Interval> bounding_box() const;

    // An interval containing d(p, A).
    Interval eval_point(const double* p) const;
    // An interval containing d(p, A) for every p in the box (lower <= min, upper >= max). Refines
    // until the lower bound of the minimum is within epsilon (see box_tolerance) of an upper bound of
    // the minimum; the upper end is the best witness bound of the maximum (at least the variation of
    // d over the box).
    Interval eval_box(const Interval* box) const;
    // The same, with counters.
    DistanceResult query(const Interval* box) const;

    // Eq. (2): all paths of `level` arcs from the initial state.
    BruteForceResult brute_force(const double* p, int level) const;
    // The k of eq. (2): the least level whose leaf radii are all <= epsilon (R rho^k <= epsilon with
    // rho the largest arc Lipschitz bound); -1 when rho >= 1.
    int brute_force_level(double epsilon) const;

    // What the queries read, as bytes in this host's byte order (compiled models carry it: frac
    // compile), and back. deserialize throws std::invalid_argument when `data` is not what serialize
    // wrote.
    std::vector<std::uint8_t> serialize() const;
    static AttractorDistance deserialize(const std::uint8_t* data, std::size_t size);

private:
    AttractorDistance() = default;

    struct ArcData {
        std::size_t to = 0;
        std::vector<Interval> op; // rows(from) x cols(to), row-major
        double lip = 0;           // proven Lipschitz bound
        std::vector<double> nearest;
    };
    struct StateData {
        std::size_t coords = 0;
        bool bary = false;
        std::vector<std::size_t> arcs; // indices into arcs_ (live arcs only)
    };

    int dim_ = 2;
    DistanceOptions options_;
    std::vector<StateBall> balls_;
    std::vector<StateData> states_;
    std::vector<ArcData> arcs_;
    std::size_t initial_ = 0;
    std::vector<Interval> root_; // d x coords(initial): the output rows of P (or [I 0])
    double root_lip_ = 1;
};

} // namespace frac::rt
