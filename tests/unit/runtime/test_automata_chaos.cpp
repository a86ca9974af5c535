// The chaos game: reproducible streams, probabilities, graph-directed automata, threads.
#include "runtime/automata/chaos.hpp"
#include "runtime/automata/tabulate.hpp"
#include "runtime/dimension.hpp"
#include "tests/unit/automata_examples.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>

using namespace frac;
using namespace frac::test;

TEST_CASE("xoshiro256** streams are fixed by seed and stream", "[automata][chaos]") {
    rt::Xoshiro256 a(42), b(42), c(43), d(42, 1);
    std::uint64_t first = 0;
    for (int i = 0; i < 1000; ++i) {
        const std::uint64_t x = a();
        CHECK(x == b());
        if (i == 0) first = x;
    }
    CHECK(first != c());
    CHECK(first != d());
    // Thresholds split [0, 2^64) in proportion.
    const auto t = rt::draw_thresholds({1, 1, 2});
    CHECK(t[0] == (std::uint64_t{1} << 62) - 1);
    CHECK(t[1] == (std::uint64_t{1} << 63) - 1);
    CHECK(t[2] == UINT64_MAX);
}

TEST_CASE("probabilities: the model's, else from determinants with a floor", "[automata][chaos]") {
    const auto p = rt::chaos_probabilities(fern());
    const double dets[] = {0.0, 0.85 * 0.85 + 0.04 * 0.04, 0.2 * 0.22 + 0.26 * 0.23,
                           0.15 * 0.24 + 0.28 * 0.26};
    const double floor = 0.01 * dets[1];
    const double total = floor + dets[1] + dets[2] + dets[3];
    CHECK(p[0] == Approx(floor / total).epsilon(1e-12));
    CHECK(p[1] == Approx(dets[1] / total).epsilon(1e-12));
    CHECK(p[3] == Approx(dets[3] / total).epsilon(1e-12));
    ir::Automaton given = sierpinski();
    given.arcs[0].probability = 2;
    given.arcs[1].probability = 1;
    given.arcs[2].probability = 1;
    CHECK(rt::chaos_probabilities(given) == std::vector<double>{0.5, 0.25, 0.25});
    given.arcs[0].probability = -1;
    CHECK_THROWS_WITH(rt::chaos_probabilities(given), Catch::Contains("probability -1"));
}

TEST_CASE("chaos-game points lie on the Sierpinski triangle and miss its holes", "[automata][chaos]") {
    std::uint64_t n = 0;
    rt::chaos_points(sierpinski(), 20000, 100, 7, [&](const std::vector<double>& p) {
        ++n;
        REQUIRE(p.size() == 2);
        CHECK(p[1] >= -1e-12);
        CHECK(p[1] <= 2 * p[0] + 1e-12);
        CHECK(p[1] <= 2 * (1 - p[0]) + 1e-12);
        // The central hole: below y = 1/2, between the lines through (1/2, 0).
        CHECK_FALSE((p[1] < 0.5 - 1e-9 && p[1] > 2 * std::abs(p[0] - 0.5) + 1e-9));
    });
    CHECK(n == 20000);
    rt::ChaosOptions o;
    o.points = 200000;
    o.width = 64;
    o.box = std::array<double, 4>{0, 1, 0, 1};
    const rt::Density d = rt::chaos_game(sierpinski(), o);
    CHECK(d.height == 64);
    CHECK(d.outside == 0);
    CHECK(d.recorded == 200000);
    CHECK(d.count(32, 19) == 0); // (0.5, 0.3): in the hole
    CHECK(d.count(2, 1) > 0);    // near the corner (0, 0)
    CHECK(d.count(60, 60) == 0); // outside the triangle
}

TEST_CASE("the same seed and thread count give the same density", "[automata][chaos]") {
    rt::ChaosOptions o;
    o.points = 100000;
    o.width = 128;
    o.seed = 11;
    const rt::Density a = rt::chaos_game(fern(), o), b = rt::chaos_game(fern(), o);
    CHECK(a.counts == b.counts);
    CHECK(a.x0 == b.x0);
    o.threads = 2;
    const rt::Density c = rt::chaos_game(fern(), o), e = rt::chaos_game(fern(), o);
    CHECK(c.counts == e.counts);
    CHECK(c.recorded + c.outside == 100000);
    CHECK(c.counts != a.counts); // other streams
    o.seed = 12;
    o.threads = 1;
    CHECK(rt::chaos_game(fern(), o).counts != a.counts);
    // The default box holds the fern (about [-2.2, 2.7] x [0, 10]).
    CHECK(a.x0 < -2.1);
    CHECK(a.x1 > 2.6);
    CHECK(a.y1 > 9.9);
    CHECK(a.outside < 100);
}

namespace {

// How far chaos-game points stray from a curve tabulated at 2^12 parameters, and their x range.
struct Spread {
    double worst = 0, xmin = 1e9, xmax = -1e9;
};

Spread spread_from_curve(const ir::Automaton& a) {
    const rt::Tabulation curve =
        rt::tabulate(a, 12 / static_cast<int>(std::log2(a.arcs_from(a.initial).size())));
    Spread s;
    rt::chaos_points(a, 2000, 50, 3, [&](const std::vector<double>& p) {
        double best = 1e9;
        for (const auto& c : curve.values) best = std::min(best, std::hypot(p[0] - c[0], p[1] - c[1]));
        s.worst = std::max(s.worst, best);
        s.xmin = std::min(s.xmin, p[0]), s.xmax = std::max(s.xmax, p[0]);
    });
    return s;
}

} // namespace

TEST_CASE("graph-directed chaos: B-splines through a transient or a barycentric initial state",
          "[automata][chaos]") {
    // A CIFS whose initial state a is transient: every point lies on the curve, both segments are
    // visited (the curve runs from (0.5, 1) to (3.5, 1)).
    const Spread cifs = spread_from_curve(bspline(2, {{0, 0}, {1, 2}, {3, 2}, {4, 0}}));
    CHECK(cifs.worst < 5e-3);
    CHECK(cifs.xmin < 0.7);
    CHECK(cifs.xmax > 3.3);
    // A projected IFS: the points are projected by the control points (from (1, 2) to (4, 2.5)).
    const Spread projected = spread_from_curve(projected_quadratic({{0, 0}, {2, 4}, {6, 1}}));
    CHECK(projected.worst < 5e-3);
    CHECK(projected.xmin < 1.2);
    CHECK(projected.xmax > 3.8);
}

TEST_CASE("chaos game errors and the density picture", "[automata][chaos]") {
    ir::Automaton dead = golden();
    dead.arcs.pop_back();
    CHECK_THROWS_WITH(rt::chaos_game(dead), Catch::Contains("state b has no transitions"));
    rt::ChaosOptions o;
    o.threads = 0;
    CHECK_THROWS_WITH(rt::chaos_game(sierpinski(), o), Catch::Contains("threads 0"));
    o.threads = 1;
    o.points = 50000;
    o.width = 100;
    const rt::Density d = rt::chaos_game(cantor(), o);
    CHECK(d.height >= 1);
    const rt::Image img = rt::density_image(d);
    CHECK(img.width == 100);
    const auto path = std::filesystem::temp_directory_path() / "frac_chaos_cantor.png";
    rt::write_density_png(d, path.string());
    CHECK(std::filesystem::file_size(path) > 50);
    std::filesystem::remove(path);
}

TEST_CASE("chaos-game covers: box counting agrees with the similarity dimension", "[automata][chaos]") {
    rt::ChaosOptions o;
    o.points = 2'000'000;
    o.seed = 9;
    const rt::Cover c = rt::chaos_cover(sierpinski(), 9, o);
    CHECK(c.depth == 9);
    CHECK(c.levels[0].undecided == 1);
    CHECK(c.cells.size() == c.evaluated);
    const rt::DimensionEstimate e = rt::box_counting(c, 3, 8);
    CHECK(std::abs(e.dimension - std::log(3.0) / std::log(2.0)) < 0.05);
    // The Koch curve and the Cantor set too.
    const rt::DimensionEstimate k = rt::box_counting(rt::chaos_cover(koch(), 9, o, false), 3, 8);
    CHECK(std::abs(k.dimension - std::log(4.0) / std::log(3.0)) < 0.05);
    o.width = 100;
    CHECK_THROWS_WITH(rt::density_cover(rt::chaos_game(cantor(), o)), Catch::Contains("2^k x 2^k"));
}

TEST_CASE("graph-directed chaos on a reducible automaton keeps sampling every part", "[automata][chaos]") {
    // A_F = A_F / 2  u  (A_S / 2 + 1/2), A_S the Cantor set: once a path enters S it never returns to
    // F, yet half of A_F's measure lies on the Cantor copy in [1/2, 1] (the seed 004 fern with a
    // Sierpinski state has this shape).
    ir::Automaton a;
    a.states.push_back(state("F", ir::Space::euclidean(1)));
    a.states.push_back(state("S", ir::Space::euclidean(1)));
    a.arcs.push_back(arc(0, 0, affine({{q(1, 2)}}, {0}), "half"));
    a.arcs.push_back(arc(0, 1, affine({{q(1, 2)}}, {q(1, 2)}), "cantor"));
    a.arcs.push_back(arc(1, 1, affine({{q(1, 3)}}, {0}), "c0"));
    a.arcs.push_back(arc(1, 1, affine({{q(1, 3)}}, {q(2, 3)}), "c1"));
    std::uint64_t right = 0, total = 0;
    rt::chaos_points(a, 100000, 100, 5, [&](const std::vector<double>& p) {
        ++total;
        if (p[0] < 0.5) return;
        ++right;
        // 2x - 1 lies in the Cantor set: in a kept third at each of the first five levels.
        double y = 2 * p[0] - 1;
        for (int k = 0; k < 5; ++k) {
            const bool kept = y <= 1.0 / 3 + 1e-9 || y >= 2.0 / 3 - 1e-9;
            CHECK(kept);
            y = y <= 0.5 ? 3 * y : 3 * y - 2;
        }
    });
    CHECK(total == 100000);
    CHECK(std::abs(static_cast<double>(right) / 100000 - 0.5) < 0.01);
}
