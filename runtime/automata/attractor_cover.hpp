// Attractor covers by cell graphs (seed 000, sec. 2.4).
//
// The cells of a grid over a box are the vertices of a graph, with an arc from cell C to cell C'
// whenever the interval image of C under a map meets C' (so f(C) and C' may share a point). A cell
// whose vertex lies on no cycle (transient: a strongly connected component of one vertex without a
// loop) holds no point of the attractor: no orbit starting in it comes back. The non-transient cells
// cover the attractor; splitting them and rebuilding the graph on the children (the arcs only go to
// kept cells) refines the cover. Strongly connected components come from Tarjan's algorithm, written
// iteratively (graphs of millions of cells).
//
// Two inputs:
//  - a map of the plane (or space) given by its components, each an ir::Evaluator of the d
//    coordinates: the attractor of its non-divergent orbits (Hénon, Julia sets);
//  - an automaton (IFS, graph-directed IFS, euclidean or barycentric states): the vertices are
//    (state, cell) pairs, each state with its own grid in its affine coordinates (x for R2 and R3, the
//    first n - 1 weights for bary(3) and bary(4)), the initial state over the given box, the others
//    over boxes around their proven bounding balls, with an arc (b, C) -> (a, C') when the operator of
//    an arc a -> b maps C onto a set meeting C'. A barycentric initial state gets a state of the output
//    space in front, reached through the projection. Cells of states on a cycle of the automaton are
//    kept when they are recurrent; cells of a state on no cycle (a projected spline's) when a kept
//    cell maps onto them: A_a is the union of the images of its successors' attractors.
// The result is an rt::Cover of the (initial state's) attractor: at each refined level the cells that
// were kept are `subdivided` and the transient ones `outside`, at the last level the kept cells are
// `boundary`; the levels above the first graph hold the ancestors of its kept cells. So pictures,
// box-counting dimension and meshes take it like any other cover.
#pragma once

#include "ir/automaton.hpp"
#include "ir/evaluator.hpp"
#include "runtime/cover.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace frac::rt {

struct AttractorCoverOptions {
    int initial_level = 6; // the first graph is built on the 2^initial_level grid (per axis)
    int refinements = 3;   // then the kept cells are split in two per axis, this many times
    // Explicit budgets: cells of one graph (all states together) and arcs of one graph. A graph that
    // would pass either is refused (rt::LimitError, with the count or estimate) before it is built: the
    // first grid at once, each later level from the cells kept before they are split, and the last
    // level foreseen from the growth of the kept cells.
    std::uint64_t max_cells = std::uint64_t(1) << 22;
    std::uint64_t max_arcs = std::uint64_t(1) << 27;
};

// One graph: its level, its cells and arcs, the cells kept and their area (volume in 3D) for the
// initial state, and its wall time.
struct CoverStep {
    int level = 0;
    std::uint64_t cells = 0, arcs = 0, kept = 0;
    double area = 0;
    double seconds = 0;
};

struct AttractorCoverResult : Cover {
    std::vector<CoverStep> steps; // one per graph: initial_level .. initial_level + refinements
};

// The non-transient vertices of a graph in compressed form (the arcs of vertex v are
// targets[offsets[v] .. offsets[v + 1]), offsets has n + 1 entries): those on a cycle (a strongly
// connected component of several vertices, or one with a loop). Iterative Tarjan.
std::vector<bool> recurrent_vertices(const std::vector<std::uint64_t>& offsets,
                                     const std::vector<std::uint32_t>& targets);

// The attractor of the orbits of x -> (f_0(x), ..., f_{d-1}(x)) inside `root` (d = 2 or 3 axes, each
// component an evaluator of d coordinates). Throws std::invalid_argument on a bad root, component
// count or level, rt::LimitError when a budget would be exceeded.
AttractorCoverResult map_attractor_cover(const std::vector<ir::Evaluator*>& components,
                                         const std::vector<Interval>& root,
                                         const AttractorCoverOptions& options = {});

// The attractor of an automaton's initial state (through its projection when it is barycentric)
// inside `root` (empty: the box around its proven bounding ball). Every state's space must have
// dimension 2 or 3 (std::invalid_argument otherwise).
AttractorCoverResult automaton_attractor_cover(const ir::Automaton& a, const std::vector<Interval>& root,
                                               const AttractorCoverOptions& options = {});

} // namespace frac::rt
