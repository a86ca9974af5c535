// Dense matrices: exact rational elimination, double elimination and outward interval products.
#include "helpers.hpp"

#include "numeric/matrix.hpp"

#include <cfenv>
#include <random>
#include <stdexcept>
#include <vector>

using num::Matrix;
using num::Rational;

namespace {

// The n x n Hilbert matrix 1 / (i + j + 1): notoriously ill-conditioned, harmless when exact.
Matrix<Rational> hilbert(std::size_t n) {
    Matrix<Rational> h(n, n);
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < n; ++j) h(i, j) = Rational(1, static_cast<long>(i + j + 1));
    return h;
}

// det(H_n) = c_n^4 / c_{2n} with c_n = 1! 2! ... (n-1)! (Hilbert 1894), computed independently.
Rational hilbert_determinant(long n) {
    const auto c = [](long m) {
        Rational product(1), factorial(1);
        for (long i = 1; i < m; ++i) {
            factorial *= Rational(i);
            product *= factorial;
        }
        return product;
    };
    return num::pow(c(n), 4) / c(2 * n);
}

Matrix<Rational> random_integer_matrix(std::mt19937_64& rng, std::size_t rows, std::size_t cols) {
    Matrix<Rational> m(rows, cols);
    for (std::size_t r = 0; r < rows; ++r)
        for (std::size_t c = 0; c < cols; ++c) m(r, c) = Rational(static_cast<long>(rng() % 21) - 10);
    return m;
}

} // namespace

TEST_CASE("matrix construction, identity, transpose and arithmetic", "[numeric][matrix]") {
    const Matrix<Rational> a{{1, 2, 3}, {4, 5, 6}};
    CHECK(a.rows() == 2);
    CHECK(a.cols() == 3);
    CHECK(a(1, 2) == Rational(6));
    CHECK(num::transpose(a) == Matrix<Rational>{{1, 4}, {2, 5}, {3, 6}});
    CHECK(num::transpose(num::transpose(a)) == a);
    CHECK(Matrix<Rational>::identity(3) * num::transpose(a) == num::transpose(a));
    CHECK(a + a == Rational(2) * a);
    CHECK(a - a == Matrix<Rational>(2, 3));
    CHECK(a * Rational(1, 2) ==
          Matrix<Rational>{{Rational(1, 2), 1, Rational(3, 2)}, {2, Rational(5, 2), 3}});
    CHECK(a * num::transpose(a) == Matrix<Rational>{{14, 32}, {32, 77}});
    CHECK(Matrix<double>{{1, 2}, {3, 4}} * Matrix<double>{{0, 1}, {1, 0}} == Matrix<double>{{2, 1}, {4, 3}});
    CHECK_THROWS_AS(a * a, std::invalid_argument);
    CHECK_THROWS_AS(a + num::transpose(a), std::invalid_argument);
    CHECK_THROWS_AS((Matrix<Rational>{{1, 2}, {3}}), std::invalid_argument);
}

TEST_CASE("a 9x9 Hilbert system is solved exactly", "[numeric][matrix][rational]") {
    const Matrix<Rational> h = hilbert(9);
    std::mt19937_64 rng(5);
    const Matrix<Rational> b = random_integer_matrix(rng, 9, 2);
    const auto x = num::solve(h, b);
    REQUIRE(x);
    CHECK(h * *x == b);

    CHECK(num::determinant(h) == hilbert_determinant(9));
    CHECK(num::determinant(num::transpose(h)) == num::determinant(h));
    CHECK(num::rank(h) == 9);

    const auto inverse = num::inverse(h);
    REQUIRE(inverse);
    CHECK(h * *inverse == Matrix<Rational>::identity(9));
    CHECK(*inverse * h == Matrix<Rational>::identity(9));
    CHECK((*inverse)(0, 0) == Rational(81)); // the inverse of a Hilbert matrix has integer entries
    for (std::size_t i = 0; i < 9; ++i)
        for (std::size_t j = 0; j < 9; ++j) CHECK((*inverse)(i, j).is_integer());
}

TEST_CASE("random 9x9 integer systems are solved exactly", "[numeric][matrix][rational]") {
    std::mt19937_64 rng(11);
    for (int trial = 0; trial < 20; ++trial) {
        const Matrix<Rational> a = random_integer_matrix(rng, 9, 9);
        const Matrix<Rational> b = random_integer_matrix(rng, 9, 1);
        const Rational det = num::determinant(a);
        const auto x = num::solve(a, b);
        REQUIRE(x.has_value() == !det.is_zero());
        if (!x) continue;
        CHECK(a * *x == b);
        // Cramer's rule for the first unknown, as an independent check of determinant and solve.
        Matrix<Rational> a0 = a;
        for (std::size_t r = 0; r < 9; ++r) a0(r, 0) = b(r, 0);
        CHECK((*x)(0, 0) == num::determinant(a0) / det);
        CHECK(num::determinant(a * a) == det * det);
    }
    CHECK(num::determinant(Matrix<Rational>{{0, 1}, {1, 0}}) == Rational(-1));
    CHECK(num::determinant(Matrix<Rational>{{2, 0, 0}, {0, 3, 0}, {0, 0, Rational(1, 6)}}) == Rational(1));
    CHECK_THROWS_AS(num::determinant(Matrix<Rational>(2, 3)), std::invalid_argument);
}

TEST_CASE("rank and nullspace of singular matrices", "[numeric][matrix][rational]") {
    std::mt19937_64 rng(3);
    // Rows 2.. are combinations of rows 0 and 1: rank 2, nullspace of dimension 6 - 2 = 4.
    Matrix<Rational> a = random_integer_matrix(rng, 5, 6);
    for (std::size_t c = 0; c < 6; ++c) {
        a(2, c) = a(0, c) + a(1, c);
        a(3, c) = Rational(2) * a(0, c) - Rational(1, 3) * a(1, c);
        a(4, c) = Rational(0);
    }
    CHECK(num::rank(a) == 2);
    const Matrix<Rational> n = num::nullspace(a);
    CHECK(n.rows() == 6);
    CHECK(n.cols() == 6 - num::rank(a));
    CHECK(a * n == Matrix<Rational>(5, n.cols())); // each basis vector is in the nullspace
    CHECK(num::rank(n) == n.cols());               // and they are independent

    // A square singular matrix: no unique solution, no inverse, determinant 0.
    const Matrix<Rational> s{{1, 2, 3}, {4, 5, 6}, {7, 8, 9}};
    CHECK(num::rank(s) == 2);
    CHECK(num::determinant(s) == Rational(0));
    CHECK_FALSE(num::solve(s, Matrix<Rational>::column({1, 2, 3})));
    CHECK_FALSE(num::inverse(s));
    CHECK(s * num::nullspace(s) == Matrix<Rational>(3, 1));
    CHECK(num::nullspace(s) == Matrix<Rational>::column({1, -2, 1}));

    // Full column rank: the nullspace is empty; the zero matrix: everything is.
    CHECK(num::nullspace(Matrix<Rational>::identity(4)).cols() == 0);
    CHECK(num::nullspace(Matrix<Rational>(2, 3)) == Matrix<Rational>::identity(3));
    CHECK(num::rank(Matrix<Rational>(2, 3)) == 0);
}

TEST_CASE("double solve and determinant with partial pivoting", "[numeric][matrix][double]") {
    // A zero leading entry needs the pivot search.
    const Matrix<double> a{{0, 2, 1}, {1, 1, 1}, {2, 1, 3}};
    const Matrix<double> x_true = Matrix<double>::column({1, -2, 3});
    const auto x = num::solve(a, a * x_true);
    REQUIRE(x);
    for (std::size_t i = 0; i < 3; ++i) CHECK((*x)(i, 0) == Approx(x_true(i, 0)).epsilon(1e-12));
    CHECK(num::determinant(a) == Approx(-3.0).epsilon(1e-12));
    CHECK(num::determinant(Matrix<double>{{1, 2}, {2, 4}}) == 0.0);
    CHECK_FALSE(num::solve(Matrix<double>{{1, 2}, {2, 4}}, Matrix<double>::column({1, 1})));

    // Agrees with the exact solver on a random well-conditioned system.
    std::mt19937_64 rng(23);
    const Matrix<Rational> q =
        random_integer_matrix(rng, 6, 6) + Rational(40) * Matrix<Rational>::identity(6);
    const Matrix<Rational> b = random_integer_matrix(rng, 6, 1);
    Matrix<double> qd(6, 6), bd(6, 1);
    for (std::size_t r = 0; r < 6; ++r) {
        for (std::size_t c = 0; c < 6; ++c) qd(r, c) = q(r, c).to_double();
        bd(r, 0) = b(r, 0).to_double();
    }
    const auto exact = num::solve(q, b);
    const auto approx = num::solve(qd, bd);
    REQUIRE(exact);
    REQUIRE(approx);
    for (std::size_t i = 0; i < 6; ++i)
        CHECK((*approx)(i, 0) == Approx((*exact)(i, 0).to_double()).epsilon(1e-12));
    CHECK(num::determinant(qd) == Approx(num::determinant(q).to_double()).epsilon(1e-12));
}

TEST_CASE("interval matrix products enclose the exact rational products", "[numeric][matrix][interval]") {
    std::mt19937_64 rng(31);
    for (int trial = 0; trial < 50; ++trial) {
        // Rationals such as k/7 are not doubles: their enclosures are one ulp wide.
        Matrix<Rational> a(4, 5), b(5, 3);
        for (std::size_t r = 0; r < 4; ++r)
            for (std::size_t c = 0; c < 5; ++c) a(r, c) = Rational(static_cast<long>(rng() % 41) - 20, 7);
        for (std::size_t r = 0; r < 5; ++r)
            for (std::size_t c = 0; c < 3; ++c) b(r, c) = Rational(static_cast<long>(rng() % 41) - 20, 10);
        const Matrix<Rational> exact = a * b + a * b - a * b;
        const Matrix<Interval> enclosed = num::enclose(a) * num::enclose(b) + num::enclose(a * b) -
                                          Interval(1.0) * (num::enclose(a) * num::enclose(b));
        REQUIRE(std::fegetround() == FE_TONEAREST); // the operators restore the caller's mode
        for (std::size_t r = 0; r < 4; ++r)
            for (std::size_t c = 0; c < 3; ++c) {
                const Interval e = enclosed(r, c);
                CHECK(Rational::from_double(e.lo) <= exact(r, c));
                CHECK(exact(r, c) <= Rational::from_double(e.hi));
            }
    }
    // Exact inputs with exact products stay thin.
    const Matrix<Interval> m{{1, 2}, {3, 4}};
    CHECK(m * m == Matrix<Interval>{{7, 10}, {15, 22}});
    CHECK(m * Interval(-1, 1) ==
          Matrix<Interval>{{Interval(-1, 1), Interval(-2, 2)}, {Interval(-3, 3), Interval(-4, 4)}});
    CHECK(num::enclose(Matrix<Rational>{{Rational(1, 3)}})(0, 0) == num::enclose(Rational(1, 3)));
}
