// Attractor covers by cell graphs (seed 000 sec. 2.4): Hénon, a Julia set, IFS and graph-directed IFS.
#include "attractor_systems.hpp"
#include "backend/interp/interpreter.hpp"
#include "driver/pipeline.hpp"
#include "ir/tape.hpp"
#include "runtime/automata/attractor_cover.hpp"
#include "runtime/automata/chaos.hpp"
#include "runtime/dimension.hpp"
#include "runtime/limits.hpp"
#include "tests/unit/automata_examples.hpp"

#include <catch2/catch.hpp>

#include <complex>
#include <random>
#include <set>

using namespace frac;

namespace {

// The components of a plane map, compiled from Frac shapes and run by the interpreter.
struct PlaneMap {
    std::unique_ptr<front::Compilation> c;
    std::vector<std::unique_ptr<ir::Evaluator>> evaluators;
    std::vector<ir::Evaluator*> components() const {
        std::vector<ir::Evaluator*> out;
        for (const auto& e : evaluators) out.push_back(e.get());
        return out;
    }
};

PlaneMap compile_map(const std::string& source, std::initializer_list<const char*> names) {
    PlaneMap m;
    m.c = driver::compile_source("map.frac", source);
    REQUIRE(m.c->ok());
    for (const char* n : names) {
        const front::ShapeInfo* s = m.c->module.find_shape(n);
        REQUIRE(s);
        m.evaluators.push_back(
            interp::make_interpreter(ir::build_tape(m.c->module.graph, s->root, s->dimension)));
    }
    return m;
}

const char* const henon = "shape hx(x, y) = 1 + y - 1.4 * x^2;\nshape hy(x, y) = 0.3 * x;";

rt::AttractorCoverResult map_cover(const PlaneMap& m, const std::vector<num::Interval>& root,
                                   int initial_level, int refinements) {
    rt::AttractorCoverOptions o;
    o.initial_level = initial_level;
    o.refinements = refinements;
    return rt::map_attractor_cover(m.components(), root, o);
}

// Whether the point lies in a cell of the cover's last level that was kept (a closed cell).
class KeptCells {
public:
    explicit KeptCells(const rt::Cover& c) : cover_(c) {
        for (const rt::Cell& cell : c.cells)
            if (cell.level == c.depth && cell.cls == rt::CellClass::boundary)
                kept_.insert({cell.ix, cell.iy});
    }
    bool contains(double x, double y) const {
        const double n = static_cast<double>(cover_.cells_per_axis(cover_.depth));
        const auto ix = static_cast<long>(
            std::floor((x - cover_.root[0].lo) / (cover_.root[0].hi - cover_.root[0].lo) * n));
        const auto iy = static_cast<long>(
            std::floor((y - cover_.root[1].lo) / (cover_.root[1].hi - cover_.root[1].lo) * n));
        for (long dy = -1; dy <= 1; ++dy)
            for (long dx = -1; dx <= 1; ++dx) {
                if (ix + dx < 0 || iy + dy < 0) continue;
                const auto key =
                    std::pair{static_cast<std::uint32_t>(ix + dx), static_cast<std::uint32_t>(iy + dy)};
                if (!kept_.count(key)) continue;
                rt::Cell cell{static_cast<std::uint8_t>(cover_.depth), rt::CellClass::boundary, key.first,
                              key.second, 0};
                if (cover_.cell_interval(cell, 0).contains(x) && cover_.cell_interval(cell, 1).contains(y))
                    return true;
            }
        return false;
    }
    std::size_t size() const { return kept_.size(); }

private:
    const rt::Cover& cover_;
    std::set<std::pair<std::uint32_t, std::uint32_t>> kept_;
};

} // namespace

TEST_CASE("iterative Tarjan finds the vertices on cycles", "[cover]") {
    // 0 -> 1 -> 2 -> 0 (a cycle), 3 -> 3 (a loop), 4 -> 0 (transient), 5 (isolated), 6 -> 7 -> 6.
    const std::vector<std::vector<std::uint32_t>> adj{{1}, {2}, {0}, {3}, {0}, {}, {7}, {6}};
    std::vector<std::uint64_t> offsets{0};
    std::vector<std::uint32_t> targets;
    for (const auto& a : adj) {
        targets.insert(targets.end(), a.begin(), a.end());
        offsets.push_back(targets.size());
    }
    const std::vector<bool> r = rt::recurrent_vertices(offsets, targets);
    CHECK(r == std::vector<bool>{true, true, true, true, false, false, true, true});
    // A long path with a cycle at its end: no recursion, so no stack overflow on a million vertices.
    const std::uint32_t n = 1000000;
    offsets.assign(1, 0), targets.clear();
    for (std::uint32_t v = 0; v < n; ++v) {
        targets.push_back(v + 1 < n ? v + 1 : n - 2);
        offsets.push_back(targets.size());
    }
    const std::vector<bool> big = rt::recurrent_vertices(offsets, targets);
    CHECK_FALSE(big[0]);
    CHECK_FALSE(big[n - 3]);
    CHECK(big[n - 2]);
    CHECK(big[n - 1]);
}

TEST_CASE("the Hénon cover holds the orbit and shrinks at each refinement", "[cover]") {
    const PlaneMap h = compile_map(henon, {"hx", "hy"});
    const rt::AttractorCoverResult c = map_cover(h, {{-1.5, 1.5}, {-0.5, 0.5}}, 6, 3);
    REQUIRE(c.steps.size() == 4);
    CHECK(c.depth == 9);
    for (std::size_t i = 1; i < c.steps.size(); ++i) {
        INFO("step " << i << ": " << c.steps[i - 1].area << " -> " << c.steps[i].area);
        CHECK(c.steps[i].area < c.steps[i - 1].area);
    }
    const KeptCells kept(c);
    CHECK(kept.size() == c.steps.back().kept);
    double x = 0, y = 0;
    for (int i = 0; i < 1000; ++i) {
        const double nx = 1 + y - 1.4 * x * x;
        y = 0.3 * x, x = nx;
    }
    std::size_t missed = 0;
    for (int i = 0; i < 1000000; ++i) {
        const double nx = 1 + y - 1.4 * x * x;
        y = 0.3 * x, x = nx;
        if (!kept.contains(x, y)) ++missed;
    }
    CHECK(missed == 0);
    // Thin: far less than the box.
    CHECK(c.steps.back().area < 0.1 * 3.0);
}

TEST_CASE("a Julia set cover holds the points of inverse iteration", "[cover]") {
    // z^2 + c with c = -0.12 + 0.75i (Douady's rabbit).
    const PlaneMap j =
        compile_map("shape re(x, y) = x^2 - y^2 - 0.12;\nshape im(x, y) = 2 * x * y + 0.75;", {"re", "im"});
    const rt::AttractorCoverResult cover = map_cover(j, {{-2, 2}, {-2, 2}}, 6, 2);
    for (std::size_t i = 1; i < cover.steps.size(); ++i) CHECK(cover.steps[i].area < cover.steps[i - 1].area);
    const KeptCells kept(cover);
    // Backward orbits converge to the Julia set: z <- +-sqrt(z - c).
    const std::complex<double> c(-0.12, 0.75);
    std::complex<double> z(1, 1);
    std::mt19937_64 rng(1);
    std::size_t missed = 0;
    for (int i = 0; i < 100000; ++i) {
        z = std::sqrt(z - c) * (rng() & 1 ? 1.0 : -1.0);
        if (i > 100 && !kept.contains(z.real(), z.imag())) ++missed;
    }
    CHECK(missed == 0);
}

TEST_CASE("the Sierpinski cover holds the chaos game and has its dimension", "[cover]") {
    const ir::Automaton s = rt::test::sierpinski();
    rt::AttractorCoverOptions o;
    o.initial_level = 3;
    o.refinements = 6;
    const rt::AttractorCoverResult c = rt::automaton_attractor_cover(s, {{0, 1}, {0, 1}}, o);
    CHECK(c.depth == 9);
    const KeptCells kept(c);
    std::mt19937_64 rng(2);
    double x = 0.3, y = 0.3;
    std::size_t missed = 0;
    for (int i = 0; i < 100000; ++i) {
        const auto& m = s.arcs[rng() % 3].op.nearest;
        const double nx = m(0, 0) * x + m(0, 1) * y + m(0, 2), ny = m(1, 0) * x + m(1, 1) * y + m(1, 2);
        x = nx, y = ny;
        if (i > 20 && !kept.contains(x, y)) ++missed;
    }
    CHECK(missed == 0);
    const rt::DimensionEstimate e = rt::box_counting(c, 4, 9);
    std::string counts;
    for (const auto& [level, count] : e.counts) counts += " " + std::to_string(count);
    INFO("dimension " << e.dimension << ", counts" << counts);
    CHECK(e.dimension == Approx(std::log(3.0) / std::log(2.0)).margin(0.05));
}

TEST_CASE("a graph-directed cover holds its chaos game", "[cover]") {
    const ir::Automaton a = rt::test::two_state();
    rt::AttractorCoverOptions o;
    o.initial_level = 4;
    o.refinements = 4;
    const rt::AttractorCoverResult c = rt::automaton_attractor_cover(a, {}, o);
    const KeptCells kept(c);
    std::mt19937_64 rng(4);
    double x = 0, y = 0;
    std::size_t state = 0, missed = 0, checked = 0;
    for (int i = 0; i < 100000; ++i) {
        std::vector<std::size_t> in; // arcs a -> state: a point of A_state maps into A_a
        for (std::size_t k = 0; k < a.arcs.size(); ++k)
            if (a.arcs[k].to == state) in.push_back(k);
        const ir::Arc& arc = a.arcs[in[rng() % in.size()]];
        const auto& m = arc.op.nearest;
        const double nx = m(0, 0) * x + m(0, 1) * y + m(0, 2), ny = m(1, 0) * x + m(1, 1) * y + m(1, 2);
        x = nx, y = ny, state = arc.from;
        if (i > 50 && state == a.initial) ++checked, missed += kept.contains(x, y) ? 0 : 1;
    }
    CHECK(checked > 10000);
    CHECK(missed == 0);
    for (std::size_t i = 1; i < c.steps.size(); ++i) CHECK(c.steps[i].area <= c.steps[i - 1].area);
}

TEST_CASE("a cover in R3: the Sierpinski tetrahedron", "[cover]") {
    const ir::Automaton t = rt::test::tetrahedron();
    rt::AttractorCoverOptions o;
    o.initial_level = 2;
    o.refinements = 4;
    const rt::AttractorCoverResult c = rt::automaton_attractor_cover(t, {{0, 1}, {0, 1}, {0, 1}}, o);
    CHECK(c.dimension() == 3);
    std::set<std::array<std::uint32_t, 3>> kept;
    for (const rt::Cell& cell : c.cells)
        if (cell.level == c.depth && cell.cls == rt::CellClass::boundary)
            kept.insert({cell.ix, cell.iy, cell.iz});
    // Chaos-game points away from cell faces (the grid is dyadic, so are the maps: offset by a third
    // of a cell) lie in a kept cell.
    std::mt19937_64 rng(6);
    std::array<double, 3> p{0.1, 0.1, 0.1};
    const double n = static_cast<double>(c.cells_per_axis(c.depth));
    std::size_t missed = 0;
    for (int i = 0; i < 20000; ++i) {
        const auto& m = t.arcs[rng() % 4].op.nearest;
        for (std::size_t k = 0; k < 3; ++k) p[k] = m(k, k) * p[k] + m(k, 3);
        std::array<std::uint32_t, 3> cell{};
        for (std::size_t k = 0; k < 3; ++k)
            cell[k] = static_cast<std::uint32_t>(std::min(n - 1, std::floor(p[k] * n)));
        if (i > 30 && !kept.count(cell)) {
            // On a face: any of the neighbouring cells holding it counts.
            bool found = false;
            for (int dz = -1; dz <= 1; ++dz)
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const std::array<long, 3> q{long(cell[0]) + dx, long(cell[1]) + dy,
                                                    long(cell[2]) + dz};
                        bool holds = true;
                        for (std::size_t k = 0; k < 3; ++k)
                            holds = holds && q[k] >= 0 && q[k] / n <= p[k] && p[k] <= (q[k] + 1) / n;
                        if (holds &&
                            kept.count({std::uint32_t(q[0]), std::uint32_t(q[1]), std::uint32_t(q[2])}))
                            found = true;
                    }
            if (!found) ++missed;
        }
    }
    CHECK(missed == 0);
    const rt::DimensionEstimate e = rt::box_counting(c, 3, 6);
    std::string counts;
    for (const auto& [level, count] : e.counts) counts += " " + std::to_string(count);
    INFO("dimension " << e.dimension << ", counts" << counts);
    // Closed cells overcount along the dyadic faces the attractor lies on, which fades with the level
    // (ratios 4.57, 4.44, 4.32 towards 4): the slope of the last two levels is within 0.15 of 2.
    const double last =
        std::log2(static_cast<double>(e.counts[3].second) / static_cast<double>(e.counts[2].second));
    CHECK(last == Approx(2.0).margin(0.15));
    CHECK(e.dimension > 2.0);
}

namespace {
// An engine that cannot bound its value: NaN bounds (the cover must then assume any value).
class Unknown : public ir::Evaluator {
public:
    int dimension() const override { return 2; }
    std::string engine() const override { return "test"; }
    double eval_point(const double*) override { return std::nan(""); }
    num::Interval eval_box(const num::Interval*) override { return {std::nan(""), std::nan("")}; }
    std::unique_ptr<Evaluator> clone() const override { return std::make_unique<Unknown>(); }
};
} // namespace

TEST_CASE("a component with NaN bounds keeps the cover sound", "[cover]") {
    const PlaneMap h = compile_map(henon, {"hx", "hy"});
    Unknown unknown;
    rt::AttractorCoverOptions o;
    o.initial_level = 5;
    o.refinements = 2;
    const rt::AttractorCoverResult c =
        rt::map_attractor_cover({h.evaluators[0].get(), &unknown}, {{-1.5, 1.5}, {-0.5, 0.5}}, o);
    const KeptCells kept(c);
    double x = 0, y = 0;
    std::size_t missed = 0;
    for (int i = 0; i < 100000; ++i) {
        const double nx = 1 + y - 1.4 * x * x;
        y = 0.3 * x, x = nx;
        if (i > 1000 && !kept.contains(x, y)) ++missed;
    }
    CHECK(missed == 0);
}

TEST_CASE("attractor covers report bad input and budgets", "[cover]") {
    const PlaneMap h = compile_map(henon, {"hx", "hy"});
    rt::AttractorCoverOptions o;
    o.initial_level = 6;
    o.refinements = 6;
    o.max_cells = 20000;
    CHECK_THROWS_AS(rt::map_attractor_cover(h.components(), {{-1.5, 1.5}, {-0.5, 0.5}}, o), rt::LimitError);
    CHECK_THROWS_WITH(rt::map_attractor_cover(h.components(), {{-1.5, 1.5}, {-0.5, 0.5}}, o),
                      Catch::Contains("cells (foreseen after level 7), more than the limit of 20000 cells"));
    // The first grid is refused before it is built.
    o.initial_level = 8;
    CHECK_THROWS_WITH(
        rt::map_attractor_cover(h.components(), {{-1.5, 1.5}, {-0.5, 0.5}}, o),
        Catch::Contains("the first grid (level 8) has 65536 cells, more than the limit of 20000"));
    CHECK_THROWS_AS(rt::map_attractor_cover(h.components(), {{-1.5, 1.5}}, {}), std::invalid_argument);
    CHECK_THROWS_AS(rt::map_attractor_cover(h.components(), {{1.5, -1.5}, {-0.5, 0.5}}, {}),
                    std::invalid_argument);
    ir::Automaton line = rt::test::sierpinski();
    line.name = "line";
    line.states.push_back({"l", ir::Space::barycentric(2), {}});
    CHECK_THROWS_WITH(rt::automaton_attractor_cover(line, {}, {}),
                      Catch::Contains("state 'l' is bary(2); covers need spaces of dimension 2 or 3"));
    ir::Automaton unprojected = rt::test::sierpinski_bary();
    unprojected.projection.reset();
    CHECK_THROWS_WITH(rt::automaton_attractor_cover(unprojected, {}, {}), Catch::Contains("no projection"));
}

TEST_CASE("barycentric automata are covered in their projected space and hold their chaos game", "[cover]") {
    struct Case {
        ir::Automaton a;
        int initial_level, refinements;
    };
    const std::vector<Case> cases = {
        {rt::test::sierpinski_bary(), 3, 5},                               // bary(3) initial, projected
        {frac::test::projected_quadratic({{0, 0}, {1, 2}, {3, 2}}), 3, 5}, // one segment, projected
        {frac::test::bspline(2, {{0, 0}, {1, 2}, {3, 2}, {4, 0}, {6, 1}}), 3, 5}, // R2 initial on no cycle
        {frac::test::bspline(3, {{0, 0}, {1, 2}, {3, 2}, {4, 0}, {6, 1}}), 3, 4}, // bary(4): a 3D grid
    };
    for (const Case& k : cases) {
        INFO(k.a.name);
        rt::AttractorCoverOptions o;
        o.initial_level = k.initial_level;
        o.refinements = k.refinements;
        const rt::AttractorCoverResult c = rt::automaton_attractor_cover(k.a, {}, o);
        REQUIRE(c.root.size() == 2);
        const KeptCells kept(c);
        CHECK(kept.size() > 0);
        std::size_t missed = 0, seen = 0;
        rt::chaos_points(k.a, 200000, 100, 7, [&](const std::vector<double>& p) {
            ++seen;
            missed += kept.contains(p[0], p[1]) ? 0 : 1;
        });
        CHECK(seen == 200000);
        CHECK(missed == 0);
        for (std::size_t i = 1; i < c.steps.size(); ++i) CHECK(c.steps[i].area <= c.steps[i - 1].area);
    }
    // The projected Sierpinski triangle has about the dimension of the euclidean one: its cells are the
    // images of the barycentric grid's, coarser than a euclidean grid's, so the fine levels count
    // more boxes (1.67 measured, where the euclidean cover gives 1.58).
    rt::AttractorCoverOptions o;
    o.initial_level = 3;
    o.refinements = 6;
    const rt::AttractorCoverResult c =
        rt::automaton_attractor_cover(rt::test::sierpinski_bary(), {{0, 1}, {0, 1}}, o);
    const rt::DimensionEstimate e = rt::box_counting(c, 4, 9);
    CHECK(e.dimension == Approx(std::log(3.0) / std::log(2.0)).margin(0.1));
    // A curve: box counting near 1.
    const rt::AttractorCoverResult q = rt::automaton_attractor_cover(
        frac::test::bspline(2, {{0, 0}, {1, 2}, {3, 2}, {4, 0}, {6, 1}}), {{-1, 7}, {-1, 7}}, o);
    CHECK(rt::box_counting(q, 4, 9).dimension == Approx(1.0).margin(0.05));
}
