// Surface meshes of 3D covers: the boundary of the union of the selected leaf cells of an octree
// (inside cells, or inside plus boundary cells), as a closed, consistently oriented, 2-manifold
// triangle mesh, for 3D printing (binary STL, OBJ, PLY).
//
// Construction (see mesh_build.cpp for the details and the correctness argument):
//  - Everything happens on the finest lattice (split^depth cells per axis), without a dense 3D grid:
//    for each axis and each lattice plane, the faces between selected and unselected cells are
//    computed from the leaves that touch the plane (a sweep over the plane's squares) and merged
//    into maximal-run rectangles (coplanar faces merged).
//  - Non-manifold places (two selected cells meeting only along an edge or at a corner, the trap of
//    fractal solids) are resolved by treating the cells as slightly apart: a lattice point gets one
//    vertex copy per fan (cycle) of faces around it, and where the two surface sheets meeting along
//    an edge would share both end vertices, the edge is split by one midpoint copy per sheet.
//  - Rectangles are triangulated with every vertex lying on their sides (no T-junctions).
// The result is watertight (every edge has exactly two triangles), edge- and vertex-manifold and
// oriented with outward normals; check_mesh verifies this.
//
// Vertex coordinates: a point with coordinate i on the doubled lattice (0..2n, n = split^depth;
// odd values are rectangle centres and edge midpoints) maps to x0 + (x1 - x0) * i / (2n) of the
// root box, computed in double (the root's bounds exactly at i = 0 and i = 2n).
#pragma once

#include "runtime/cover.hpp"
#include "runtime/limits.hpp"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace frac::rt {

// Which leaves form the solid: the cells proven inside, the whole cover (inside and boundary cells;
// the boundary cells at the depth limit may hold points of the shape), or the boundary cells alone
// (a thin solid around the surface: the printable form of a shape without interior, such as a
// sponge's limit set or a surface given by its distance).
enum class MeshSelection { inside, inside_and_boundary, boundary };

struct MeshStats {
    std::uint64_t cells = 0;             // selected leaf cells
    std::uint64_t unit_faces = 0;        // faces between selected and unselected unit lattice cells
                                         // (the unmerged quad count; 2 triangles each without merging)
    std::uint64_t rectangles = 0;        // coplanar faces after merging
    std::uint64_t split_points = 0;      // lattice points with more than one vertex copy
    std::uint64_t split_edges = 0;       // non-manifold edges split through a midpoint (two copies)
    std::uint64_t nonmanifold_edges = 0; // mesh edges where two selected cells meet only along the edge
    double seconds = 0;                  // wall time of mesh_cover
};

// An indexed triangle mesh. Triangles are counter-clockwise seen from outside (right-hand normals
// point out of the solid). Copies of one lattice point are distinct vertices at equal coordinates.
struct Mesh {
    std::vector<std::array<double, 3>> vertices;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    MeshStats stats;
};

// The mesh of the union of the selected leaves of a 3D cover computed with keep_cells. An empty
// selection gives an empty mesh. Throws std::invalid_argument for a 2D cover or one without cells, and
// a LimitError when the mesh would have more than `max_triangles` triangles (0: no limit), found once the
// merged faces are known, before the triangles are made.
Mesh mesh_cover(const Cover& r, MeshSelection selection, std::uint64_t max_triangles = 0);

// Sum of the volumes of the selected leaves, from the exact grid geometry (long double sum).
double selected_volume(const Cover& r, MeshSelection selection);

// Signed volume enclosed by the mesh (divergence theorem; positive for outward orientation).
double enclosed_volume(const Mesh& mesh);

struct MeshCheck {
    bool watertight = false;          // every edge has exactly two incident triangles
    bool manifold = false;            // no edge with more than two triangles, and the triangles around each
                                      // vertex form a single fan (a disc, or a half-disc on an open boundary)
    bool oriented = false;            // every edge with two triangles is used once in each direction
    double volume = 0;                // enclosed_volume: positive when the normals point outwards
    std::uint64_t vertices = 0;       // vertices used by some triangle
    std::uint64_t unreferenced = 0;   // vertices used by none (not an error)
    std::uint64_t edges = 0;          // distinct undirected edges
    std::uint64_t boundary_edges = 0; // edges with one triangle: the rim of an open surface
    std::uint64_t faces = 0;          // triangles
    std::int64_t euler = 0;           // vertices - edges + faces
    std::uint64_t components = 0;     // connected components (through shared vertices)
    std::uint64_t degenerate = 0;     // triangles with a repeated vertex or zero area
    std::string problem;              // the first problem found, in words; empty when there is none

    // Closed, manifold, oriented outwards and without degenerate triangles: printable.
    bool ok() const {
        return watertight && manifold && oriented && degenerate == 0 && problem.empty() &&
               (faces == 0 || volume > 0);
    }
};

MeshCheck check_mesh(const Mesh& mesh);

// Writers. write_mesh picks the format by the path's extension (case-insensitive): .stl binary STL,
// .obj Wavefront OBJ (ASCII, shortest round-trip doubles, 1-based indices), .ply binary little-endian
// PLY (float x, y, z; uchar-counted int vertex_indices). STL stores float coordinates and no
// indices, so readers merge the vertex copies of split points back into one. Throw
// std::runtime_error naming the path on I/O failure (no partial file is left behind) and
// std::invalid_argument for an unknown extension.
void write_mesh(const Mesh& mesh, const std::string& path);
void write_stl(const Mesh& mesh, const std::string& path);
void write_obj(const Mesh& mesh, const std::string& path);
void write_ply(const Mesh& mesh, const std::string& path);

} // namespace frac::rt
