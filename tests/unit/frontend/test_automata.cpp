// Automata in the language: operators lowered exactly where written exactly, enclosures otherwise,
// checks located at the arc or state they are about.
#include "compile.hpp"

#include <catch2/catch.hpp>
#include <cmath>

using namespace frac;
using namespace frac::front;
using frac::test::compile_ok;
using frac::test::errors_of;

TEST_CASE("operators are exact where written exactly", "[automata]") {
    auto c =
        compile_ok("ifs t in R2 { T0 = translate(1/3, 0.1) * scale(2/3); T1 = rotate(pi/6) * scale(1/2); }");
    const ir::Automaton& a = c->module.find_automaton("t")->automaton;
    REQUIRE(a.arcs.size() == 2);
    // translate(1/3, 0.1) * scale(2/3): [[2/3, 0, 1/3], [0, 2/3, 1/10], [0, 0, 1]], exactly.
    REQUIRE(a.arcs[0].op.exact);
    const auto& m = *a.arcs[0].op.exact;
    CHECK(m(0, 0) == num::Rational(2, 3));
    CHECK(m(0, 2) == num::Rational(1, 3));
    CHECK(m(1, 2) == num::Rational(1, 10));
    CHECK(m(2, 2) == num::Rational(1));
    // rotate(pi/6): enclosures of cos and sin, each containing the true value, none exact.
    CHECK_FALSE(a.arcs[1].op.exact);
    const auto& r = a.arcs[1].op.enclosure;
    CHECK(r(0, 0).contains(0.5 * std::cos(M_PI / 6)));
    CHECK(r(1, 0).contains(0.25));
    CHECK(r(0, 1).contains(-0.25));
    CHECK(r(0, 0).lo < r(0, 0).hi);
    CHECK(a.arcs[1].op.nearest(0, 0) == Approx(0.5 * std::cos(M_PI / 6)).epsilon(1e-15));
}

TEST_CASE("a transform takes the dimension of the space it acts in", "[automata]") {
    auto c = compile_ok("ifs t in R3 { T0 = scale(1/2); T1 = translate(0, 0, 1/2) * scale(1/2); }");
    const ir::Automaton& a = c->module.find_automaton("t")->automaton;
    CHECK(a.arcs[0].op.rows() == 4);
    CHECK(a.arcs[1].op.exact->operator()(2, 3) == num::Rational(1, 2));
    CHECK(a.output_dimension() == 3);
}

TEST_CASE("controls project a barycentric space; the proof of contraction is kept", "[automata]") {
    auto c = compile_ok("cifs q { state a in R2; state b in bary(3);\n"
                        "  a -> b : controls((0, 0), (1, 2), (2, 0));\n"
                        "  b -> b : [[3/4, 1/4, 0], [1/4, 3/4, 3/4], [0, 0, 1/4]];\n"
                        "  b -> b : [[1/4, 0, 0], [3/4, 3/4, 1/4], [0, 1/4, 3/4]]; }");
    const AutomatonInfo& info = *c->module.find_automaton("q");
    const auto& p = *info.automaton.arcs[0].op.exact;
    CHECK(p.rows() == 3);
    CHECK(p(1, 1) == num::Rational(2)); // P1.y
    CHECK(p(2, 0) == num::Rational(1)); // the homogeneous row
    CHECK(info.contraction.find("contractive") != std::string::npos);
    CHECK(info.arc_locs.at(2).line == 4);
}

TEST_CASE("value checks are located at the arc", "[automata]") {
    auto c = driver::compile_source("t.frac", "ifs t in R2 {\n  T0 = scale(1/2);\n  T1 = scale(2);\n}");
    REQUIRE_FALSE(c->ok());
    const std::string e = c->diags.render(c->sources);
    CHECK(e.find("t.frac:3:3: error: 't': not contractive: the cycle t -T1-> t does not contract") !=
          std::string::npos);
}
