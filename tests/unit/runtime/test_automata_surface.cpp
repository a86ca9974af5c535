// Tessellation of projected-IFS patches and curves (runtime/automata/surface.hpp): the bicubic
// B-spline patch against direct tensor-product evaluation, shared sides, cracks, layouts.
#include "driver/pipeline.hpp"
#include "runtime/automata/surface.hpp"
#include "runtime/automata/tabulate.hpp"
#include "tests/unit/automata_examples.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <map>

using namespace frac;
using namespace frac::test;

namespace {

// The 4 x 4 (or 3 x 3) control grid in R3, point (a, b) at weight index a * k + b: a bumpy sheet.
Matrix<Rational> grid_controls(std::size_t k) {
    Matrix<Rational> m(4, k * k);
    for (std::size_t a = 0; a < k; ++a)
        for (std::size_t b = 0; b < k; ++b) {
            const std::size_t c = a * k + b;
            m(0, c) = Rational(static_cast<long>(a)) + q(static_cast<long>(b), 7);
            m(1, c) = Rational(static_cast<long>(b)) - q(static_cast<long>(a * a), 5);
            m(2, c) = q(static_cast<long>((a * 3 + b * 5) % 4) - 1, 3);
            m(3, c) = 1;
        }
    return m;
}

ir::Automaton projected_patch(int degree) {
    ir::Automaton a = tensor_patch(degree);
    a.projection = ir::Operator::from_exact(grid_controls(static_cast<std::size_t>(degree) + 1));
    return a;
}

// Uniform cubic B-spline basis on one segment.
std::array<double, 4> cubic_basis(double s) {
    const double r = 1 - s;
    return {r * r * r / 6, (3 * s * s * s - 6 * s * s + 4) / 6, (-3 * s * s * s + 3 * s * s + 3 * s + 1) / 6,
            s * s * s / 6};
}

std::array<double, 3> bicubic(const Matrix<Rational>& controls, double s, double t) {
    const auto bs = cubic_basis(s), bt = cubic_basis(t);
    std::array<double, 3> p{0, 0, 0};
    for (std::size_t a = 0; a < 4; ++a)
        for (std::size_t b = 0; b < 4; ++b)
            for (std::size_t r = 0; r < 3; ++r) p[r] += bs[a] * bt[b] * controls(r, a * 4 + b).to_double();
    return p;
}

// The unit square of R2 cut into 4 quarters, the quarter (1, 0) mirrored in s.
ir::Automaton mirrored_square() {
    ir::Automaton a;
    a.name = "square";
    a.states.push_back(state("q", ir::Space::euclidean(2)));
    const Rational h = q(1, 2);
    a.arcs.push_back(arc(0, 0, affine({{h, 0}, {0, h}}, {0, 0}), "A"));
    a.arcs.push_back(arc(0, 0, affine({{h, 0}, {0, h}}, {0, h}), "B"));
    a.arcs.push_back(arc(0, 0, affine({{-h, 0}, {0, h}}, {1, 0}), "C")); // x -> 1 - x/2
    a.arcs.push_back(arc(0, 0, affine({{h, 0}, {0, h}}, {h, h}), "D"));
    return a;
}

// The unit square's grid: vertex (i, j) exactly at (i / n, j / n, 0) (dyadic: no rounding anywhere).
void check_unit_grid(const rt::Tessellation& t, std::size_t n) {
    REQUIRE(t.vertices.size() == (n + 1) * (n + 1));
    for (std::size_t i = 0; i <= n; ++i)
        for (std::size_t j = 0; j <= n; ++j) {
            const auto& v = t.vertices[i * (n + 1) + j];
            CHECK(v[0] == static_cast<double>(i) / static_cast<double>(n));
            CHECK(v[1] == static_cast<double>(j) / static_cast<double>(n));
            CHECK(v[2] == 0);
        }
}

// The unit cube's surface as 6 bilinear patches (bary(4), T_st = L_s (x) L_t) drawn through the
// controls of each face, (a, b) -> origin + a e1 + b e2 with e1 x e2 pointing out.
ir::Automaton cube(std::size_t faces = 6) {
    ir::Automaton a;
    a.name = "cube";
    a.states.push_back(state("box", ir::Space::euclidean(3)));
    a.states.push_back(state("face", ir::Space::barycentric(4)));
    using V = std::array<long, 3>;
    const std::array<std::array<V, 3>, 6> frames{{{V{0, 0, 0}, V{0, 1, 0}, V{1, 0, 0}},
                                                  {V{0, 0, 1}, V{1, 0, 0}, V{0, 1, 0}},
                                                  {V{0, 0, 0}, V{1, 0, 0}, V{0, 0, 1}},
                                                  {V{0, 1, 0}, V{0, 0, 1}, V{1, 0, 0}},
                                                  {V{0, 0, 0}, V{0, 0, 1}, V{0, 1, 0}},
                                                  {V{1, 0, 0}, V{0, 1, 0}, V{0, 0, 1}}}};
    for (std::size_t f = 0; f < faces; ++f) {
        Matrix<Rational> m(4, 4);
        for (std::size_t c = 0; c < 4; ++c) {
            const long u = static_cast<long>(c / 2), v = static_cast<long>(c % 2);
            for (std::size_t r = 0; r < 3; ++r)
                m(r, c) = frames[f][0][r] + u * frames[f][1][r] + v * frames[f][2][r];
            m(3, c) = 1;
        }
        a.arcs.push_back(arc(0, 1, m, "F" + std::to_string(f)));
    }
    const Matrix<Rational> l[2] = {Matrix<Rational>{{1, q(1, 2)}, {0, q(1, 2)}},
                                   Matrix<Rational>{{q(1, 2), 0}, {q(1, 2), 1}}};
    for (int s = 0; s < 2; ++s)
        for (int t = 0; t < 2; ++t) {
            Matrix<Rational> m(4, 4);
            for (std::size_t r = 0; r < 4; ++r)
                for (std::size_t c = 0; c < 4; ++c) m(r, c) = l[s](r / 2, c / 2) * l[t](r % 2, c % 2);
            a.arcs.push_back(arc(1, 1, m, "T" + std::to_string(s) + std::to_string(t)));
        }
    return a;
}

} // namespace

TEST_CASE("several patches joined along their sides: a closed cube", "[automata][surface]") {
    for (const int p : {0, 1, 3}) {
        const std::size_t n = std::size_t{1} << p;
        const rt::PatchSurface s = rt::tessellate_patches(cube(), p);
        CHECK(s.patches == 6);
        CHECK(s.joins == 12);
        // 6 (n + 1)^2 grid vertices, the 12 edges' n + 1 shared once, the 8 corners three times.
        CHECK(s.mesh.vertices.size() == 6 * (n + 1) * (n + 1) - 12 * (n + 1) + 8);
        const rt::MeshCheck ck = rt::check_mesh(s.mesh);
        INFO("depth " << p << ": " << ck.problem);
        CHECK(ck.ok());
        CHECK(ck.watertight);
        CHECK(ck.euler == 2);
        CHECK(ck.volume == Approx(1.0).epsilon(1e-12));
    }
    // Five faces: an open box, its rim the missing face's 4 n edges.
    const rt::PatchSurface open = rt::tessellate_patches(cube(5), 2);
    CHECK(open.joins == 8);
    const rt::MeshCheck ck = rt::check_mesh(open.mesh);
    CHECK_FALSE(ck.watertight);
    CHECK(ck.boundary_edges == 16);
    CHECK(ck.euler == 1);
    // The initial state must not be reached again.
    CHECK_THROWS_WITH(rt::tessellate_patches(projected_patch(2), 1), Catch::Contains("reached again"));
}

TEST_CASE("the bicubic patch's vertices are the tensor-product B-spline", "[automata][surface]") {
    const ir::Automaton a = projected_patch(3);
    const rt::SurfaceLayout layout = rt::infer_layout(a);
    CHECK(layout.exact);
    CHECK(layout.states[0]->dimension == 2);
    for (const int p : {0, 1, 4, 8}) {
        const rt::Tessellation t = rt::tessellate(a, layout, p);
        const std::size_t side = (std::size_t{1} << p) + 1;
        REQUIRE(t.side_s == side);
        REQUIRE(t.side_t == side);
        double worst = 0;
        for (std::size_t i = 0; i < side; ++i)
            for (std::size_t j = 0; j < side; ++j) {
                const auto expected = bicubic(*a.projection->exact, static_cast<double>(i) / double(side - 1),
                                              static_cast<double>(j) / double(side - 1));
                for (std::size_t r = 0; r < 3; ++r)
                    worst = std::max(worst, std::abs(t.vertices[i * side + j][r] - expected[r]));
            }
        INFO("depth " << p);
        CHECK(worst < 1e-12);
    }
}

TEST_CASE("sub-patches share their sides: one vertex, no cracks", "[automata][surface]") {
    for (const int degree : {2, 3}) {
        const ir::Automaton a = projected_patch(degree);
        const rt::SurfaceLayout layout = rt::infer_layout(a);
        for (const int p : {1, 3, 6}) {
            const rt::Tessellation t = rt::tessellate(a, layout, p);
            const std::size_t n = std::size_t{1} << p;
            const rt::Mesh mesh = rt::surface_mesh(t);
            CHECK(mesh.vertices.size() == (n + 1) * (n + 1));
            CHECK(mesh.triangles.size() == 2 * n * n);
            const rt::MeshCheck ck = rt::check_mesh(mesh);
            INFO("degree " << degree << ", depth " << p << ": " << ck.problem);
            // An open disc: every interior edge has two triangles, the rim 4 n edges, one component.
            CHECK(ck.manifold);
            CHECK(ck.oriented);
            CHECK(ck.degenerate == 0);
            CHECK(ck.boundary_edges == 4 * n);
            CHECK(ck.euler == 1);
            CHECK(ck.components == 1);
            // The side vertices are computed once through the left/lower sub-patch; through the other
            // sub-patch's address (tabulation's, digit 1 first) the same point comes within rounding.
            const rt::Tabulation tab = rt::tabulate_surface(a, p);
            double worst = 0;
            for (std::size_t j = 0; j < n; ++j)
                for (std::size_t r = 0; r < 3; ++r) {
                    worst = std::max(worst, std::abs(t.vertices[(n / 2) * (n + 1) + j][r] -
                                                     tab.values[(n / 2) * n + j][r]));
                    worst = std::max(
                        worst, std::abs(t.vertices[j * (n + 1) + n / 2][r] - tab.values[j * n + n / 2][r]));
                }
            CHECK(worst < 1e-13);
        }
    }
}

TEST_CASE("separately tessellated sub-patches would leave cracks", "[automata][surface]") {
    // The check above can fail: four sub-patch grids side by side, each with its own side vertices,
    // have every shared side twice, open.
    const ir::Automaton a = projected_patch(2);
    rt::Mesh joined;
    for (std::size_t k = 0; k < 4; ++k) {
        ir::Automaton sub = a;
        sub.projection = ir::Operator::from_exact(*a.projection->exact * *a.arcs[k].op.exact);
        const rt::Mesh m = rt::surface_mesh(rt::tessellate(sub, rt::infer_layout(sub), 2));
        const auto base = static_cast<std::uint32_t>(joined.vertices.size());
        joined.vertices.insert(joined.vertices.end(), m.vertices.begin(), m.vertices.end());
        for (auto tri : m.triangles)
            joined.triangles.push_back({tri[0] + base, tri[1] + base, tri[2] + base});
    }
    const rt::MeshCheck ck = rt::check_mesh(joined);
    CHECK(ck.boundary_edges == 4 * 16); // 4 x 16 rim edges, instead of the whole patch's 32
    CHECK(ck.components == 4);
}

TEST_CASE("the layout is inferred whatever the order of the maps", "[automata][surface]") {
    const ir::Automaton a = projected_patch(2);
    ir::Automaton shuffled = a;
    std::swap(shuffled.arcs[0], shuffled.arcs[3]);
    std::swap(shuffled.arcs[1], shuffled.arcs[2]);
    const rt::SurfaceLayout l1 = rt::infer_layout(a), l2 = rt::infer_layout(shuffled);
    // The first order that joins: the model's in both cases; the shuffled one has T11 at (0, 0), the
    // patch traced from its other corner.
    CHECK(l1.states[0]->cells[0].arc == 0);
    CHECK(l1.states[0]->cells[3].arc == 3);
    CHECK(shuffled.arcs[l2.states[0]->cells[0].arc].label == "T11");
    const rt::Tessellation t1 = rt::tessellate(a, l1, 4), t2 = rt::tessellate(shuffled, l2, 4);
    double worst = 0;
    for (std::size_t v = 0; v < t1.vertices.size(); ++v)
        for (std::size_t r = 0; r < 3; ++r)
            worst = std::max(worst, std::abs(t1.vertices[v][r] - t2.vertices[t1.vertices.size() - 1 - v][r]));
    CHECK(worst < 1e-14);
    // Cells named on the command line: the given order, checked.
    rt::LayoutRequest request;
    request.cells = {"T00", "T01", "T10", "T11"};
    CHECK(rt::infer_layout(shuffled, request).states[0]->cells[0].arc == 3);
    request.cells = {"T00", "T10", "T11", "T01"};
    CHECK_THROWS_WITH(rt::infer_layout(shuffled, request), Catch::Contains("do not meet"));
    request.cells = {"T00", "T01", "T10", "X"};
    CHECK_THROWS_WITH(rt::infer_layout(shuffled, request), Catch::Contains("no arc labelled X"));
}

TEST_CASE("a mirrored sub-cell: an explicit layout places it", "[automata][surface]") {
    const ir::Automaton a = mirrored_square();
    CHECK_THROWS_WITH(rt::infer_layout(a), Catch::Contains("cannot infer the layout of square"));
    rt::SurfaceLayout layout;
    layout.states.resize(1);
    layout.states[0] = rt::CellLayout{2, 2, 2, {{0}, {1}, {2, false, true, false}, {3}}};
    rt::check_layout(a, layout);
    CHECK(layout.exact);
    check_unit_grid(rt::tessellate(a, layout, 5), 32);
    // Without the flip, the quarters do not meet.
    layout.states[0]->cells[2].flip_s = false;
    CHECK_THROWS_WITH(rt::check_layout(a, layout), Catch::Contains("(0, 0) [A] and (1, 0) [C]"));
}

TEST_CASE("a transposed and reversed sub-cell: swap and flips compose", "[automata][surface]") {
    // Quarter (1, 1) maps (u, v) to (1 - v/2, 1/2 + u/2): swapped, then reversed in s.
    ir::Automaton a = mirrored_square();
    const Rational h = q(1, 2);
    a.arcs[3] = arc(0, 0, affine({{0, -h}, {h, 0}}, {1, h}), "D");
    rt::SurfaceLayout layout;
    layout.states.resize(1);
    layout.states[0] = rt::CellLayout{2, 2, 2, {{0}, {1}, {2, false, true, false}, {3, true, true, false}}};
    rt::check_layout(a, layout);
    check_unit_grid(rt::tessellate(a, layout, 4), 16);
    // Swapped without the flip, or flipped without the swap: the quarters do not meet (the first
    // join found wrong is elsewhere, the corner (1, 1) of the square being D's).
    layout.states[0]->cells[3].flip_s = false;
    CHECK_THROWS_WITH(rt::check_layout(a, layout), Catch::Contains("do not meet"));
    layout.states[0]->cells[3] = {3, false, true, false};
    CHECK_THROWS_WITH(rt::check_layout(a, layout), Catch::Contains("do not meet"));
    // A swap needs a square patch.
    layout.states[0]->cells[3] = {3, true, true, false};
    layout.states[0]->dimension = 1;
    CHECK_THROWS(rt::check_layout(a, layout));
}

TEST_CASE("curves: a cubic B-spline of two segments as a polyline", "[automata][surface]") {
    const ir::Automaton a = bspline(3, {{0, 0}, {1, 2}, {2, 0}, {3, 1}, {4, 3}});
    const rt::SurfaceLayout layout = rt::infer_layout(a);
    REQUIRE(layout.states[0]->dimension == 1);
    const rt::Tessellation t = rt::tessellate(a, layout, 6);
    REQUIRE(t.side_t == 1);
    REQUIRE(t.vertices.size() == 65);
    const rt::Tabulation tab = rt::tabulate(a, 6);
    for (std::size_t i = 0; i < 64; ++i) {
        CHECK(t.vertices[i][0] == Approx(tab.values[i][0]).margin(1e-13));
        CHECK(t.vertices[i][1] == Approx(tab.values[i][1]).margin(1e-13));
    }
    // The end: (P2 + 4 P3 + P4) / 6 = (3, 7/6).
    CHECK(t.vertices[64][0] == Approx(3.0).margin(1e-14));
    CHECK(t.vertices[64][1] == Approx(7.0 / 6).margin(1e-14));
    CHECK_THROWS_WITH(rt::surface_mesh(t), Catch::Contains("polyline"));
}

TEST_CASE("a curve with enclosed operators: the Koch curve, joins to 1e-9", "[automata][surface]") {
    const ir::Automaton a = koch();
    const rt::SurfaceLayout layout = rt::infer_layout(a);
    CHECK_FALSE(layout.exact);
    const rt::Tessellation t = rt::tessellate(a, layout, 3);
    REQUIRE(t.vertices.size() == 65);
    CHECK(t.vertices.front()[0] == Approx(0.0).margin(1e-15));
    CHECK(t.vertices.back()[0] == Approx(1.0).margin(1e-15));
    CHECK(t.vertices[32][1] == Approx(std::sqrt(3.0) / 6).margin(1e-15)); // the peak
}

TEST_CASE("layouts that cannot be tessellated are refused clearly", "[automata][surface]") {
    CHECK_THROWS_WITH(rt::infer_layout(sierpinski()),
                      Catch::Contains("cannot infer the layout of sierpinski"));
    // Three segments of state a over a state cut in two.
    CHECK_THROWS_WITH(rt::infer_layout(bspline(2, {{0, 0}, {1, 2}, {2, 0}, {3, 1}, {4, 3}})),
                      Catch::Contains("the same cells at every state"));
    const ir::Automaton a = projected_patch(3);
    const rt::SurfaceLayout layout = rt::infer_layout(a);
    CHECK_THROWS_WITH(rt::tessellate(a, layout, 14), Catch::Contains("at most 2^26"));
    CHECK_THROWS_WITH(rt::tessellate(a, layout, -1), Catch::Contains("outside [0, 24]"));
    rt::SurfaceLayout bad = layout;
    bad.states[0]->cells.pop_back();
    CHECK_THROWS_WITH(rt::check_layout(a, bad), Catch::Contains("3 cells for 2 x 2 sub-cells and 4 arcs"));
}

TEST_CASE("a triangle patch: the quadratic Bezier triangle's vertices, shared sides, one sheet",
          "[automata][surface]") {
    // The library's bezier_triangle: a bcifs whose triangle topology the compiler records, its
    // de Casteljau operators given. Vertex (i, j) of the depth-3 grid is the Bezier triangle at
    // (u, v) = (i, j) / 8: sum over control points p(a, b) of 2! / (c! a! b!) w^c u^a v^b, w = 1 - u - v.
    const auto c = driver::compile_source("t.frac", "import \"bcifs\";");
    REQUIRE(c->ok());
    const ir::Automaton& a = c->module.find_automaton("bezier_triangle")->automaton;
    REQUIRE(a.triangle_patches.size() == 1);
    const int depth = 3, side = 8;
    const rt::Mesh mesh = rt::tessellate_triangle_patch(a, a.triangle_patches[0], depth);
    CHECK(mesh.vertices.size() == static_cast<std::size_t>((side + 1) * (side + 2) / 2));
    CHECK(mesh.triangles.size() == 64);
    const double controls[6][3] = {{0, 0, 0}, {1, 0, 1}, {2, 0, 0}, {0, 1, 1}, {1, 1, 1}, {0, 2, 0}};
    const int ai[6] = {0, 1, 2, 0, 1, 0}, bi[6] = {0, 0, 0, 1, 1, 2};
    double worst = 0;
    std::size_t v = 0;
    for (int j = 0; j <= side; ++j)
        for (int i = 0; i + j <= side; ++i, ++v) {
            const double u = i / 8.0, t = j / 8.0, w = 1 - u - t;
            for (int r = 0; r < 3; ++r) {
                double x = 0;
                for (int p = 0; p < 6; ++p) {
                    const int cw = 2 - ai[p] - bi[p];
                    const double multinomial =
                        2.0 / ((cw == 2 ? 2 : 1) * (ai[p] == 2 ? 2 : 1) * (bi[p] == 2 ? 2 : 1));
                    x += controls[p][r] * multinomial * std::pow(w, cw) * std::pow(u, ai[p]) *
                         std::pow(t, bi[p]);
                }
                worst = std::max(worst, std::abs(x - mesh.vertices[v][static_cast<std::size_t>(r)]));
            }
        }
    CHECK(worst < 1e-12);
    // One oriented sheet: every inner edge shared by two triangles running it in opposite directions.
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
    for (const auto& tri : mesh.triangles)
        for (int e = 0; e < 3; ++e)
            ++edges[{tri[static_cast<std::size_t>(e)], tri[static_cast<std::size_t>((e + 1) % 3)]}];
    int inner = 0, rim = 0;
    for (const auto& [edge, count] : edges) {
        CHECK(count == 1);
        (edges.count({edge.second, edge.first}) ? inner : rim) += 1;
    }
    CHECK(rim == 3 * side);
    CHECK(inner % 2 == 0);
}
