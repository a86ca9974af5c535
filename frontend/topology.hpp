// Topology declarations of a bcifs (seed 002's conclusion names them as the missing piece): the
// operators and the incidence and adjacency constraints of the common cells, generated so users do not
// write the equations by hand.
//
//   topology e = edge(v) split n;       e in bary(k), k >= 2, bounded by the vertex cell v (bary(1)):
//       boundary e from v { B0 = the first control point; B1 = the last; }, T0 ... T(n-1) unknown,
//       v.T0 = [[1]]; incidence e.B0 * v.T0 == e.T0 * e.B0, e.B1 * v.T0 == e.T(n-1) * e.B1;
//       adjacency e.Ti * e.B1 == e.T(i+1) * e.B0.
//   topology f = quad(e, g) split n x m;  two edge cells: e (bary(k), split n) for the bottom and top
//       rows, g (bary(h), split m) for the left and right columns, f in bary(k * h), h rows of k points;
//       quad(e) is quad(e, e) (then n = m). The rest as for the square patch:
//   topology f = quad(e) split n x n;   f in bary(k * k): a grid of control points p[k * row + column],
//       bounded by the edge cell e (bary(k), split into n): B0 the bottom row, B1 the left column, B2 the
//       right column, B3 the top row (each from its first to its last point); sub-patch T(i + n j) is the
//       i-th along s and the j-th along t (T0 bottom left); incidence: each boundary's pieces are the
//       sub-patches along it; adjacency: neighbours share their common side.
//   topology c = cube(f) split n x n x n;  c in bary(k^3) over the face cell f (bary(k^2), split n x n):
//       six faces B0 ... B5 (z low, z high, y low, y high, x low, x high), n^3 sub-cubes, incidence on
//       every face, adjacency between neighbours along each axis.
//
// Operators the model writes itself are kept (a partly known T0, a different B0); only missing ones are
// generated. The pass runs after parsing (the `constraints` stage), before names are resolved.
#pragma once

#include "frontend/ast.hpp"
#include "frontend/diagnostics.hpp"

#include <cstdint>
#include <string>

namespace frac::front {

void expand_topology(Program& program, Diagnostics& diags);

// Every bcifs's operators and constraints of `file` (0: the main file), the generated ones marked with
// the topology declaration they come from (frac check --emit=constraints).
std::string print_constraints(const Program& program, std::uint32_t file = 0);

} // namespace frac::front
