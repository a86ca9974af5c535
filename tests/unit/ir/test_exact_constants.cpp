// Constants keep their exact value where it is rational: literals as written, and what folds exactly
// from them; the enclosure is taken from the exact value (the tightest), the point value is its
// nearest double.
#include "ir/graph.hpp"
#include "ir/semantics.hpp"
#include "numeric/rational.hpp"

#include <catch2/catch.hpp>

using namespace frac;
using frac::ir::Graph;
using frac::ir::NodeId;
using frac::ir::Op;
using frac::num::Rational;

TEST_CASE("exact constants fold exactly: 1/3 + 1/6 is 1/2", "[graph][exact]") {
    Graph g;
    const NodeId third = g.op(Op::Div, g.constant(1.0), g.constant(3.0));
    const NodeId sixth = g.op(Op::Div, g.constant(1.0), g.constant(6.0));
    REQUIRE(g.exact_value(third) != nullptr);
    CHECK(*g.exact_value(third) == Rational(1, 3));
    const NodeId half = g.op(Op::Add, third, sixth);
    REQUIRE(g.exact_value(half) != nullptr);
    CHECK(*g.exact_value(half) == Rational(1, 2));
    // Interval folding would give a few ulps around 1/2; the exact value gives the thin 1/2.
    CHECK(g[half].value == ir::Interval(0.5));
    CHECK(g[half].point == 0.5);
    CHECK(g[third].value == num::enclose(Rational(1, 3)));
}

TEST_CASE("powers, floors and comparisons of exact constants are exact", "[graph][exact]") {
    Graph g;
    const NodeId p = g.op(Op::PowI, g.constant(3.0), ir::no_node, ir::no_node, 20);
    REQUIRE(g.exact_value(p) != nullptr);
    CHECK(*g.exact_value(p) == Rational(3486784401L));
    const NodeId tenth = g.constant(*Rational::parse_decimal("0.1"));
    const NodeId three_tenths = g.op(Op::Mul, tenth, g.constant(3.0));
    CHECK(*g.exact_value(three_tenths) == Rational(3, 10));
    // 0.1 * 3 == 0.3 exactly, though the doubles differ.
    const NodeId eq = g.op(Op::Eq, three_tenths, g.constant(*Rational::parse_decimal("0.3")));
    CHECK(g[eq].value == ir::tv_true);
    CHECK(*g.exact_value(g.op(Op::Dz, g.constant(*Rational::parse_decimal("2.7")))) == Rational(3, 10));
    CHECK(*g.exact_value(g.op(Op::Floor, g.op(Op::Neg, tenth))) == Rational(-1));
}

TEST_CASE("what is not rational, or too large, is enclosed as before", "[graph][exact]") {
    Graph g;
    const NodeId two = g.constant(2.0);
    CHECK(g.exact_value(g.op(Op::Sqrt, two)) == nullptr);                                 // irrational
    CHECK(g.exact_value(g.op(Op::Div, two, g.constant(0.0))) == nullptr);                 // not a number
    CHECK(g.exact_value(g.op(Op::PowI, two, ir::no_node, ir::no_node, 9000)) == nullptr); // too large
    CHECK(g.exact_value(g.constant(ir::Interval(0.0, 1.0), 0.5)) == nullptr);             // an interval
    CHECK(g.exact_value(g.constant(-0.0)) == nullptr);                                    // -0 keeps its sign
}
