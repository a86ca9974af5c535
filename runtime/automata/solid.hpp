// Meshes of solids: BCIFS volume cells (the cell of a cube topology, bounded by its six faces) and the
// automata that place them, such as seed 002 sec. 3.3's arborescent solid, a condensation
// A^a = T_b(A^b) ∪ T_1(A^a) ∪ ... ∪ T_4(A^a): a block on top, four smaller copies of the whole below it.
#pragma once

#include "ir/automaton.hpp"
#include "runtime/mesh.hpp"

#include <cstddef>

namespace frac::rt {

struct SolidMesh {
    Mesh mesh;
    std::size_t blocks = 0; // volume cells drawn
    std::size_t faces = 0;  // face patches tessellated (six per block)
    std::size_t inner = 0;  // grid squares shared by two faces, so inside the solid, and removed
    int layers = 0;         // levels of the walk at which blocks were drawn
};

// Whether a volume cell (ir::VolumeCell) is reachable from the initial state.
bool reaches_volume(const ir::Automaton& a);

// Walks the automaton from its initial state with the remaining depth p in [0, 24]. A volume cell
// reached is drawn as its six faces, each face cell tessellated to the remaining depth through its
// boundary operator (runtime/automata/surface.hpp: every grid vertex computed once). Any other state
// places what its arcs lead to: a volume cell at the same remaining depth, another state one level
// deeper while depth remains. So a condensation is drawn layer by layer, layer L at depth p - L, and a
// block's foot meets the top of the block below on the same grid.
//
// Vertices within 1e-9 of the model's extent are merged; a grid square that two faces share (a block
// standing on another, two blocks side by side) lies inside the solid, and both copies are removed.
// The rest is cut into triangles and oriented consistently across shared edges, outwards (positive
// enclosed volume) in each component. A closed model gives a closed mesh. Throws std::invalid_argument
// when no volume cell is reached, a face cell is no quad patch, or the mesh would exceed 2^26 vertices.
SolidMesh tessellate_solid(const ir::Automaton& a, int depth);

} // namespace frac::rt
