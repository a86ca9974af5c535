// Type checking: the stage between name resolution and lowering. Every expression of the program gets
// a type (types.hpp) and every type error is reported here, located, before anything is lowered.
// Functions are generic (a parameter takes the type of its argument, functions are values), so a
// function's body is checked once per distinct signature it is called with (its instances).
#pragma once

#include "frontend/ast.hpp"
#include "frontend/lower.hpp"
#include "frontend/types.hpp"
#include "support/flat_map.hpp"

#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace frac::front {

struct FunctionInstance {
    const Item* function = nullptr;
    std::vector<Type> params;
    Type result;
};

// What type checking found: the types of the definitions and of each function instance. Every
// expression is checked, but only the types of whole expressions are kept (a table of every node's type
// cost a 7000-clause model two thirds of its type checking, and nothing reads it).
struct TypedProgram {
    std::unordered_map<const Item*, Type> items; // const: its value's type; shape: Type{shape, dimension}
    std::vector<FunctionInstance> instances;     // in the order first used
    // The type of each expression checked as a whole: the body of a const, shape, print or function
    // (under its latest instance), a shape's box, an expectation's sides, an automaton's operators,
    // probabilities and projections.
    support::FlatMap<const Expr*, Type> roots;
    // The items and expectations (Expect) with a type error, reported: lowering skips them and lowers
    // the rest, so that errors that need values are found in the same run.
    std::unordered_set<const void*> failed;
};

void typecheck(const Program& program, const Limits& limits, TypedProgram& out, Diagnostics& diags);

// Text form (frac check --emit=typecheck): the signature of each definition of file `file` (all when 0)
// and of each function instance.
std::string print_types(const Program& program, const TypedProgram& typed, std::uint32_t file = 0);

} // namespace frac::front
