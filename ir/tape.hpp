// The flat tape: the graph of one root scheduled into straight-line blocks of SSA instructions over a
// single slot file. Block 0 is the main code; each series has its own block, run once per term, and
// may have a block of point-only code (TapeSeries::point_block).
// Code that does not depend on a series index is hoisted out of that series' block.
#pragma once

#include "ir/graph.hpp"

#include <string>
#include <vector>

namespace frac::ir {

using Slot = std::uint32_t;
inline constexpr Slot no_slot = std::numeric_limits<Slot>::max();
inline constexpr std::uint32_t no_block = std::numeric_limits<std::uint32_t>::max();

struct Instr {
    Op op = Op::Add;
    Slot out = no_slot;
    std::array<Slot, 3> in{no_slot, no_slot, no_slot};
    std::int64_t imm = 0;
    std::uint32_t series = 0; // series ops: index into Tape::series
};

struct TapeSeries {
    Op kind = Op::SeriesSum;
    SeriesData data;
    std::uint32_t block = 0; // the block computing one term
    Slot index_slot = no_slot;
    Slot body_slot = no_slot;
    Slot tail_a = no_slot, tail_b = no_slot; // infinite series: tail coefficients (tail_b optional)
    // Infinite series: slots whose point values bound A and B (lo A, hi A, lo B, hi B), for point
    // evaluation, which cannot read bounds off tail_a / tail_b (ir/point_bounds.hpp). The code that
    // computes them and nothing else is `point_block`, which point evaluation runs before the series'
    // first term (in the enclosing block's context) and box evaluation never runs. Without them
    // (a specialised tape, made for boxes) point evaluation sums up to the term limit.
    std::array<Slot, 4> point_tail{no_slot, no_slot, no_slot, no_slot};
    std::uint32_t point_block = no_block;
    // Orbit series: the point's slots, read by the block; their initial values (computed before the
    // series) and the map's values (computed by the block), copied into state_slots after each term.
    std::vector<Slot> state_slots, init_slots, update_slots;
};

struct TapeConst {
    Slot slot;
    Interval value;
    double point;
};

struct Tape {
    int inputs = 0; // number of Var inputs (coordinates)
    Slot num_slots = 0;
    std::vector<TapeConst> constants; // preloaded slots
    std::vector<Slot> input_slots;    // slot of input k, or no_slot when unused
    std::vector<std::vector<Instr>> blocks;
    std::vector<TapeSeries> series;
    Slot result = no_slot;
    // The graph's external functions (Op::External's imm indexes them); null slots are unbound.
    std::vector<std::shared_ptr<const ExternalFunction>> externals;

    std::size_t instruction_count() const;
};

// Schedules the graph reachable from `root`. `inputs` is the number of Var inputs the root may read.
Tape build_tape(const Graph& g, NodeId root, int inputs);

std::string print_tape(const Tape& t);

// Checks that every slot is written before it is read, arities, and series block structure.
// Returns an empty string when the tape is well formed.
std::string verify_tape(const Tape& t);

} // namespace frac::ir
