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

enum class ItemKind { import, fn, const_, shape, test, print };

struct Param {
    std::string name;
    Location loc;
};

struct Expect {
    Location loc;
    ExprPtr expr;
    ExprPtr within; // tolerance, or null
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
