#include "numeric/linear_system.hpp"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

using frac::num::AffineForm;
using frac::num::LinearSystem;
using frac::num::Rational;

namespace {

// sum of coefficient * x_v, plus a constant.
AffineForm form(std::initializer_list<std::pair<std::size_t, Rational>> terms, Rational constant = 0) {
    AffineForm f;
    f.constant = constant;
    for (const auto& [v, a] : terms) f.add_scaled(AffineForm::variable(v), a);
    return f;
}

} // namespace

TEST_CASE("a linear system keeps its earliest variables free", "[numeric][linear]") {
    // x0 + x1 + x2 = 1: x2 is the pivot, x0 and x1 stay free.
    LinearSystem s(3);
    s.add(form({{0, 1}, {1, 1}, {2, 1}}, -1), 0);
    const auto sol = s.solve();
    REQUIRE(sol.consistent);
    CHECK(sol.free == std::vector<std::size_t>{0, 1});
    CHECK(sol.rank == 1);
    CHECK(sol.values[2] == form({{0, -1}, {1, -1}}, 1));
    CHECK(sol.values[0] == AffineForm::variable(0));
}

TEST_CASE("a linear system solves exactly and substitutes back", "[numeric][linear]") {
    // 3 x0 = 1; x1 - x0 = 0; x2 + x1 = 2.
    LinearSystem s(3);
    s.add(form({{0, 3}}, -1), 0);
    s.add(form({{1, 1}, {0, -1}}), 1);
    s.add(form({{2, 1}, {1, 1}}, -2), 2);
    const auto sol = s.solve();
    REQUIRE(sol.consistent);
    CHECK(sol.free.empty());
    CHECK(sol.values[0] == form({}, Rational(1, 3)));
    CHECK(sol.values[1] == form({}, Rational(1, 3)));
    CHECK(sol.values[2] == form({}, Rational(5, 3)));
}

TEST_CASE("an inconsistent system names a minimal conflicting set", "[numeric][linear]") {
    // Sources 0 and 2 fix x0 to 1 and to 2; 1 and 3 are consistent with either.
    LinearSystem s(2);
    s.add(form({{0, 1}}, -1), 0);
    s.add(form({{1, 1}}, -5), 1);
    s.add(form({{0, 1}, {1, 1}}, -7), 2); // x0 = 2 once x1 = 5
    s.add(form({{1, 2}}, -10), 3);
    const auto sol = s.solve();
    REQUIRE_FALSE(sol.consistent);
    // {0, 1, 2} and {0, 2, 3} both conflict; each is minimal, and one is reported.
    const bool first = sol.conflict == std::vector<std::size_t>{0, 1, 2};
    const bool second = sol.conflict == std::vector<std::size_t>{0, 2, 3};
    CHECK((first || second));
}

TEST_CASE("redundant equations do not change the rank", "[numeric][linear]") {
    LinearSystem s(2);
    s.add(form({{0, 1}, {1, 1}}, -1), 0);
    s.add(form({{0, 2}, {1, 2}}, -2), 1);
    const auto sol = s.solve();
    REQUIRE(sol.consistent);
    CHECK(sol.rank == 1);
    CHECK(sol.free == std::vector<std::size_t>{0});
}

TEST_CASE("with a tolerance, a system is solved in floating point and its rank checked",
          "[numeric][linear]") {
    // x0 + x1 = 1, x1 = sqrt(2)/2 rounded; a third equation holds only within rounding.
    const double s = std::sqrt(2.0) / 2;
    LinearSystem sys(2);
    sys.add(form({{0, 1}, {1, 1}}, -1), 0);
    sys.add(form({{1, 1}}, -Rational::from_double(s)), 1);
    sys.add(form({{0, 1}}, -Rational::from_double(1 - s + 1e-16)), 2);
    CHECK_FALSE(sys.solve().consistent); // exactly, the three do not agree
    const auto sol = sys.solve(1e-9);
    REQUIRE(sol.consistent);
    CHECK(sol.rank == 2);
    CHECK(sol.qr_checked);
    CHECK(sol.qr_rank == 2);
    CHECK(std::abs(sol.values[1].constant.to_double() - s) < 1e-15);
    CHECK(std::abs(sol.values[0].constant.to_double() - (1 - s)) < 1e-15);
}

TEST_CASE("with a tolerance, a conflict above it names its minimal set", "[numeric][linear]") {
    LinearSystem sys(2);
    sys.add(form({{0, 1}, {1, 1}}, -1), 0);
    sys.add(form({{1, 1}}, -Rational::from_double(0.5)), 1);
    sys.add(form({{0, 1}}, -Rational::from_double(0.5 + 1e-6)), 2);
    sys.add(form({{1, 1}, {0, -1}}), 3); // x1 = x0: with 1 and 2, another conflict of three
    const auto sol = sys.solve(1e-9);
    REQUIRE_FALSE(sol.consistent);
    CHECK(sol.conflict.size() == 3);
    CHECK(std::find(sol.conflict.begin(), sol.conflict.end(), 2) != sol.conflict.end());
    CHECK(std::find(sol.conflict.begin(), sol.conflict.end(), 1) != sol.conflict.end());
}

TEST_CASE("with a tolerance, a rank the QR factorisation does not confirm is ill-conditioned",
          "[numeric][linear]") {
    // Rows (1, 1) and (1, 1 + 1.2e-9): elimination keeps the second pivot (1.2e-9 > 1e-9), while the
    // QR's second diagonal entry, 1.2e-9 / sqrt(2) = 0.85e-9, is under the tolerance.
    LinearSystem sys(2);
    sys.add(form({{0, 1}, {1, 1}}, -1), 0);
    sys.add(form({{0, 1}, {1, Rational::from_double(1 + 1.2e-9)}}, -1), 1);
    const auto sol = sys.solve(1e-9);
    CHECK(sol.ill_conditioned);
    CHECK(sol.rank == 2);
    CHECK(sol.qr_rank == 1);
}
