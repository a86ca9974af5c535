// Bounds of a tail coefficient that point evaluation can compute.
//
// The tail coefficients A and B of a series (graph.hpp) are enclosures: their nodes hold interval
// constants (the range of dz, a [0, 1] factor) and hulls (a select on an unknown condition). Their
// *point* values are representatives of those enclosures, not bounds: the point value of
// [-1/4, 1/4] is 0. Point evaluation needs bounds to stop a series, so the graph carries, beside
// each coefficient, two nodes whose point values are a lower and an upper bound of it: interval
// arithmetic over the coefficient's cone written out as ordinary point operations (min and max of
// corner values, selects on signs). A node whose cone has no interval constant is its own bound.
// Rounding to nearest makes the bounds approximate to an ulp, which the stopping rule's slack covers
// (ir::series_point_estimate); a bound that may be NaN reads as unbounded.
#pragma once

#include "ir/graph.hpp"

namespace frac::ir {

struct PointBounds {
    NodeId lo = no_node;
    NodeId hi = no_node;
};

// Nodes whose point values bound the values of `id` from below and above (the same node when `id`
// computes its exact value at a point). Adds nodes to `g`.
PointBounds point_bounds(Graph& g, NodeId id);

} // namespace frac::ir
