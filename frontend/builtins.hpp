// The builtin functions and constants, shared by name resolution and elaboration.
#pragma once

#include "ir/graph.hpp"

#include <optional>
#include <string>
#include <vector>

namespace frac::front {

enum class BuiltinKind {
    unary,     // an IR op of one argument
    binary,    // an IR op of two arguments
    variadic,  // min/max of two or more arguments
    mod,       // mod(x, m)
    pow,       // pow(x, y) = x^y
    enclose,   // enclose(shape, box): a proven enclosure (tests and print only)
    dimension, // dimension(shape, from: a, to: b [, split: s]), dimension(automaton) (tests and print only)
    transform, // translate, rotate, scale, shear: an affine map of R2 or R3 (constant arguments)
    controls,  // controls(P0, ..., Pn-1): the projection of bary(n) by control points
    kron,      // kron(A, B): the Kronecker product of two matrices (tensor-product surfaces)
    primitive, // point, segment, polyline, polygon: what a state of an automaton draws
    tabulate,  // tabulate(automaton, t): the point F(t) of its address map, t = i / N^p (tests, print)
    distance,  // dist(p, automaton): the distance from the point p to the attractor (an external function)
    dof,       // dof(bcifs.cell): the free entries a cell's operators keep after the constraints (tests)
};

struct Builtin {
    const char* name;
    BuiltinKind kind;
    int min_args, max_args;
    ir::Op op;
};

const Builtin* find_builtin(const std::string& name);
bool is_builtin_constant(const std::string& name); // pi, e, identity (the identity transform)
std::vector<std::string> builtin_names();          // the builtin functions, for suggestions

} // namespace frac::front
