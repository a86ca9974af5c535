// The pruning pass on hand-built tapes: which choices are recorded, and what the pruned tape keeps.
#include "ir/graph.hpp"
#include "ir/semantics.hpp"
#include "ir/specialize.hpp"
#include "ir/tape.hpp"

#include <catch2/catch.hpp>

using namespace frac;
using namespace frac::ir;

namespace {

// The register file of block 0 over a box (no series in these tapes), under upward rounding.
std::vector<Interval> registers(const Tape& t, const std::vector<Interval>& box) {
    num::UpwardRounding up;
    std::vector<Interval> r(t.num_slots);
    for (const TapeConst& c : t.constants) r[c.slot] = c.value;
    for (std::size_t k = 0; k < box.size(); ++k)
        if (t.input_slots[k] != no_slot) r[t.input_slots[k]] = box[k];
    for (const Instr& ins : t.blocks[0]) {
        Interval a[3];
        for (int i = 0; i < arity(ins.op); ++i) a[i] = r[ins.in[static_cast<std::size_t>(i)]];
        r[ins.out] = apply_interval(ins.op, a, ins.imm);
    }
    return r;
}

std::vector<Choice> choices_over(const Tape& t, const std::vector<Interval>& box) {
    return record_choices(t, registers(t, box).data());
}

} // namespace

TEST_CASE("a min whose operands are disjoint keeps the smaller one", "[specialize]") {
    Graph g;
    const NodeId x = g.var(0), y = g.var(1);
    const NodeId far = g.op(Op::Add, g.op(Op::Mul, y, y), g.constant(10.0)); // y^2 + 10
    const NodeId near = g.op(Op::Sub, x, g.constant(1.0));
    const Tape t = build_tape(g, g.op(Op::Min, near, far), 2);
    REQUIRE(has_choices(t));

    const std::vector<Choice> c = choices_over(t, {{0, 1}, {-1, 1}});
    REQUIRE(any_decided(c));
    const Tape p = specialize(t, c);
    CHECK(verify_tape(p).empty());
    CHECK(p.instruction_count() == 1); // x - 1
    CHECK(p.blocks[0][0].op == Op::Sub);
    CHECK(p.input_slots[1] == no_slot); // y is no longer read
    CHECK(tape_cost(p) < tape_cost(t));
    // Overlapping operands decide nothing.
    CHECK_FALSE(any_decided(choices_over(t, {{0, 20}, {-1, 1}})));
}

TEST_CASE("an operand that can become empty below is never dropped", "[specialize]") {
    Graph g;
    const NodeId x = g.var(0), y = g.var(1);
    const NodeId low = g.op(Op::Sub, x, g.constant(10.0));
    const Tape t = build_tape(g, g.op(Op::Min, low, g.op(Op::Sqrt, y)), 2);
    CHECK_FALSE(any_decided(choices_over(t, {{0, 1}, {-1, 1}}))); // sqrt(y) is empty for y < 0
    CHECK(any_decided(choices_over(t, {{0, 1}, {0, 1}})));        // ... and defined on [0, 1]
    const Tape d = build_tape(g, g.op(Op::Min, low, g.op(Op::Div, g.constant(1.0), y)), 2);
    CHECK_FALSE(any_decided(choices_over(d, {{0, 1}, {-1, 1}}))); // 1 / [0, 0] is empty
    CHECK(any_decided(choices_over(d, {{0, 1}, {0.5, 1}})));
}

TEST_CASE("a decided select keeps one branch, an undecided one keeps both", "[specialize]") {
    Graph g;
    const NodeId x = g.var(0), y = g.var(1);
    const NodeId cond = g.op(Op::Lt, x, g.constant(0.0));
    const NodeId then_value = g.op(Op::Mul, y, g.constant(3.0));
    const NodeId else_value = g.op(Op::Add, g.op(Op::Sqr, x), g.op(Op::Sqr, y));
    const Tape t = build_tape(g, g.op(Op::Select, cond, then_value, else_value), 2);
    const Tape left = specialize(t, choices_over(t, {{-2, -1}, {0, 1}}));
    CHECK(left.instruction_count() == 1);
    CHECK(left.blocks[0][0].op == Op::Mul);
    const Tape right = specialize(t, choices_over(t, {{1, 2}, {0, 1}}));
    CHECK(right.instruction_count() == 3);
    CHECK_FALSE(any_decided(choices_over(t, {{-1, 1}, {0, 1}})));
}

TEST_CASE("pruning to the same function gives the same tape", "[specialize]") {
    Graph g;
    const NodeId x = g.var(0), y = g.var(1);
    const NodeId a = g.op(Op::Sub, x, g.constant(5.0));
    const NodeId b = g.op(Op::Sqr, y);
    const NodeId c = g.op(Op::Add, y, g.constant(100.0));
    // min(min(a, b), c): over x in [0, 1], y in [-1, 1] both mins keep a.
    const Tape t = build_tape(g, g.op(Op::Min, g.op(Op::Min, a, b), c), 2);
    const std::vector<Choice> all = choices_over(t, {{0, 1}, {-1, 1}});
    std::vector<Choice> outer_only = all;
    for (std::size_t k = 0; k < t.blocks[0].size(); ++k)
        if (t.blocks[0][k].out != t.result) outer_only[k] = Choice::both;
    const Tape p1 = specialize(t, all);
    const Tape p2 =
        specialize(specialize(t, outer_only), choices_over(specialize(t, outer_only), {{0, 1}, {-1, 1}}));
    CHECK(p1.instruction_count() == 1);
    CHECK(tape_key(p1) == tape_key(p2));
    CHECK_THROWS_AS(specialize(t, std::vector<Choice>(1)), std::invalid_argument);
}
