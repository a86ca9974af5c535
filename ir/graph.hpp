// The expression graph: hash-consed, constant-folded nodes in topological order (an argument's id is
// always smaller than its user's). Functions and lets are inlined by the frontend before they get here.
#pragma once

#include "ir/external.hpp"
#include "numeric/interval.hpp"

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

namespace frac::num {
class Rational; // numeric/rational.hpp
} // namespace frac::num

namespace frac::ir {

using num::Interval;

enum class Op : std::uint8_t {
#define FRAC_OP(name, arity, text, cls) name,
#include "ir/opcodes.def"
#undef FRAC_OP
};

enum class OpClass : std::uint8_t { leaf, arith, logic, series };

namespace detail {
// The opcode table's columns (ir/opcodes.def), inline: the passes over tapes ask them per instruction.
inline constexpr std::uint8_t op_arity[] = {
#define FRAC_OP(name, arity, text, cls) arity,
#include "ir/opcodes.def"
#undef FRAC_OP
};
inline constexpr OpClass op_classes[] = {
#define FRAC_OP(name, arity, text, cls) OpClass::cls,
#include "ir/opcodes.def"
#undef FRAC_OP
};
} // namespace detail

inline int arity(Op op) {
    return detail::op_arity[static_cast<int>(op)];
}
const char* op_name(Op op);
inline OpClass op_class(Op op) {
    return detail::op_classes[static_cast<int>(op)];
}
inline bool is_series(Op op) {
    return op_class(op) == OpClass::series;
}

using NodeId = std::uint32_t;

// A State leaf's imm names the series level (1..max_series_level) and the component
// (0..max_state_components - 1) of its orbit point.
inline constexpr int max_series_level = 63;
inline constexpr int max_state_components = 8;
inline constexpr std::int64_t state_imm(int level, int component) {
    return std::int64_t{level} * max_state_components + component;
}
inline constexpr int state_level(std::int64_t imm) {
    return static_cast<int>(imm / max_state_components);
}
inline constexpr int state_component(std::int64_t imm) {
    return static_cast<int>(imm % max_state_components);
}
inline constexpr NodeId no_node = std::numeric_limits<NodeId>::max();
inline constexpr std::int64_t infinite_end = std::numeric_limits<std::int64_t>::max();

// What an infinite series needs for its tail: every term t_i (i >= start) lies in (A + B i) gamma^i,
// with A and B enclosed by evaluating the nodes tail_a / tail_b over the current box (B may be absent)
// and 0 < gamma < 1. A may be unbounded on one side: a min series needs only a lower bound of its
// terms, a max series only an upper bound. The frontend proves this form (frontend/series_bounds).
// An escape certificate of an orbit min (max) series, proven by the frontend (frontend/orbit_escape):
// once the orbit point q_m lies outside the ball |q| <= radius (Euclidean norm), every later term t_j
// (j >= m) of a min series satisfies t_j >= (slope (|q_m| - radius) + offset) * scale0 / growth^m; for a
// max series -t_j does. slope >= 0 and offset <= 0 are lower bounds, radius an upper bound.
struct OrbitEscape {
    bool present = false;
    double radius = 0.0;
    double slope = 0.0;
    double offset = 0.0;
    Interval scale0{1.0, 1.0};
    Interval growth{1.0, 1.0};
    // When > 0: the term of index j is lipschitz * (map_lipschitz / growth)^j - Lipschitz in the orbit's
    // initial point, and |M(q) - M(q')| <= map_lipschitz |q - q'| (Euclidean): a box may be evaluated
    // at its centre and widened (ir::lipschitz_finish).
    double lipschitz = 0.0;
    double map_lipschitz = 0.0;
    bool operator==(const OrbitEscape&) const = default;
};

struct SeriesData {
    int level = 0; // nesting level; the body reads the index with Index(level)
    std::int64_t start = 0;
    std::int64_t end = infinite_end; // inclusive; infinite_end for an infinite series
    Interval gamma{0.0, 0.0};        // decay, proven 0 < gamma.hi < 1 for infinite series
    int state_count = 0;             // orbit series: components of the orbit point
    OrbitEscape escape;              // orbit series: optional escape certificate
    // The term bound is one-sided (A infinite on one side): the tail says nothing about the value's
    // other side, so point evaluation cannot estimate the tail from A's point value.
    bool one_sided = false;
    bool operator==(const SeriesData&) const = default;
};

struct Node {
    Op op = Op::Const;
    std::array<NodeId, 3> args{no_node, no_node, no_node};
    Interval value{0.0, 0.0}; // Const: outward enclosure of the constant
    double point = 0.0;       // Const: its round-to-nearest value
    // Const: the exact value, when it is a rational the compiler knows (a literal as written, 1/3,
    // 3^20 and what folds exactly from them); value and point are then its enclosure and nearest double.
    // Null otherwise (pi, sqrt(2), an interval, a rational too large to keep).
    std::shared_ptr<const num::Rational> exact;
    std::int64_t imm = 0; // Var: input index; Index: level; PowI: exponent
    SeriesData series;    // series ops only
    // Orbit series: the initial point's components, then the map's components (of State nodes).
    std::vector<NodeId> orbit;
    // Infinite series: nodes whose point values bound A and B (ir/point_bounds.hpp): lo A, hi A, lo B,
    // hi B (no_node without B). Made by Graph::series from the tail coefficients.
    std::array<NodeId, 4> point_tail{no_node, no_node, no_node, no_node};
    // Bit L set when the node depends on the index of series level L (L >= 1); bit 0 unused.
    std::uint64_t index_mask = 0;
};

class Graph {
public:
    const Node& operator[](NodeId id) const { return chunks_[id >> chunk_bits][id & (chunk_size - 1)]; }
    std::size_t size() const { return size_; }

    NodeId constant(Interval value, double point);
    // A double is a rational: an exact constant when finite.
    NodeId constant(double exact);
    // An exact rational constant; its enclosure is taken here, when it is lowered to the graph.
    NodeId constant(const num::Rational& exact);
    // The exact value of a constant node, or null.
    const num::Rational* exact_value(NodeId id) const { return (*this)[id].exact.get(); }
    NodeId var(int index);
    NodeId index(int level);
    // Component `component` of the orbit point of the series of level `level`.
    NodeId state(int level, int component);
    // An operation; folds constants and a few identities, and returns an existing node when it has one.
    NodeId op(Op op, NodeId a, NodeId b = no_node, NodeId c = no_node, std::int64_t imm = 0);
    NodeId series(Op kind, const SeriesData& data, NodeId body, NodeId tail_a, NodeId tail_b,
                  std::vector<NodeId> orbit = {});

    // A call of external function `index` (an index into `externals`) at the point (a, b, c); a 2D
    // point passes a constant 0 as c. Never folded, even on constants.
    NodeId external(std::int64_t index, NodeId a, NodeId b, NodeId c);

    bool is_const(NodeId id) const { return (*this)[id].op == Op::Const; }

    // The implementations of the External nodes, by their imm. A slot stays null until a driver binds
    // it (driver/pipeline.cpp); tapes built afterwards carry the bound implementations.
    std::vector<std::shared_ptr<const ExternalFunction>> externals;
    // True when the node is a thin integer constant; sets `value`.
    bool const_integer(NodeId id, std::int64_t& value) const;

private:
    NodeId intern(const Node& n);
    NodeId fold(const Node& n);

    static std::uint32_t key_hash(const Node& n);
    static bool same_key(const Node& a, const Node& b);
    void grow_index();

    // The nodes, in chunks of chunk_size (the first grows up to it): a large graph grows without moving
    // the nodes it has.
    static constexpr unsigned chunk_bits = 12;
    static constexpr std::size_t chunk_size = std::size_t{1} << chunk_bits;
    std::vector<std::vector<Node>> chunks_;
    std::size_t size_ = 0;
    // Hash-consing: an open-addressing table (a power of two in size, at most half full) of node ids
    // (no_node where empty) with their hashes, so that probing and growing read no node but a match.
    struct Slot {
        NodeId id = no_node;
        std::uint32_t hash = 0;
    };
    std::vector<Slot> index_;
};

// Text form of the sub-graph reachable from `roots`, one node a line ("%4 = add %2, %3").
std::string print_graph(const Graph& g, const std::vector<NodeId>& roots);
// " #k name" of external function k, for the printers of the graph and the tape.
std::string external_text(std::int64_t index,
                          const std::vector<std::shared_ptr<const ExternalFunction>>& table);
// The text of an escape certificate, for the printers of the graph and the tape.
std::string escape_text(const OrbitEscape& e);

// Structural checks (arities, topological order, index levels, series invariants).
// Returns an empty string when the graph is well formed, else a description of the first defect.
std::string verify_graph(const Graph& g);

} // namespace frac::ir
