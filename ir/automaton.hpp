// The automaton IR: IFS, controlled (graph-directed) IFS, and later BCIFS, as states and arcs.
//
// Every space is written in homogeneous coordinates, so every operator is one matrix:
//   - euclidean R^d: a point x is the column (x, 1) of d + 1 entries;
//   - barycentric bary(n): a point is a column of n weights summing to 1.
// Each space has an affine functional w (the last unit vector for R^d, all ones for bary(n)) with
// w^T p = 1 on its points. An arc a -> b carries an operator T from the space of b into the space of
// a (as in the papers: A_a = union over arcs a -> b of T(A_b)); T is affine exactly when
// w_a^T T = w_b^T, which covers homogeneous affine maps of R^d (last row 0 ... 0 1), barycentric
// matrices (columns sum to 1) and projections by control points (bary(n) -> R^d: the columns are the
// control points with a 1 appended) alike. A composite operator along a path is the product of the
// arcs' matrices; the attractor of the initial state is drawn through `projection` when that state
// is barycentric.
//
// Operators keep an exact rational matrix when every entry was written exactly (checks and
// similarity dimensions use it), an outward enclosure (distances and covers use it) and the
// nearest doubles (the chaos game and pictures use them).
#pragma once

#include "numeric/interval.hpp"
#include "numeric/matrix.hpp"
#include "numeric/rational.hpp"

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace frac::ir {

struct Space {
    enum class Kind { euclidean, barycentric } kind = Kind::euclidean;
    int dimension = 2; // R^d: d; bary(n): n - 1 (the dimension of its hyperplane)

    static Space euclidean(int d) { return {Kind::euclidean, d}; }
    static Space barycentric(int n) { return {Kind::barycentric, n - 1}; }
    // Entries of a point's homogeneous column: d + 1 for R^d, n for bary(n).
    int coordinates() const { return dimension + 1; }
    bool operator==(const Space&) const = default;
};

// "R2", "R3", "bary(4)".
std::string space_name(Space s);

struct Operator {
    std::optional<num::Matrix<num::Rational>> exact; // when every entry is rational and known exactly
    num::Matrix<num::Interval> enclosure;            // always: contains the true matrix entry-wise
    num::Matrix<double> nearest;                     // the nearest doubles (midpoints of the enclosure)

    static Operator from_exact(const num::Matrix<num::Rational>& m);
    static Operator from_enclosure(const num::Matrix<num::Interval>& m);
    std::size_t rows() const { return nearest.rows(); }
    std::size_t cols() const { return nearest.cols(); }
};

// What is drawn for a state at the leaves of an evaluation tree.
struct Primitive {
    enum class Kind {
        none,     // nothing: the state's attractor only (chaos game, covers, distance)
        points,   // each column of `points`
        polyline, // the columns of `points` joined in order
        polygon,  // closed
        shape,    // a Frac shape of the module (index into Module::shapes), in the state's space
    } kind = Kind::none;
    num::Matrix<double> points; // homogeneous columns in the state's space
    std::size_t shape = 0;
};

struct State {
    std::string name;
    Space space;
    Primitive primitive;
};

struct Arc {
    std::size_t from = 0, to = 0; // state indices: the operator maps the space of `to` into that of `from`
    Operator op;
    std::optional<double> probability; // chaos game weight, when the model gives one
    std::string label;                 // the name written in the model (T0, f1, ...), may be empty
};

// A cell split as a triangle patch (a bcifs's `topology t = triangle(e) split n`, frontend/topology.hpp):
// its control points p(i, j), i + j <= k - 1, and its arcs to the upward sub-triangles U(a, b) (corners
// (a, b), (a+1, b), (a, b+1) in units of 1/n) and the downward ones D(a, b), whose reference corners
// (0, 0), (1, 0), (0, 1) sit at (a+1, b), (a, b+1), (a+1, b+1). The tessellation of triangle patches
// (runtime/automata/surface.hpp) follows it.
struct TrianglePatch {
    std::size_t state = 0;
    int n = 2;
    std::vector<std::size_t> up, down;  // arc indices, U(a, b) and D(a, b) by b, then a
    std::array<std::size_t, 3> corners; // the weights at the corners (0, 0), (1, 0), (0, 1)
};

// A cell split as a cube (a bcifs's `topology c = cube(f) split n x n x n`, frontend/topology.hpp): its
// solid is bounded by the six faces B0 ... B5 (z low, high, y low, high, x low, high), each the face
// cell's attractor through its boundary operator. The meshing of solids (runtime/automata/solid.hpp)
// follows it.
struct VolumeCell {
    std::size_t state = 0;
    std::array<std::size_t, 6> faces{}; // indices into Automaton::embeddings, B0 ... B5
};

struct Automaton {
    std::string name;
    std::vector<State> states;
    std::vector<Arc> arcs;
    std::size_t initial = 0;
    // For a barycentric initial state: the control points as the columns of a (d + 1) x n homogeneous
    // matrix bary(n) -> R^d. Empty when the initial state is euclidean (its space is the picture's).
    std::optional<Operator> projection;
    // A BCIFS's boundary (embedding) operators B : X^to -> X^from (seed 002): they place a lower cell's
    // attractor inside a higher one's and are no part of the union that defines an attractor, so they
    // are kept apart from the arcs (junctions, shared boundaries and meshes use them).
    std::vector<Arc> embeddings;
    std::vector<TrianglePatch> triangle_patches;
    std::vector<VolumeCell> volume_cells;

    // The arcs leaving state s, in model order.
    std::vector<std::size_t> arcs_from(std::size_t s) const;
    // The euclidean dimension the attractor is drawn in (the initial space, or the projection's).
    int output_dimension() const;
};

// The affine functional w of a space (see the file comment), as a row.
num::Matrix<num::Rational> affine_functional(Space s);

// Text form (frac check --emit=automaton): states with their spaces and primitives, arcs with their
// matrices (exact entries as fractions), the initial state and the projection.
std::string print_automaton(const Automaton& a);

} // namespace frac::ir
