#include "numeric/matrix.hpp"

#include <cmath>
#include <utility>

namespace frac::num {

// ---- Intervals ----

Matrix<Interval> operator+(const Matrix<Interval>& a, const Matrix<Interval>& b) {
    detail::require_same_shape(a.rows(), a.cols(), b.rows(), b.cols());
    const UpwardRounding upward;
    Matrix<Interval> s(a.rows(), a.cols());
    for (std::size_t r = 0; r < a.rows(); ++r)
        for (std::size_t c = 0; c < a.cols(); ++c) s(r, c) = add(a(r, c), b(r, c));
    return s;
}

Matrix<Interval> operator-(const Matrix<Interval>& a, const Matrix<Interval>& b) {
    detail::require_same_shape(a.rows(), a.cols(), b.rows(), b.cols());
    const UpwardRounding upward;
    Matrix<Interval> s(a.rows(), a.cols());
    for (std::size_t r = 0; r < a.rows(); ++r)
        for (std::size_t c = 0; c < a.cols(); ++c) s(r, c) = sub(a(r, c), b(r, c));
    return s;
}

Matrix<Interval> operator*(const Matrix<Interval>& a, const Matrix<Interval>& b) {
    detail::require_product_shape(a.cols(), b.rows());
    const UpwardRounding upward;
    Matrix<Interval> p(a.rows(), b.cols());
    for (std::size_t r = 0; r < a.rows(); ++r)
        for (std::size_t c = 0; c < b.cols(); ++c) {
            // Each partial sum encloses the exact partial sum, so the last one encloses the entry.
            Interval sum(0.0);
            for (std::size_t k = 0; k < a.cols(); ++k) sum = add(sum, mul(a(r, k), b(k, c)));
            p(r, c) = sum;
        }
    return p;
}

Matrix<Interval> operator*(Interval s, const Matrix<Interval>& a) {
    const UpwardRounding upward;
    Matrix<Interval> p(a.rows(), a.cols());
    for (std::size_t r = 0; r < a.rows(); ++r)
        for (std::size_t c = 0; c < a.cols(); ++c) p(r, c) = mul(s, a(r, c));
    return p;
}

Matrix<Interval> operator*(const Matrix<Interval>& a, Interval s) {
    return s * a;
}

Matrix<Interval> enclose(const Matrix<Rational>& a) {
    Matrix<Interval> e(a.rows(), a.cols());
    for (std::size_t r = 0; r < a.rows(); ++r)
        for (std::size_t c = 0; c < a.cols(); ++c) e(r, c) = enclose(a(r, c));
    return e;
}

// ---- Rationals ----

namespace {

template <typename T>
void swap_rows(Matrix<T>& m, std::size_t i, std::size_t j) {
    if (i == j) return;
    for (std::size_t c = 0; c < m.cols(); ++c) std::swap(m(i, c), m(j, c));
}

void require_square(std::size_t rows, std::size_t cols, const char* what) {
    if (rows != cols) throw std::invalid_argument(what);
}

} // namespace

RowEchelon row_echelon(Matrix<Rational> a) {
    RowEchelon result;
    std::size_t row = 0;
    for (std::size_t col = 0; col < a.cols() && row < a.rows(); ++col) {
        // Exact arithmetic: any nonzero pivot will do.
        std::size_t pivot = row;
        while (pivot < a.rows() && a(pivot, col).is_zero()) ++pivot;
        if (pivot == a.rows()) continue;
        swap_rows(a, row, pivot);
        const Rational scale = Rational(1) / a(row, col);
        for (std::size_t c = col; c < a.cols(); ++c) a(row, c) *= scale;
        for (std::size_t r = 0; r < a.rows(); ++r) {
            if (r == row || a(r, col).is_zero()) continue;
            const Rational factor = a(r, col);
            for (std::size_t c = col; c < a.cols(); ++c) a(r, c) -= factor * a(row, c);
        }
        result.pivot_columns.push_back(col);
        ++row;
    }
    result.reduced = std::move(a);
    return result;
}

std::size_t rank(const Matrix<Rational>& a) {
    return row_echelon(a).pivot_columns.size();
}

Rational determinant(const Matrix<Rational>& a) {
    require_square(a.rows(), a.cols(), "determinant of a non-square matrix");
    Matrix<Rational> m = a;
    Rational det(1);
    const std::size_t n = m.rows();
    for (std::size_t col = 0; col < n; ++col) {
        std::size_t pivot = col;
        while (pivot < n && m(pivot, col).is_zero()) ++pivot;
        if (pivot == n) return Rational(0);
        if (pivot != col) {
            swap_rows(m, col, pivot);
            det = -det;
        }
        det *= m(col, col);
        for (std::size_t r = col + 1; r < n; ++r) {
            if (m(r, col).is_zero()) continue;
            const Rational factor = m(r, col) / m(col, col);
            for (std::size_t c = col; c < n; ++c) m(r, c) -= factor * m(col, c);
        }
    }
    return det;
}

std::optional<Matrix<Rational>> solve(const Matrix<Rational>& a, const Matrix<Rational>& b) {
    require_square(a.rows(), a.cols(), "solve with a non-square matrix");
    if (b.rows() != a.rows()) throw std::invalid_argument("solve: right-hand side of the wrong height");
    const std::size_t n = a.rows(), k = b.cols();
    // Reduce [a | b]: a is invertible exactly when its n columns all get pivots.
    Matrix<Rational> augmented(n, n + k);
    for (std::size_t r = 0; r < n; ++r) {
        for (std::size_t c = 0; c < n; ++c) augmented(r, c) = a(r, c);
        for (std::size_t c = 0; c < k; ++c) augmented(r, n + c) = b(r, c);
    }
    const RowEchelon echelon = row_echelon(std::move(augmented));
    const auto& pivots = echelon.pivot_columns;
    if (pivots.size() < n || pivots[n - 1] != n - 1) return std::nullopt;
    Matrix<Rational> x(n, k);
    for (std::size_t r = 0; r < n; ++r)
        for (std::size_t c = 0; c < k; ++c) x(r, c) = echelon.reduced(r, n + c);
    return x;
}

std::optional<Matrix<Rational>> inverse(const Matrix<Rational>& a) {
    return solve(a, Matrix<Rational>::identity(a.rows()));
}

Matrix<Rational> nullspace(const Matrix<Rational>& a) {
    const RowEchelon echelon = row_echelon(a);
    const auto& pivots = echelon.pivot_columns;
    std::vector<bool> is_pivot(a.cols(), false);
    for (std::size_t p : pivots) is_pivot[p] = true;
    Matrix<Rational> basis(a.cols(), a.cols() - pivots.size());
    std::size_t column = 0;
    for (std::size_t free = 0; free < a.cols(); ++free) {
        if (is_pivot[free]) continue;
        // x_free = 1; each pivot variable is minus its row's coefficient of x_free.
        basis(free, column) = Rational(1);
        for (std::size_t r = 0; r < pivots.size(); ++r) basis(pivots[r], column) = -echelon.reduced(r, free);
        ++column;
    }
    return basis;
}

// ---- Doubles ----

namespace {

// Index of the row at or below `col` with the largest |m(row, col)|.
std::size_t partial_pivot(const Matrix<double>& m, std::size_t col) {
    std::size_t best = col;
    for (std::size_t r = col + 1; r < m.rows(); ++r)
        if (std::fabs(m(r, col)) > std::fabs(m(best, col))) best = r;
    return best;
}

} // namespace

std::optional<Matrix<double>> solve(const Matrix<double>& a, const Matrix<double>& b) {
    require_square(a.rows(), a.cols(), "solve with a non-square matrix");
    if (b.rows() != a.rows()) throw std::invalid_argument("solve: right-hand side of the wrong height");
    const std::size_t n = a.rows();
    Matrix<double> m = a, x = b;
    for (std::size_t col = 0; col < n; ++col) {
        const std::size_t pivot = partial_pivot(m, col);
        if (m(pivot, col) == 0.0) return std::nullopt;
        swap_rows(m, col, pivot);
        swap_rows(x, col, pivot);
        for (std::size_t r = col + 1; r < n; ++r) {
            const double factor = m(r, col) / m(col, col);
            if (factor == 0.0) continue;
            for (std::size_t c = col; c < n; ++c) m(r, c) -= factor * m(col, c);
            for (std::size_t c = 0; c < x.cols(); ++c) x(r, c) -= factor * x(col, c);
        }
    }
    for (std::size_t row = n; row-- > 0;) // back substitution
        for (std::size_t c = 0; c < x.cols(); ++c) {
            double v = x(row, c);
            for (std::size_t k = row + 1; k < n; ++k) v -= m(row, k) * x(k, c);
            x(row, c) = v / m(row, row);
        }
    return x;
}

double determinant(const Matrix<double>& a) {
    require_square(a.rows(), a.cols(), "determinant of a non-square matrix");
    const std::size_t n = a.rows();
    Matrix<double> m = a;
    double det = 1.0;
    for (std::size_t col = 0; col < n; ++col) {
        const std::size_t pivot = partial_pivot(m, col);
        if (m(pivot, col) == 0.0) return 0.0;
        if (pivot != col) {
            swap_rows(m, col, pivot);
            det = -det;
        }
        det *= m(col, col);
        for (std::size_t r = col + 1; r < n; ++r) {
            const double factor = m(r, col) / m(col, col);
            for (std::size_t c = col; c < n; ++c) m(r, c) -= factor * m(col, c);
        }
    }
    return det;
}

} // namespace frac::num
