// fif declarations (frontend/fif.hpp): the lowered shears against seed 001's constraints written out here
// independently — T_i(P_j) = P_(i-1) and T_i(P_k) = P_i for the linear part [[a, 0], [b, C]] with the
// given vertical scaling C — in exact rationals, for functions and curves, FIF, reflected and RFIF pieces.
#include "compile.hpp"

#include "ir/automaton.hpp"

#include <catch2/catch.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

using namespace frac;
using num::Matrix;
using num::Rational;

namespace {

// T applied to the homogeneous point (t, x[, y], 1).
std::vector<Rational> apply(const Matrix<Rational>& m, const std::vector<Rational>& p) {
    std::vector<Rational> out(m.rows(), Rational(0));
    for (std::size_t r = 0; r < m.rows(); ++r) {
        for (std::size_t c = 0; c < p.size(); ++c) out[r] = out[r] + m(r, c) * p[c];
        out[r] = out[r] + m(r, m.cols() - 1);
    }
    out.pop_back();
    return out;
}

Rational q(long n, long d = 1) {
    return Rational(n) / Rational(d);
}

// Checks every labelled arc T_i of `name`: the interpolation constraints, the shear form (first row
// (a, 0, ..., d)) and the vertical block equal to the scaling written in the model.
void check_pieces(const front::Compilation& c, const std::string& name,
                  const std::vector<std::vector<Rational>>& points,
                  const std::vector<std::array<int, 2>>& domains,
                  const std::vector<std::vector<std::vector<Rational>>>& scalings) {
    const front::AutomatonInfo* info = c.module.find_automaton(name);
    REQUIRE(info);
    std::size_t checked = 0;
    for (const ir::Arc& arc : info->automaton.arcs) {
        if (arc.label.empty()) continue;
        const std::size_t i = std::stoul(arc.label.substr(1)); // T1 ... TN
        INFO(name << " " << arc.label);
        REQUIRE(arc.op.exact);
        const Matrix<Rational>& m = *arc.op.exact;
        const auto [j, k] = domains[i - 1];
        CHECK(apply(m, points[static_cast<std::size_t>(j)]) == points[i - 1]);
        CHECK(apply(m, points[static_cast<std::size_t>(k)]) == points[i]);
        for (std::size_t col = 1; col + 1 < m.cols(); ++col) CHECK(m(0, col) == Rational(0));
        const auto& s = scalings[scalings.size() == 1 ? 0 : i - 1];
        for (std::size_t r = 0; r < s.size(); ++r)
            for (std::size_t col = 0; col < s.size(); ++col) CHECK(m(1 + r, 1 + col) == s[r][col]);
        ++checked;
    }
    CHECK(checked >= points.size() - 1);
}

} // namespace

TEST_CASE("fif: a FIF's shears interpolate its points (eq. 1)", "[fif]") {
    auto c = test::compile_ok(R"(
fif f { points (0, 0), (1/3, 1/2), (3/4, -1/5), (1, 3/10); scale 3/5, -1/2, 7/10; }
fif reflected { points (0, 0), (1/3, 1/2), (3/4, -1/5), (1, 3/10); scale 3/5, -1/2, 7/10;
                domains (0, 3), (3, 0), (0, 3); }
)");
    const std::vector<std::vector<Rational>> points = {
        {q(0), q(0)}, {q(1, 3), q(1, 2)}, {q(3, 4), q(-1, 5)}, {q(1), q(3, 10)}};
    const std::vector<std::vector<std::vector<Rational>>> scalings = {
        {{q(3, 5)}}, {{q(-1, 2)}}, {{q(7, 10)}}};
    check_pieces(*c, "f", points, {{0, 3}, {0, 3}, {0, 3}}, scalings);
    check_pieces(*c, "reflected", points, {{0, 3}, {3, 0}, {0, 3}}, scalings);
    CHECK(c->module.find_automaton("f")->automaton.states.size() == 1);
}

TEST_CASE("fif: an RFIF maps each domain's graph onto its range (eq. 4-6)", "[fif]") {
    auto c = test::compile_ok(R"(
fif r { points (0, 0), (1, 1), (2, 1/2), (3, 4/5); scale 4/5, -7/10, 9/10; domains (0, 2), (3, 1), (0, 3); }
)");
    const std::vector<std::vector<Rational>> points = {
        {q(0), q(0)}, {q(1), q(1)}, {q(2), q(1, 2)}, {q(3), q(4, 5)}};
    check_pieces(*c, "r", points, {{0, 2}, {3, 1}, {0, 3}}, {{{q(4, 5)}}, {{q(-7, 10)}}, {{q(9, 10)}}});
    // A state per range and the union; piece i leads from range i to every range its domain covers.
    const ir::Automaton& a = c->module.find_automaton("r")->automaton;
    REQUIRE(a.states.size() == 4);
    std::vector<std::vector<std::string>> targets(4);
    for (const ir::Arc& arc : a.arcs)
        if (!arc.label.empty()) targets[arc.from].push_back(a.states[arc.to].name);
    CHECK(targets[1] == std::vector<std::string>{"r1", "r2"});
    CHECK(targets[2] == std::vector<std::string>{"r2", "r3"});
    CHECK(targets[3] == std::vector<std::string>{"r1", "r2", "r3"});
}

TEST_CASE("fif: curves with the hidden variable, separable (eq. 8) and coupled (eq. 9)", "[fif]") {
    auto c = test::compile_ok(R"(
fif s { points (0, 0, 0), (1/2, 1, 1), (1, 2, 0); scale (3/10, 1/2); }
fif k { points (0, 0, 0), (1/2, 1, 1), (1, 2, 0); scale [[3/10, 1/10], [-1/10, 3/10]], [[3/10, 0], [1/5, 2/5]]; }
)");
    const std::vector<std::vector<Rational>> points = {
        {q(0), q(0), q(0)}, {q(1, 2), q(1), q(1)}, {q(1), q(2), q(0)}};
    check_pieces(*c, "s", points, {{0, 2}, {0, 2}}, {{{q(3, 10), q(0)}, {q(0), q(1, 2)}}});
    check_pieces(*c, "k", points, {{0, 2}, {0, 2}},
                 {{{q(3, 10), q(1, 10)}, {q(-1, 10), q(3, 10)}}, {{q(3, 10), q(0)}, {q(1, 5), q(2, 5)}}});
}

TEST_CASE("fif: a PFIF's states are intervals each tiled by its arcs' images (eq. 7)", "[fif]") {
    // Seed 001 Table 3 with fractions, and a PFIF whose domains end between the ranges' ends.
    auto c = test::compile_ok(R"(
fif top {
    piece [5/18, 2/3] [[-1/3, 0, 2/9],   [0, -1/2, 3/8],   [0, 0, 1]];
    piece [1/6, 1/2]  [[1/3, 0, 2/27],   [0, -1/2, 9/16],  [0, 0, 1]];
    piece [1/6, 4/9]  [[1/3, 0, 5/27],   [0, 1/2, 1/16],   [0, 0, 1]];
    piece [0, 1]      [[1/3, 0, 1/3],    [0, 1/2, 1/4],    [0, 0, 1]];
    piece [1/6, 4/9]  [[-1/3, 0, 22/27], [0, -1/2, 15/16], [0, 0, 1]];
    piece [1/6, 1/2]  [[-1/3, 0, 25/27], [0, 1/2, 7/16],   [0, 0, 1]];
    piece [5/18, 2/3] [[1/3, 0, 7/9],    [0, 1/2, 5/8],    [0, 0, 1]];
}
fif between {
    piece [1/6, 5/6] [[1/2, 0, -1/12], [0.3, 0.4, 0],     [0, 0, 1]];
    piece [0, 2/3]   [[1/2, 0, 1/3],   [-0.2, -0.5, 0.5], [0, 0, 1]];
    piece [1/3, 1]   [[1/2, 0, 1/2],   [0.1, 0.3, 0.2],   [0, 0, 1]];
}
)");
    for (const auto& [name, states] : {std::pair{"top", 8}, std::pair{"between", 6}}) {
        INFO(name);
        const ir::Automaton& a = c->module.find_automaton(name)->automaton;
        REQUIRE(a.states.size() == static_cast<std::size_t>(states));
        // A state's interval: the t of its chord's ends.
        const auto interval = [&](std::size_t s) {
            const auto& p = a.states[s].primitive.points;
            return std::pair{p(0, 0), p(0, 1)};
        };
        for (std::size_t s = 0; s < a.states.size(); ++s) {
            std::vector<std::pair<double, double>> images;
            for (const ir::Arc& arc : a.arcs) {
                if (arc.from != s) continue;
                REQUIRE(arc.op.exact);
                const auto [u, v] = interval(arc.to);
                const double at = (*arc.op.exact)(0, 0).to_double(), d = (*arc.op.exact)(0, 2).to_double();
                images.push_back(std::minmax(at * u + d, at * v + d));
            }
            std::sort(images.begin(), images.end());
            const auto [u, v] = interval(s);
            REQUIRE(!images.empty());
            CHECK(images.front().first == Approx(u).margin(1e-15));
            CHECK(images.back().second == Approx(v).margin(1e-15));
            for (std::size_t k = 1; k < images.size(); ++k)
                CHECK(images[k].first == Approx(images[k - 1].second).margin(1e-15));
        }
    }
    // Table 3's graph runs from (0, 0) to (1, 1): f(0+) = -f(2/3-)/2 + 3/8 with f(2/3-) = f(1-)/2 + 1/4 and
    // f(1-) = f(2/3-)/2 + 5/8, so f(2/3-) = 3/4, f(1-) = 1, f(0+) = 0; the chord of the whole joins them.
    const auto& chord = c->module.find_automaton("top")->automaton.states[0].primitive.points;
    CHECK(chord(1, 0) == Approx(0).margin(1e-12));
    CHECK(chord(1, 1) == Approx(1).margin(1e-12));
}
