#include "ir/graph.hpp"
#include "ir/semantics.hpp"
#include "ir/tape.hpp"

#include <cmath>
#include <memory>
#include <string>

#include <catch2/catch.hpp>

using namespace frac::ir;

TEST_CASE("hash-consing returns the same node for the same operation", "[graph]") {
    Graph g;
    const NodeId x = g.var(0), y = g.var(1);
    const NodeId a = g.op(Op::Add, x, y);
    CHECK(g.op(Op::Add, x, y) == a);
    CHECK(g.op(Op::Add, y, x) != a); // no reordering: evaluation order is the user's
    CHECK(g.var(0) == x);
    CHECK(g.constant(2.0) == g.constant(2.0));
    CHECK(g.constant(0.0) != g.constant(-0.0));
}

TEST_CASE("constant folding gives outward enclosures and point values", "[graph]") {
    Graph g;
    const NodeId third = g.op(Op::Div, g.constant(1.0), g.constant(3.0));
    REQUIRE(g.is_const(third));
    CHECK(g[third].value.lo < g[third].value.hi);
    CHECK(g[third].point == 1.0 / 3.0);
    const NodeId sq = g.op(Op::Sqrt, g.constant(4.0));
    CHECK(g[sq].value == Interval(2.0));
    const NodeId cond = g.op(Op::Lt, g.constant(1.0), g.constant(2.0));
    CHECK(g.op(Op::Select, cond, g.var(0), g.var(1)) == g.var(0));
}

TEST_CASE("every opcode has a name and an arity", "[graph]") {
#define FRAC_OP(name, ar, text, cls)                                                                         \
    CHECK(std::string(op_name(Op::name)) == text);                                                           \
    CHECK(arity(Op::name) == ar);
#include "ir/opcodes.def"
#undef FRAC_OP
}

TEST_CASE("index masks and series levels", "[graph]") {
    Graph g;
    const NodeId i = g.index(1);
    const NodeId term =
        g.op(Op::Div, g.op(Op::Dz, g.op(Op::Mul, g.op(Op::Pow, g.constant(2.0), i), g.var(0))),
             g.op(Op::Pow, g.constant(2.0), i));
    CHECK(g[term].index_mask == 2u);
    SeriesData d;
    d.level = 1;
    d.gamma = Interval(0.5);
    const NodeId s = g.series(Op::SeriesSum, d, term, g.constant(Interval(0.0, 0.5), 0.25), no_node);
    CHECK(g[s].index_mask == 0u);
    CHECK(verify_graph(g).empty());
    const Tape t = build_tape(g, s, 1);
    CHECK(verify_tape(t).empty());
    CHECK(t.series.size() == 1);
    CHECK(t.blocks.size() == 2);
    CHECK(print_tape(t).find("series_sum") != std::string::npos);
    CHECK(print_graph(g, {s}).find("series_sum level 1 in 0..inf") != std::string::npos);
}

TEST_CASE("the tape verifier catches malformed tapes", "[tape]") {
    Graph g;
    const NodeId e = g.op(Op::Add, g.var(0), g.constant(1.0));
    Tape t = build_tape(g, e, 1);
    REQUIRE(verify_tape(t).empty());
    Tape bad = t;
    bad.blocks[0][0].in[0] = bad.num_slots + 5;
    CHECK_FALSE(verify_tape(bad).empty());
    Tape twice = t;
    twice.blocks[0].push_back(twice.blocks[0][0]);
    CHECK_FALSE(verify_tape(twice).empty());
}

namespace {
// |p|: a stand-in for the runtime's distance, enough for the graph and the tape.
class Norm final : public ExternalFunction {
public:
    int arity() const override { return 2; }
    Interval eval_box(const Interval* a) const override {
        return frac::num::sqrt(frac::num::add(frac::num::sqr(a[0]), frac::num::sqr(a[1])));
    }
    double eval_point(const double* a) const override { return std::hypot(a[0], a[1]); }
    std::string name() const override { return "norm"; }
};
} // namespace

TEST_CASE("an external call is never folded, and tapes carry the bound implementations", "[graph]") {
    Graph g;
    const NodeId zero = g.constant(0.0);
    g.externals.resize(1);
    // Constant arguments: still a call (the graph cannot evaluate it).
    const NodeId c = g.external(0, g.constant(3.0), g.constant(4.0), zero);
    CHECK(g[c].op == Op::External);
    CHECK(g.external(0, g.constant(3.0), g.constant(4.0), zero) == c); // hash-consed
    CHECK(verify_graph(g).empty());
    CHECK(print_graph(g, {c}).find("external %") != std::string::npos);
    CHECK(print_graph(g, {c}).find("#0 (unbound)") != std::string::npos);
    g.externals[0] = std::make_shared<Norm>();
    const NodeId x = g.external(0, g.var(0), g.var(1), zero);
    const Tape t = build_tape(g, g.op(Op::Add, x, c), 2);
    REQUIRE(t.externals.size() == 1);
    CHECK(t.externals[0] == g.externals[0]);
    CHECK(verify_tape(t).empty());
    CHECK(print_tape(t).find("#0 norm") != std::string::npos);
    // An index outside the table is a malformed graph.
    g.external(1, g.var(0), g.var(1), zero);
    CHECK(verify_graph(g).find("external #1 out of range") != std::string::npos);
}

TEST_CASE("a product of a value with itself is its square", "[graph]") {
    Graph g;
    const NodeId x = g.var(0);
    const NodeId u = g.op(Op::Sub, x, g.constant(1.0));
    const NodeId uu = g.op(Op::Mul, u, u);
    CHECK(g[uu].op == Op::Sqr);
    CHECK(uu == g.op(Op::Sqr, u)); // one node, however it is written
    CHECK(g[g.op(Op::Mul, u, x)].op == Op::Mul);
    // Over u in [-1, 2] the square is [0, 4]; a product of independent factors would be [-2, 4].
    const Interval u_box[2] = {{-1, 2}, {-1, 2}};
    frac::num::UpwardRounding up;
    CHECK(apply_interval(g[uu].op, u_box, 0) == Interval(0, 4));
    CHECK(apply_interval(Op::Mul, u_box, 0) == Interval(-2, 4));
    const Tape t = build_tape(g, g.op(Op::Add, uu, g.constant(0.5)), 1);
    REQUIRE(t.instruction_count() == 3); // sub, sqr, add
    CHECK(t.blocks[0][1].op == Op::Sqr);
}
