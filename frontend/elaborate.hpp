// Elaboration: type checking and lowering of a resolved program to the expression graph, with
// functions, shapes and lets inlined and every infinite series bounded (series_bounds).
#pragma once

#include "frontend/ast.hpp"
#include "frontend/module.hpp"

namespace frac::front {

struct Limits {
    int max_finite_terms = 10000; // terms of a finite series
    int max_inline_depth = 64;    // nested function calls
    int max_series_nesting = 16;
};

void elaborate(const Program& program, const SourceManager& sources, const Limits& limits, Module& out,
               Diagnostics& diags);

} // namespace frac::front
