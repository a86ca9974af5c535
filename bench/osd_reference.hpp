// OpenSubdiv (Far, CPU, double precision) as the reference for a uniform bicubic B-spline patch: the
// patch of a 4 x 4 control grid is the limit surface of the central face of the grid's 3 x 3
// Catmull-Clark faces (a regular face whose 1-ring is regular). Used by the agreement test
// (tests/unit/opensubdiv) and by bench_surface.
#pragma once

#include "ir/automaton.hpp"

#include <array>
#include <cstddef>
#include <vector>

namespace frac::osd {

struct RefinedPatch {
    int level = 0;
    // Limit positions of the last level's vertices on the central face, (2^level + 1)^2 of them at
    // index i * (2^level + 1) + j for s = i / 2^level, t = j / 2^level.
    std::vector<std::array<double, 3>> grid;
    std::size_t refined_vertices = 0; // vertices of the last level over all 9 faces
    double topology_seconds = 0;      // TopologyRefinerFactory::Create and RefineUniform
    double interpolate_seconds = 0;   // PrimvarRefiner::Interpolate over the levels
    double limit_seconds = 0;         // PrimvarRefiner::Limit at the last level
    double seconds() const { return topology_seconds + interpolate_seconds + limit_seconds; }
};

// controls[a * 4 + b] is control point (a, b), a along s. level in [1, 10]. Throws
// std::runtime_error when a central vertex cannot be placed on the grid.
RefinedPatch refine_bicubic_patch(const std::array<std::array<double, 3>, 16>& controls, int level);

// The 16 control points of a bicubic patch automaton: the columns of its projection (bary(16) -> R3).
// Throws std::invalid_argument for another shape of projection.
std::array<std::array<double, 3>, 16> patch_controls(const ir::Automaton& a);

// The largest coordinate difference between the reference grid and vertices in the same order.
double max_difference(const RefinedPatch& reference, const std::vector<std::array<double, 3>>& vertices);

} // namespace frac::osd
