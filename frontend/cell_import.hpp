// Cells taken from another bcifs (`cell l = spline.e;`): seed 004 joins two curves built by different
// processes (a cubic and a quadratic B-spline, or two fractal curves) by an intermediate curve whose
// operators are constrained by theirs. The taking bcifs gets the source cell's space and, for every
// operator of the source cell whose target is also taken from the same bcifs (its subdivisions into
// itself, the boundary operators from a taken vertex), the same operator, marked with its source: it is
// known, not solved again — lowering takes the source's solved values, the free entries as the source
// chose them.
//
// The pass runs in the constraints stage (topology.hpp orders it: a source's own cells and topology
// first, then the taking bcifs's cells, then its topology, which may build on them).
#pragma once

#include "frontend/ast.hpp"
#include "frontend/diagnostics.hpp"

#include <functional>
#include <string>

namespace frac::front {

// The bcifs named `name`, after its own cells and topology are complete; null (and an error reported at
// `loc`) when there is none or taking from it would be circular.
using BcifsSource = std::function<const Item*(const std::string& name, Location loc)>;

// Gives the cells of `a` that name a source their space and their operators.
void import_cells(AutomatonDecl& a, const BcifsSource& source, Diagnostics& diags);

} // namespace frac::front
