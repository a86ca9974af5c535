// The syntax tree, as parsed. Names are resolved and types checked by later passes.
#pragma once

#include "frontend/diagnostics.hpp"
#include "frontend/lexer.hpp"
#include "frontend/limits.hpp"

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace frac::front {

enum class ExprKind {
    number,   // text: the literal
    name,     // text: the name
    call,     // text: callee; args
    unary,    // op; kids[0]
    binary,   // op; kids[0], kids[1]
    if_,      // kids: condition, then, else
    let,      // bindings; kids[0]: body
    tuple,    // kids: components (a point)
    field,    // text: component name (x, y, z); kids[0]
    interval, // kids: lo, hi
    series,   // text: sum | min | max; var; kids: start, end (null if infinite), body,
              // and for an orbit series (orbit_var in orbit(kids[3], orbit_map)) the initial point,
              // then the escape radius kids[4] when there is one
    lambda,   // fn (a, b) = body, an argument: bindings: the parameters (values null); kids[0]: body
    matrix,   // [[a, b], [c, d]]: kids: the rows, each a tuple of its entries
};

struct Expr;
using ExprPtr = std::unique_ptr<Expr>;

struct Binding {
    std::string name;
    Location loc;
    ExprPtr value;
};

struct Arg {
    std::string name; // empty for a positional argument
    Location loc;
    ExprPtr value;
};

// What only a series has, apart from its expression: few nodes are series.
struct SeriesSyntax {
    std::string var;                  // the index's name
    std::string orbit_var, orbit_map; // orbit series: the point's name and the map (a function)
    Location orbit_loc, escape_loc;
};

// Small, with what every pass reads of every node first: a large tree takes less memory, and its walks
// touch fewer cache lines.
struct Expr {
    ExprKind kind;
    Tok op = Tok::end; // unary / binary operator
    Location loc;
    std::vector<ExprPtr> kids;
    std::vector<Arg> args;
    std::vector<Binding> bindings;
    std::string text;
    std::unique_ptr<SeriesSyntax> series; // a series's; null for the other kinds
};

enum class ItemKind { import, fn, const_, shape, test, print, automaton };

struct Param {
    std::string name;
    Location loc;
};

struct Expect {
    Location loc;
    ExprPtr expr;
    ExprPtr within; // tolerance, or null
};

// An automaton (ifs, cifs): states with their spaces, arcs a -> b carrying an operator from the space
// of b into the space of a (A_a is the union of T(A_b) over its arcs), an initial state.
struct SpaceDecl {
    bool barycentric = false;
    int n = 2; // R^n, or bary(n) (n weights)
    Location loc;
};

struct StateDecl {
    std::string name;
    Location loc;
    SpaceDecl space;
    ExprPtr primitive; // drawn at the leaves of evaluation trees, or null
    // A bcifs cell taken from another bcifs (`cell l = spline.e;`): its space and its solved operators
    // (frontend/cell_import.hpp); empty for a declared cell.
    std::string source, source_cell;
    Location source_loc;
};

struct ArcDecl {
    std::string from, to, label; // label: the operator's name (T0), may be empty
    Location loc, from_loc, to_loc;
    ExprPtr op;
    ExprPtr probability; // or null
};

// A BCIFS (seed 002 sec. 3): cells are the states; each cell has subdivision operators (arcs of the
// automaton: A_c is the union of T(A_target)) and boundary operators B : X^from -> X^c that embed a
// lower cell, which are no arcs. Operators may be unknown (`?`, or a matrix with `?` entries); the
// constraints (products of operators, equal) and `fix` statements determine them, solved exactly.
struct OperatorDecl {
    std::string cell, name, target; // subdivision: cell -> target; boundary: the cell it embeds
    bool boundary = false;
    Location loc, target_loc;
    ExprPtr value; // null: unknown; a matrix whose entries may be unknown (is_unknown); or an expression
    bool generated = false; // by a topology declaration
    // An operator of a cell taken from another bcifs: the solved operator source.source_cell.name,
    // known when this bcifs is lowered; empty otherwise.
    std::string source, source_cell;
};

// One factor of a constraint's product: an operator `cell.name`, or a constant matrix.
struct FactorDecl {
    std::string cell, name; // empty for a constant
    ExprPtr constant;
    Location loc;
};

struct ConstraintDecl {
    std::vector<FactorDecl> left, right;
    Location loc;
    std::string origin; // empty when written; else the topology declaration that generated it
};

// fix cell.name[row][col] = value;
struct FixDecl {
    std::string cell, name;
    int row = 0, col = 0;
    ExprPtr value;
    Location loc, index_loc;
};

// param name [in [lo, hi]] [= value];  a symbolic parameter of the solution (seed 002's λ, μ).
struct ParamDecl {
    std::string name;
    Location loc;
    ExprPtr lo, hi, value; // each may be null
};

// topology e = edge(v) split n;  topology f = quad(e) split n x n;  (frontend/topology.hpp)
struct TopologyDecl {
    std::string cell, kind, of; // kind: edge, quad, triangle or cube; `of`: the boundary cell
    std::string across;         // quad(e, g): the edge cell of the left and right sides (else `of`)
    int n = 2, m = 1, l = 1;
    Location loc, kind_loc, of_loc, across_loc;
};

struct BcifsDecl {
    // seed N;  the free entries take values drawn from N (as with --seed, which overrides it).
    std::optional<std::uint64_t> seed;
    std::vector<TopologyDecl> topologies;
    std::vector<OperatorDecl> operators;
    std::vector<ConstraintDecl> constraints;
    std::vector<FixDecl> fixes;
    std::vector<ParamDecl> params;
};

// An unknown entry `?` of an operator's matrix.
inline bool is_unknown(const Expr& e) {
    return e.kind == ExprKind::name && e.text == "?";
}

// A fractal interpolation function or curve (seed 001 sec. 2):
//   fif NAME { points (t0, x0), ..., (tN, xN); | data "file.csv";
//              scale c1, ..., cN; | scale c;       (curves: c, (cx, cy) or [[cxx, cxy], [cyx, cyy]])
//              [domains (j1, k1), ..., (jN, kN);] }
// Piece i is the shear T_i (eq. 1; eq. 8/9 for a curve (t, x, y)) with T_i(P_j) = P_(i-1) and T_i(P_k) = P_i
// for its domain (j, k) (default (0, N): a FIF; k < j: the "reflected" constraints; other domains: an
// RFIF). frontend/fif.hpp expands it into the states and arcs of a cifs after parsing.
// A piece of a partitioned FIF (seed 001 sec. 2.3): the shear `map` (a homogeneous matrix over (t, x) or
// (t, x, y)) takes the graph over its domain [from, to] onto the graph over its range.
struct FifPiece {
    Location loc; // the `piece` keyword
    ExprPtr from, to, map;
};

struct FifDecl {
    std::vector<FifPiece> pieces; // a PFIF, instead of points and scalings
    std::vector<ExprPtr> points;  // tuples (t, x) or (t, x, y)
    std::string data;             // a CSV file of rows t, x[, y], relative to the model, instead of points
    Location points_loc, data_loc, scale_loc, domains_loc;
    std::vector<ExprPtr> scales;
    std::vector<std::array<int, 2>> domains; // point indices (j, k), one per piece, or empty
    std::vector<Location> domain_locs;
    std::vector<ExprPtr> values; // set by the expansion: every point as a tuple (t, x[, y])
    bool malformed = false;      // a statement failed to parse (reported): not expanded
};

struct AutomatonDecl {
    bool graph_directed = false;      // cifs or bcifs; an ifs has one state, named as the automaton
    std::shared_ptr<BcifsDecl> bcifs; // a bcifs: its states are the cells
    std::shared_ptr<FifDecl> fif;     // a fif: its states and arcs are generated from it
    std::vector<StateDecl> states;
    std::vector<ArcDecl> arcs;
    std::string initial; // empty: the first state
    Location initial_loc;
    ExprPtr projection; // project = controls(...): for a barycentric initial state, or null
};

// The initial state: the one named `initial`, else the first state (ifs, cifs) or the last cell (a bcifs,
// whose cells are declared from the lowest up).
inline const StateDecl& initial_state(const AutomatonDecl& a) {
    for (const StateDecl& s : a.states)
        if (s.name == a.initial) return s;
    return a.bcifs ? a.states.back() : a.states.front();
}

struct Item {
    ItemKind kind;
    Location loc;
    std::string name;            // fn/const/shape name, test title, import path
    std::string alias;           // import "m" as alias: the module's names are alias.name
    std::vector<Param> params;   // fn, shape
    bool has_params = false;     // shape with an explicit parameter list
    ExprPtr over;                // shape: default box, or null
    ExprPtr body;                // fn/const/shape/print
    std::vector<Expect> expects; // test
    std::shared_ptr<AutomatonDecl> automaton;
};

struct Program {
    std::vector<Item> items;
};

// Parses one file's tokens; syntax errors go to `diags`, with recovery at the next item. Of `limits`,
// the nesting of expressions and the operators of a definition.
Program parse(const std::vector<Token>& tokens, Diagnostics& diags, const Limits& limits = {});

// Text form of the syntax tree (frac check --emit=ast).
// Only the items of `file` when it is not 0 (imported files' items are left out).
std::string print_ast(const Program& p, std::uint32_t file = 0);
std::string print_expr(const Expr& e);
// A constraint's side as written: e.B0 * v.T0 (a constant factor in its syntax-tree form).
std::string print_product(const std::vector<FactorDecl>& side);

} // namespace frac::front
