// Lowering of a type-checked program to the expression graph, with functions, shapes and lets inlined,
// constants folded (exactly where they are rational) and every infinite series bounded
// (series_bounds). Type errors were reported by the type checker (typecheck.hpp); what is left here
// needs values: constant bounds and indices, series tails, escape certificates.
#pragma once

#include "frontend/ast.hpp"
#include "frontend/module.hpp"

namespace frac::front {

struct Limits {
    int max_finite_terms = 10000; // terms of a finite series
    int max_inline_depth = 64;    // nested function calls
    int max_series_nesting = 16;
};

struct TypedProgram;

void lower(const Program& program, const TypedProgram& typed, const SourceManager& sources,
           const Limits& limits, Module& out, Diagnostics& diags);

} // namespace frac::front
