// Similarity dimensions of IFS and graph-directed CIFS (Moran, Mauldin–Williams) with proven brackets.
#include "runtime/automata/dimension.hpp"
#include "tests/unit/automata_examples.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace frac;
using namespace frac::test;

namespace {

void check_dimension(const ir::Automaton& a, double expected) {
    INFO(a.name);
    const rt::SimilarityDimension d = rt::similarity_dimension(a);
    INFO(d.reason);
    REQUIRE(d.defined);
    CHECK(std::abs(d.value - expected) < 1e-9);
    CHECK(d.bracket.hi - d.bracket.lo <= 1e-12);
    // The proven bracket holds the closed form (itself rounded, hence the ulps of slack).
    CHECK(d.bracket.lo <= expected + 4e-16);
    CHECK(expected - 4e-16 <= d.bracket.hi);
}

} // namespace

TEST_CASE("similarity dimensions of the classical IFS", "[automata][dimension]") {
    CHECK(std::abs(rt::similarity_dimension(sierpinski()).value - 1.584962501) < 1e-9);
    check_dimension(sierpinski(), std::log(3.0) / std::log(2.0));
    check_dimension(koch(), std::log(4.0) / std::log(3.0));
    CHECK(std::abs(rt::similarity_dimension(koch()).value - 1.261859507) < 1e-9);
    check_dimension(cantor(), std::log(2.0) / std::log(3.0));
    CHECK(std::abs(rt::similarity_dimension(cantor()).value - 0.630929754) < 1e-9);
    CHECK(rt::similarity_dimension(cantor()).method == "Moran equation");
}

TEST_CASE("Mauldin–Williams dimension of graph-directed systems", "[automata][dimension]") {
    const double phi = (1 + std::sqrt(5.0)) / 2;
    check_dimension(golden(), std::log(phi) / std::log(2.0));
    // Penrose kite and dart: M(s) = [[u, 1], [u, u]] with u = phi^-s, rho = u + sqrt(u) = 1 at s = 2.
    check_dimension(penrose(), 2.0);
    CHECK(rt::similarity_dimension(penrose()).method == "Mauldin–Williams spectral radius");
}

TEST_CASE("similarity ratios, exact and enclosed", "[automata][dimension]") {
    const auto s = rt::similarity_ratio(sierpinski(), 1);
    CHECK(s.similitude);
    CHECK(s.exact);
    CHECK(s.ratio == num::Interval(0.5, 0.5));
    const auto k = rt::similarity_ratio(koch(), 1); // rotated by 60 degrees, entries irrational
    CHECK(k.similitude);
    CHECK_FALSE(k.exact);
    CHECK(k.ratio.contains(1.0 / 3.0));
    CHECK(k.ratio.hi - k.ratio.lo < 1e-14);
    // A reflection is a similitude too.
    const auto r = rt::similarity_ratio(
        [] {
            ir::Automaton a = sierpinski();
            a.arcs[0] = arc(0, 0, affine({{0, q(1, 3)}, {q(1, 3), 0}}, {0, 0}), "flip");
            return a;
        }(),
        0);
    CHECK(r.similitude);
    CHECK(r.ratio.contains(1.0 / 3.0));
}

TEST_CASE("maps that are not similitudes get a clear answer", "[automata][dimension]") {
    const auto f = rt::similarity_dimension(fern());
    CHECK_FALSE(f.defined);
    CHECK(f.reason.find("is not a similitude") != std::string::npos);
    CHECK(f.reason.find("f1") != std::string::npos); // the stem squashes x to 0
    const auto b = rt::similarity_dimension(bspline(2, {{0, 0}, {1, 2}, {3, 2}, {4, 0}}));
    CHECK_FALSE(b.defined);
    CHECK(b.reason.find("T0b") != std::string::npos);
    CHECK(b.reason.find("not a similitude") != std::string::npos);
    CHECK(rt::similarity_ratio(fern(), 1).similitude); // 0.85 R(-2.7 degrees) scaled: a similitude
    CHECK_FALSE(rt::similarity_ratio(fern(), 2).similitude);
}

TEST_CASE("transient arcs and single cycles", "[automata][dimension]") {
    // The Sierpinski triangle seen through an injective projection arc from a new initial state keeps
    // its dimension; a state with a single loop is a point.
    ir::Automaton a = sierpinski();
    for (auto& arc : a.arcs) ++arc.to, ++arc.from;
    a.states.insert(a.states.begin(), state("top", ir::Space::euclidean(2)));
    a.arcs.push_back(arc(0, 1, affine({{2, 1}, {0, 3}}, {5, 5}), "into"));
    a.initial = 0;
    check_dimension(a, std::log(3.0) / std::log(2.0));
    ir::Automaton point;
    point.states.push_back(state("p", ir::Space::euclidean(2)));
    point.arcs.push_back(arc(0, 0, affine({{q(1, 2), 0}, {0, q(1, 2)}}, {1, 1}), "f"));
    const auto d = rt::similarity_dimension(point);
    REQUIRE(d.defined);
    CHECK(d.value == 0.0);
}
