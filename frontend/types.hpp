// The types of the language and its typing rules, in one place: the type checker (typecheck.hpp)
// applies them to types before anything is lowered, and lowering applies the same rules to the
// values it builds, so a rule and its message are written once.
#pragma once

#include "frontend/diagnostics.hpp"
#include "frontend/lexer.hpp"
#include "frontend/module.hpp"

#include <string>

namespace frac::front {

struct Type {
    enum class Kind {
        number,
        boolean,   // a condition
        point,     // size: its coordinates (2 or 3)
        interval,  // a constant interval [lo, hi]
        box,       // size: its axes (2 or 3)
        matrix,    // rows × cols, entries constant numbers
        transform, // an affine map of the plane or space (translate, rotate, scale, shear, ...);
                   // size: its dimension, or 0 while no operand fixed it (scale(1/2) fits R2 and R3)
        shape,     // size: its coordinates; a shape named as a value (enclose, dimension, an argument)
        function,  // a function named as a value (passed as an argument)
        automaton, // an ifs or cifs named as a value
    } kind = Kind::number;
    int size = 0;           // see the kinds
    int rows = 0, cols = 0; // matrix

    static Type number() { return {Kind::number}; }
    static Type boolean() { return {Kind::boolean}; }
    static Type point(int n) { return {Kind::point, n}; }
    static Type interval() { return {Kind::interval}; }
    static Type box(int axes) { return {Kind::box, axes}; }
    static Type matrix(int rows, int cols) { return {Kind::matrix, 0, rows, cols}; }
    static Type transform(int dimension) { return {Kind::transform, dimension}; }
    bool operator==(const Type&) const = default;
};

// "a number", "a condition", "a point", "an interval", "a box", "a 3×3 matrix", ... as messages use it.
std::string type_name(Type t);
// The short form of signatures (--emit=typecheck): number, condition, point2, box3, matrix3x3, ...
std::string type_spelling(Type t);
// The value kinds the module records for print statements.
ValueKind value_kind(Type t);

// ---- typing rules: each returns the result type or throws CompileError with a located message ----

// A number is expected (an interval is accepted: it stands for its midpoint's enclosure).
void require_number(Type t, Location loc);
void require_condition(Type t, Location loc);
// not, +, -, ~ applied to `a` (at la).
Type unary_rule(Tok op, Type a, Location la);
// a op b, for every binary operator of the language (e at the operator, la and lb at the operands).
Type binary_rule(Tok op, Type a, Type b, Location e, Location la, Location lb);
// `*` where a box is expected: the ASCII spelling of ×; nullopt-like: returns false when the rule does
// not apply (the operands are no intervals), so the expression is an ordinary product.
bool is_box_product(Type a, Type b);
// The box a × b.
Type box_product_rule(Type a, Type b, Location e);
Type if_rule(Type then_type, Type else_type, Location lthen, Location lelse);
// p.x, p.y, p.z
Type field_rule(Type p, const std::string& field, Location e);
// (a, b[, c]) of `components` numbers.
Type tuple_rule(std::size_t components, Location e);

} // namespace frac::front
