// The evaluation tree of an automaton (seed 002 sec. 2, Fig. 1/3/5): the root is the initial state;
// a node at depth k is a path of k arcs from it, with the composite operator T_1 ... T_k mapping the
// space of the path's last state into the initial state's space. The leaves (depth n, or a state
// without arcs) draw their state's primitive through that operator (and the projection).
//
// The tree is streamed: a depth-first walk keeps one composite per level, so memory is O(depth)
// whatever the number of nodes (sum of out-degrees^k).
#pragma once

#include "ir/automaton.hpp"
#include "runtime/picture.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

namespace frac::rt {

struct TreeNode {
    int depth = 0;
    const std::vector<std::size_t>* address = nullptr; // the arcs from the root (address->size() == depth)
    std::size_t state = 0;                             // the last state of the path
    const num::Matrix<double>* op = nullptr;           // composite: space of `state` -> initial space
    const num::Matrix<num::Interval>* enclosure = nullptr; // its outward enclosure, when asked for
    bool leaf = false;
};

struct TreeOptions {
    int depth = 3;          // in [0, 64]
    bool intervals = false; // also compose the enclosures (outward rounded)
};

struct TreeStats {
    std::uint64_t nodes = 0, leaves = 0;
    std::size_t stack_bytes = 0; // the walk's own storage for composites and the address (O(depth))
};

// The size of the tree to `depth`, counted level by level over the states before any walk (in doubles:
// no overflow, however many nodes): its nodes, its leaves and the bytes of its SVG drawing
// (write_tree_svg, about). Throws std::invalid_argument as walk_tree does.
struct TreeSize {
    double nodes = 0, leaves = 0, svg_bytes = 0;
};
TreeSize tree_size(const ir::Automaton& a, int depth);
// The most nodes of a tree frac walks unless raised (--max-cells or FRAC_MAX_CELLS): some 10 s of work.
inline constexpr std::uint64_t default_max_tree_nodes = std::uint64_t{1} << 25;

// Visits every node in depth-first order, children in arc order; the references in a node are valid
// during the call only. Throws std::invalid_argument for a depth outside [0, 64] or an automaton whose
// arcs do not fit its states (run ir::check_automaton first).
TreeStats walk_tree(const ir::Automaton& a, const TreeOptions& options,
                    const std::function<void(const TreeNode&)>& visit);

// The text dump (--emit=tree): one line per node, indented by depth: the arc taken, the state reached
// and, with `matrices`, the composite operator's rows.
void write_tree_text(const ir::Automaton& a, int depth, std::ostream& out, bool matrices = true);
std::string tree_text(const ir::Automaton& a, int depth, bool matrices = true);

// Drawing of the leaves: each leaf's primitive (points, polyline, closed polygon; a state without
// a drawable primitive shows its attractor point) mapped to the output space and seen from above
// (x, y; a 1D output is drawn on y = 0), one colour per state. The view is the bounding box of what
// is drawn, found by a first walk. `pixels` in [16, 16384] is the longer side.
Image draw_tree(const ir::Automaton& a, int depth, int pixels = 1024);
void write_tree_png(const ir::Automaton& a, int depth, const std::string& path, int pixels = 1024);
// SVG: polylines, polygons and dots in a 1024-unit view; curves come out as polylines.
void write_tree_svg(const ir::Automaton& a, int depth, const std::string& path);

// The colour of a state in pictures (a fixed palette, cycled).
std::array<std::uint8_t, 3> state_colour(std::size_t state);

} // namespace frac::rt
