// The syntax tree, as parsed. Names are resolved and types checked by later passes.
#pragma once

#include "frontend/diagnostics.hpp"
#include "frontend/lexer.hpp"

#include <memory>
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

struct Expr {
    ExprKind kind;
    Location loc;
    std::string text;
    std::string var;                  // series index name
    std::string orbit_var, orbit_map; // orbit series: the point's name and the map (a function)
    Location orbit_loc, escape_loc;
    Tok op = Tok::end; // unary / binary operator
    std::vector<ExprPtr> kids;
    std::vector<Arg> args;
    std::vector<Binding> bindings;
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
};

struct ArcDecl {
    std::string from, to, label; // label: the operator's name (T0), may be empty
    Location loc, from_loc, to_loc;
    ExprPtr op;
    ExprPtr probability; // or null
};

struct AutomatonDecl {
    bool graph_directed = false; // cifs; an ifs has one state, named as the automaton
    std::vector<StateDecl> states;
    std::vector<ArcDecl> arcs;
    std::string initial; // empty: the first state
    Location initial_loc;
    ExprPtr projection; // project = controls(...): for a barycentric initial state, or null
};

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

// Parses one file's tokens; syntax errors go to `diags`, with recovery at the next item.
Program parse(const std::vector<Token>& tokens, Diagnostics& diags);

// Text form of the syntax tree (frac check --emit=ast).
// Only the items of `file` when it is not 0 (imported files' items are left out).
std::string print_ast(const Program& p, std::uint32_t file = 0);
std::string print_expr(const Expr& e);

} // namespace frac::front
