// Tabulation F(i / N^p) of projected attractors (seed 003 sec. 2.4) against de Boor evaluation.
#include "runtime/automata/tabulate.hpp"
#include "tests/unit/automata_examples.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace frac;
using namespace frac::test;

namespace {

using Points = std::vector<std::pair<long, long>>;

// de Boor's algorithm on the uniform knots 0, 1, 2, ...: the curve of degree k over [k, n].
std::array<double, 2> de_boor(const Points& p, int k, double u) {
    const int n = static_cast<int>(p.size());
    int l = std::min(static_cast<int>(std::floor(u)), n - 1); // t_l <= u < t_{l+1}
    std::vector<std::array<double, 2>> d;
    for (int j = 0; j <= k; ++j)
        d.push_back({static_cast<double>(p[static_cast<std::size_t>(j + l - k)].first),
                     static_cast<double>(p[static_cast<std::size_t>(j + l - k)].second)});
    for (int r = 1; r <= k; ++r)
        for (int j = k; j >= r; --j) {
            const double t0 = j + l - k, t1 = j + 1 + l - r; // knots t_{j+l-k} and t_{j+1+l-r}
            const double alpha = (u - t0) / (t1 - t0);
            for (int c = 0; c < 2; ++c)
                d[static_cast<std::size_t>(j)][static_cast<std::size_t>(c)] =
                    (1 - alpha) * d[static_cast<std::size_t>(j - 1)][static_cast<std::size_t>(c)] +
                    alpha * d[static_cast<std::size_t>(j)][static_cast<std::size_t>(c)];
        }
    return d[static_cast<std::size_t>(k)];
}

double check_against_de_boor(int degree, const Points& points, int p) {
    const ir::Automaton a = bspline(degree, points);
    const rt::Tabulation t = rt::tabulate(a, p);
    const std::size_t segments = points.size() - static_cast<std::size_t>(degree);
    REQUIRE(t.base == segments);
    REQUIRE(t.values.size() == static_cast<std::size_t>(std::pow(segments, p)));
    double worst = 0;
    for (std::size_t i = 0; i < t.values.size(); ++i) {
        const double s = static_cast<double>(i) / static_cast<double>(t.values.size());
        const auto expected = de_boor(points, degree, degree + s * static_cast<double>(segments));
        REQUIRE(t.values[i].size() == 2);
        worst =
            std::max({worst, std::abs(t.values[i][0] - expected[0]), std::abs(t.values[i][1] - expected[1])});
    }
    return worst;
}

} // namespace

TEST_CASE("addresses of i / N^p", "[automata][tabulate]") {
    CHECK(rt::address_digits(5, 2, 4) == std::vector<std::size_t>{0, 1, 0, 1});
    CHECK(rt::address_digits(7, 3, 2) == std::vector<std::size_t>{2, 1});
    CHECK_THROWS(rt::address_digits(9, 3, 2));
    // The Cantor set: phi(0^inf) = 0, phi(1 0^inf) = 2/3, phi(0 1 0^inf) = 2/9.
    CHECK(rt::address_point(cantor(), {}) == std::vector<double>{0.0});
    CHECK(rt::address_point(cantor(), {1})[0] == Approx(2.0 / 3).epsilon(1e-15));
    CHECK(rt::address_point(cantor(), {0, 1})[0] == Approx(2.0 / 9).epsilon(1e-15));
    CHECK_THROWS_WITH(rt::address_point(cantor(), {2}), Catch::Contains("digit 2 has no arc at state c"));
}

TEST_CASE("quadratic and cubic B-spline CIFS tabulated at i/2^p equal de Boor", "[automata][tabulate]") {
    // Seed 002 Fig. 4: 4 control points, two quadratic segments; 5 points, two cubic segments.
    CHECK(check_against_de_boor(2, {{0, 0}, {1, 3}, {4, 3}, {5, -1}}, 10) < 1e-12);
    CHECK(check_against_de_boor(3, {{0, 0}, {1, 3}, {4, 3}, {5, -1}, {8, 2}}, 10) < 1e-12);
    // Three segments give a 3 arcs but b has 2: no single base N, refused naming the state.
    CHECK_THROWS_WITH(rt::tabulate(bspline(2, {{0, 0}, {1, 3}, {4, 3}, {5, -1}, {7, 0}}), 3),
                      Catch::Contains("b has 2"));
}

TEST_CASE("a projected IFS: the barycentric initial state with control points", "[automata][tabulate]") {
    const Points pts{{0, 0}, {2, 4}, {6, 1}};
    const ir::Automaton a = projected_quadratic(pts);
    const rt::Tabulation t = rt::tabulate(a, 8);
    REQUIRE(t.values.size() == 256);
    for (std::size_t i = 0; i < 256; ++i) {
        const auto e = de_boor(pts, 2, 2 + static_cast<double>(i) / 256);
        CHECK(std::abs(t.values[i][0] - e[0]) < 1e-12);
        CHECK(std::abs(t.values[i][1] - e[1]) < 1e-12);
    }
}

TEST_CASE("surface tabulation of a tensor-product patch", "[automata][tabulate]") {
    // bary(9) with T_(sigma, tau) = T_sigma (x) T_tau of the quadratic subdivision, projected by a
    // 3 x 3 grid of points in R3: F(s, t) is the tensor-product quadratic B-spline patch.
    ir::Automaton patch = tensor_patch(2);
    Matrix<Rational> grid(4, 9);
    auto height = [](std::size_t a, std::size_t b) { return static_cast<long>((a * 7 + b * 3) % 5); };
    for (std::size_t a = 0; a < 3; ++a)
        for (std::size_t b = 0; b < 3; ++b) {
            grid(0, a * 3 + b) = static_cast<long>(a);
            grid(1, a * 3 + b) = static_cast<long>(b);
            grid(2, a * 3 + b) = height(a, b);
            grid(3, a * 3 + b) = 1;
        }
    patch.projection = ir::Operator::from_exact(grid);
    const rt::Tabulation tab = rt::tabulate_surface(patch, 4);
    REQUIRE(tab.base == 2);
    REQUIRE(tab.values.size() == 256);
    // The quadratic basis of one segment at local t.
    auto basis = [](double x) {
        return std::array<double, 3>{(1 - x) * (1 - x) / 2, (-2 * x * x + 2 * x + 1) / 2, x * x / 2};
    };
    double worst = 0;
    for (std::size_t i = 0; i < 16; ++i)
        for (std::size_t j = 0; j < 16; ++j) {
            const auto bs = basis(static_cast<double>(i) / 16), bt = basis(static_cast<double>(j) / 16);
            double x = 0, y = 0, z = 0;
            for (std::size_t a = 0; a < 3; ++a)
                for (std::size_t b = 0; b < 3; ++b) {
                    const double w = bs[a] * bt[b];
                    x += w * static_cast<double>(a);
                    y += w * static_cast<double>(b);
                    z += w * static_cast<double>(height(a, b));
                }
            const auto& v = tab.values[i * 16 + j];
            worst = std::max({worst, std::abs(v[0] - x), std::abs(v[1] - y), std::abs(v[2] - z)});
        }
    CHECK(worst < 1e-12);
    CHECK_THROWS_WITH(rt::tabulate_surface(sierpinski(), 2), Catch::Contains("N^2 arcs per state"));
}
