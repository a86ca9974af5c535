// Tessellation of projected-IFS curves and quad patches (seed 003 sec. 3, seed 002 sec. 3).
//
// A curve state is cut by its maps into n sub-segments, a quad-patch state into n_s x n_t
// sub-squares; the layout says which map makes which sub-cell and how the child's parameters sit
// in it. At depth p the patch is the grid of vertices (n_s^p + 1) x (n_t^p + 1) at s = i / n_s^p,
// t = j / n_t^p, each vertex computed ONCE through its address (p compositions, then a corner of
// the state reached: the fixed point of its corner cycle), projected by the control points. A
// vertex on the side shared by two sub-patches is one vertex of both, so the sub-patches share
// their boundaries bit for bit; the layout check has proven beforehand that the sides do meet
// (exactly, in rationals, when the operators are exact).
#pragma once

#include "ir/automaton.hpp"
#include "runtime/mesh.hpp"

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace frac::rt {

// Where one map puts its image in the cell it subdivides: the child's parameters (u, v) are swapped
// first (square cells only), then each reversed, within the sub-cell.
struct CellPlacement {
    std::size_t arc = 0; // index into Automaton::arcs; its source is the state being cut
    bool swap = false;
    bool flip_s = false;
    bool flip_t = false;
    bool operator==(const CellPlacement&) const = default;
};

// How one state is cut: a curve (dimension 1, n_s pieces, n_t = 1) or a quad patch (dimension 2,
// n_s x n_t sub-squares). cells[i * n_t + j] is sub-cell i along s, j along t.
struct CellLayout {
    int dimension = 2;
    std::size_t n_s = 2, n_t = 2;
    std::vector<CellPlacement> cells;
};

// The layouts of the states reached from the root (nullopt for the others).
struct SurfaceLayout {
    std::size_t root = 0;
    std::vector<std::optional<CellLayout>> states;
    bool exact = false; // the joins were verified in exact rationals (else to 1e-9 relative)
    std::string how;    // how the layout was found, for messages
    // Set by check_layout: per state, the homogeneous columns of its corners (s, t) at index s + 2 t
    // (exact, then rounded, for exact operators), which tessellate reuses.
    std::vector<std::array<std::vector<double>, 4>> corners;
};

// What the command line says about the layout; zeros and empty mean "infer".
struct LayoutRequest {
    int dimension = 0;              // 1 curve, 2 patch
    std::size_t n_s = 0, n_t = 0;   // sub-cells per axis
    std::vector<std::string> cells; // the root state's arc labels in cell order (i * n_t + j)
};

// The layout of the automaton's initial state and of every state it reaches. Without a request it
// tries a square patch (when the arc count is a square) and then a curve, cells in model order, and
// for a single state of at most 4 arcs every order of its arcs; the first layout whose joins hold is
// taken. Throws std::invalid_argument saying why when none does.
SurfaceLayout infer_layout(const ir::Automaton& a, const LayoutRequest& request = {});

// Checks the layout's shape (every state it reaches is laid out, with all its arcs, the same cell
// counts everywhere) and its joins: adjacent sub-cells agree at the points of depth 2 along their
// common side, and the corners of each state are well defined. Sets layout.exact. Throws
// std::invalid_argument naming the first problem.
void check_layout(const ir::Automaton& a, SurfaceLayout& layout);

struct Tessellation {
    int dimension = 2;
    int depth = 0;
    std::size_t side_s = 0, side_t = 0; // vertices per side: n_s^p + 1 and n_t^p + 1 (1 for curves)
    int output_dimension = 3;           // coordinates the model gives (missing ones are 0)
    // Vertex (i, j) at index i * side_t + j: the point at s = i / n_s^p, t = j / n_t^p.
    std::vector<std::array<double, 3>> vertices;
};

// The grid of vertices at depth p in [0, 24]; at most 2^26 vertices. The layout must have passed
// check_layout (infer_layout's has). Drawn through `output` (homogeneous rows over the initial state's
// space) when given, else through the projection.
Tessellation tessellate(const ir::Automaton& a, const SurfaceLayout& layout, int depth,
                        const num::Matrix<double>* output = nullptr);

// Two triangles per grid square, counter-clockwise around ds x dt. Throws for a curve.
Mesh surface_mesh(const Tessellation& t);

// Throws RangeError when a vertex is not finite: the model's values leave the range of doubles (a fault
// of the model, reported at the automaton), which no mesh or picture file can hold.
void require_finite_vertices(const std::vector<std::array<double, 3>>& vertices);

// A triangle patch (ir::TrianglePatch, the automaton's initial state) tessellated to depth p: the
// (N + 1)(N + 2) / 2 vertices of its grid, N = n^p, each computed once from the first sub-triangle that
// reaches it (so shared sides are bit-identical), and its n^(2p) triangles, counter-clockwise in the
// parameter plane (a reflected sub-triangle's corners swapped). At most 2^26 triangles.
Mesh tessellate_triangle_patch(const ir::Automaton& a, const ir::TrianglePatch& patch, int depth);

// A surface of several patches: each arc of the initial state leads to a patch state (laid out by
// infer_layout from there), drawn through the arc's operator (and the projection). Each patch is
// tessellated to depth p; a side of one patch whose vertices all coincide with a side of another (in
// either order, within 1e-9 of the model's extent) is a join, and the two sides become one set of
// vertices (the first patch's), so a closed model gives a closed mesh. Throws std::invalid_argument
// when the initial state is reached again, a patch's layout cannot be inferred, or an arc leads to a curve.
struct PatchSurface {
    Mesh mesh;
    std::size_t patches = 0, joins = 0; // joined side pairs
};
PatchSurface tessellate_patches(const ir::Automaton& a, int depth);

// A curve: the vertices joined in order, as an SVG polyline (x, y seen from above) or an OBJ line
// element. Throw std::runtime_error naming the path when the file cannot be written.
void write_polyline_svg(const Tessellation& t, const std::string& path);
void write_polyline_obj(const Tessellation& t, const std::string& path);

} // namespace frac::rt
