#include "compile.hpp"
#include "ir/tape.hpp"

#include <catch2/catch.hpp>

using namespace frac;
using namespace frac::front;
using frac::test::compile_ok;
using frac::test::errors_of;

TEST_CASE("functions and lets are inlined into one hash-consed graph", "[lower]") {
    auto c = compile_ok("fn sq(a) = a * a;\nshape s(x, y) = let d = sq(x) + sq(y) in d - sq(x) - 1;");
    const ShapeInfo* s = c->module.find_shape("s");
    REQUIRE(s);
    const ir::Tape t = ir::build_tape(c->module.graph, s->root, 2);
    // x*x appears once although it is written three times (a square: a product of a node with itself).
    int squares = 0, muls = 0;
    for (const auto& ins : t.blocks[0]) {
        squares += ins.op == ir::Op::Sqr;
        muls += ins.op == ir::Op::Mul;
    }
    CHECK(squares == 2);
    CHECK(muls == 0);
    CHECK(ir::verify_tape(t).empty());
}

TEST_CASE("constants fold to outward enclosures", "[lower]") {
    auto c = compile_ok("const third = 1 / 3;\nshape s(x, y) = x - third;");
    const auto& g = c->module.graph;
    const ir::Node& root = g[c->module.find_shape("s")->root];
    REQUIRE(root.op == ir::Op::Sub);
    const ir::Node& k = g[root.args[1]];
    REQUIRE(k.op == ir::Op::Const);
    CHECK(k.value.lo <= 1.0 / 3.0);
    CHECK(k.value.hi > k.value.lo);
    CHECK(k.value.contains(1.0 / 3.0));
}

TEST_CASE("the default box and dimension of shapes", "[lower]") {
    auto c = compile_ok("shape a = x + y;\nshape b over [0, 1] × [0, 1] × [-1, 1] = x + y + z;\nshape c(u, "
                        "v) over [2, 3] × [4, 5] = u;");
    CHECK(c->module.find_shape("a")->dimension == 2);
    CHECK(c->module.find_shape("a")->box.size() == 2);
    CHECK(c->module.find_shape("b")->dimension == 3);
    CHECK(c->module.find_shape("c")->box[1].lo == 4.0);
}

TEST_CASE("series bounds: the decay and the linear growth of the devil's staircase", "[series]") {
    auto c = compile_ok("shape s(x, y) = y - sum(i in 1.., floor(i * x) / 2^i);");
    const auto& g = c->module.graph;
    const ir::Node& root = g[c->module.find_shape("s")->root];
    const ir::Node& series = g[root.args[1]];
    REQUIRE(series.op == ir::Op::SeriesSum);
    CHECK(series.series.gamma == ir::Interval(0.5));
    CHECK(series.args[2] != ir::no_node); // B: grows linearly with i
    CHECK(series.series.start == 1);
}

TEST_CASE("series bounds: the carpet decays like 3^-i with a bounded kernel", "[series]") {
    auto c = compile_ok("shape s(x, y) = min(i in 0.., (1/3 - min(dz(3^i * x), dz(3^i * y))) / 3^i);");
    const auto& g = c->module.graph;
    const ir::Node& series = g[c->module.find_shape("s")->root];
    REQUIRE(series.op == ir::Op::SeriesMin);
    CHECK(series.series.gamma.contains(1.0 / 3.0));
    CHECK(series.series.gamma.hi < 0.34);
    CHECK(series.args[2] == ir::no_node); // bounded kernel: no B
    const ir::Node& a = g[series.args[1]];
    REQUIRE(a.op == ir::Op::Const);
    CHECK(a.value.contains(ir::Interval(-1.0 / 6.0, 1.0 / 3.0)));
}

TEST_CASE("series that cannot be bounded are compile errors that say why", "[series]") {
    CHECK(errors_of("shape s(x, y) = sum(i in 0.., i * x);").find("do not decay geometrically") !=
          std::string::npos);
    CHECK(errors_of("shape s(x, y) = sum(i in 0.., 2^i);").find("do not decay geometrically") !=
          std::string::npos);
    CHECK(errors_of("shape s(x, y) = sum(i in 0.., i * (i + x) / 2^i);").find("faster than linearly") !=
          std::string::npos);
    // i * i is a square (the graph makes it one): bounded below, not above.
    CHECK(errors_of("shape s(x, y) = sum(i in 0.., i * i / 2^i);").find("the argument of sqr grows") !=
          std::string::npos);
    CHECK(errors_of("shape s(x, y) = sum(i in 0.., x^i);").find("positive constant base") !=
          std::string::npos);
    CHECK(errors_of("shape s(x, y) = sum(i in -1.., 1 / 2^i);").find("index >= 0") != std::string::npos);
}

TEST_CASE("series bounds see through CSG and if", "[series]") {
    auto c = compile_ok(
        "shape s(x, y) = sum(i in 0.., if dz(2^i * x) < 0.25 then 1 / 2^i else max(dz(x), 0.5) / 4^i);");
    const ir::Node& series = c->module.graph[c->module.find_shape("s")->root];
    CHECK(series.series.gamma == ir::Interval(0.5));
}

TEST_CASE("nested series and loop-invariant hoisting", "[series][tape]") {
    auto c =
        compile_ok("shape s(x, y) = sum(i in 0.., sum(j in 0.., dz(2^j * x) / 2^j) / 3^i + dz(y) / 3^i);");
    const ShapeInfo* s = c->module.find_shape("s");
    const ir::Tape t = ir::build_tape(c->module.graph, s->root, 2);
    REQUIRE(ir::verify_tape(t).empty());
    // The inner series does not depend on i: it is computed once, outside the outer series' block.
    REQUIRE(t.series.size() == 2);
    bool inner_in_main = false;
    for (const auto& ins : t.blocks[0])
        if (ins.op == ir::Op::SeriesSum && t.series[ins.series].data.level == 2) inner_in_main = true;
    CHECK(inner_in_main);
}

TEST_CASE("type errors are reported at the offending expression", "[lower]") {
    const std::string e =
        errors_of("shape s(x, y) = (x, y) * (x, y);\nfn f(p) = p.x;\nshape t(x, y) = f(1);");
    CHECK(e.find("t.frac:1:24: error: points multiply or divide by numbers only") != std::string::npos);
    CHECK(e.find("t.frac:2:12: error: '.x' needs a point, found a number") != std::string::npos);
}

TEST_CASE("imports of the standard library", "[driver]") {
    auto c = compile_ok("import \"fractals\";\nshape mine(x, y) = carpet(x, y);");
    CHECK(c->module.find_shape("carpet"));
    CHECK(c->module.find_shape("takagi"));
    CHECK(c->module.find_shape("mine"));
}
