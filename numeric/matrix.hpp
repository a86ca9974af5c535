// Small dense matrices over exact rationals, intervals and doubles.
//
// Rational matrices are the exact side: Gaussian elimination without rounding (solve, rank, determinant,
// inverse, nullspace) for the constraint solver, which needs to know exactly which parameters are free.
// Interval matrices are the enclosure side: sums and products are computed with outward rounding, so
// every entry contains the exact real result for every choice of real matrices inside the operands.
// Double matrices are for fast approximate work (partial-pivot solve and determinant).
#pragma once

#include "numeric/interval.hpp"
#include "numeric/rational.hpp"

#include <concepts>
#include <cstddef>
#include <initializer_list>
#include <optional>
#include <stdexcept>
#include <vector>

namespace frac::num {

template <typename T>
class Matrix {
public:
    Matrix() = default;
    // rows x cols, every entry T{} (0, or the thin interval [0, 0]).
    Matrix(std::size_t rows, std::size_t cols) : rows_(rows), cols_(cols), entries_(rows * cols) {}
    // Row by row: Matrix<Rational>{{1, 2}, {3, 4}}. Throws std::invalid_argument for ragged rows.
    Matrix(std::initializer_list<std::initializer_list<T>> rows) {
        *this = from_rows(std::vector<std::vector<T>>(rows.begin(), rows.end()));
    }

    static Matrix from_rows(const std::vector<std::vector<T>>& rows) {
        Matrix m(rows.size(), rows.empty() ? 0 : rows.front().size());
        for (std::size_t r = 0; r < rows.size(); ++r) {
            if (rows[r].size() != m.cols_) throw std::invalid_argument("matrix rows of different lengths");
            for (std::size_t c = 0; c < m.cols_; ++c) m(r, c) = rows[r][c];
        }
        return m;
    }
    // A column vector.
    static Matrix column(const std::vector<T>& entries) {
        Matrix m(entries.size(), 1);
        for (std::size_t r = 0; r < entries.size(); ++r) m(r, 0) = entries[r];
        return m;
    }
    static Matrix identity(std::size_t n) {
        Matrix m(n, n);
        for (std::size_t i = 0; i < n; ++i) m(i, i) = T(1);
        return m;
    }

    std::size_t rows() const { return rows_; }
    std::size_t cols() const { return cols_; }
    bool is_square() const { return rows_ == cols_; }

    T& operator()(std::size_t r, std::size_t c) { return entries_[r * cols_ + c]; }
    const T& operator()(std::size_t r, std::size_t c) const { return entries_[r * cols_ + c]; }

    // Entry-wise equality (for intervals: the same bounds, not a statement about the enclosed reals).
    bool operator==(const Matrix&) const = default;

private:
    std::size_t rows_ = 0;
    std::size_t cols_ = 0;
    std::vector<T> entries_; // row-major
};

template <typename T>
Matrix<T> transpose(const Matrix<T>& a) {
    Matrix<T> t(a.cols(), a.rows());
    for (std::size_t r = 0; r < a.rows(); ++r)
        for (std::size_t c = 0; c < a.cols(); ++c) t(c, r) = a(r, c);
    return t;
}

namespace detail {
inline void require_same_shape(std::size_t ar, std::size_t ac, std::size_t br, std::size_t bc) {
    if (ar != br || ac != bc) throw std::invalid_argument("matrix shapes differ");
}
inline void require_product_shape(std::size_t ac, std::size_t br) {
    if (ac != br) throw std::invalid_argument("matrix product of incompatible shapes");
}
} // namespace detail

// Exact or round-to-nearest arithmetic: types with the usual operators (Rational, double). Intervals
// have their own overloads below, which round outward.
template <typename T>
concept FieldLike = requires(T a, T b) {
    { a + b } -> std::convertible_to<T>;
    { a - b } -> std::convertible_to<T>;
    { a* b } -> std::convertible_to<T>;
};

template <FieldLike T>
Matrix<T> operator+(const Matrix<T>& a, const Matrix<T>& b) {
    detail::require_same_shape(a.rows(), a.cols(), b.rows(), b.cols());
    Matrix<T> s(a.rows(), a.cols());
    for (std::size_t r = 0; r < a.rows(); ++r)
        for (std::size_t c = 0; c < a.cols(); ++c) s(r, c) = a(r, c) + b(r, c);
    return s;
}

template <FieldLike T>
Matrix<T> operator-(const Matrix<T>& a, const Matrix<T>& b) {
    detail::require_same_shape(a.rows(), a.cols(), b.rows(), b.cols());
    Matrix<T> s(a.rows(), a.cols());
    for (std::size_t r = 0; r < a.rows(); ++r)
        for (std::size_t c = 0; c < a.cols(); ++c) s(r, c) = a(r, c) - b(r, c);
    return s;
}

template <FieldLike T>
Matrix<T> operator*(const Matrix<T>& a, const Matrix<T>& b) {
    detail::require_product_shape(a.cols(), b.rows());
    Matrix<T> p(a.rows(), b.cols());
    for (std::size_t r = 0; r < a.rows(); ++r)
        for (std::size_t c = 0; c < b.cols(); ++c) {
            T sum{};
            for (std::size_t k = 0; k < a.cols(); ++k) {
                // Exact types skip zero terms (no allocation for them); doubles keep 0 * inf = NaN.
                if constexpr (requires { a(r, k).is_zero(); })
                    if (a(r, k).is_zero() || b(k, c).is_zero()) continue;
                sum = sum + a(r, k) * b(k, c);
            }
            p(r, c) = sum;
        }
    return p;
}

template <FieldLike T>
Matrix<T> operator*(const T& s, const Matrix<T>& a) {
    Matrix<T> p(a.rows(), a.cols());
    for (std::size_t r = 0; r < a.rows(); ++r)
        for (std::size_t c = 0; c < a.cols(); ++c) p(r, c) = s * a(r, c);
    return p;
}

template <FieldLike T>
Matrix<T> operator*(const Matrix<T>& a, const T& s) {
    return s * a;
}

// ---- Interval matrices: every entry encloses the exact result. Any rounding mode on entry; these set
// UpwardRounding themselves and restore the caller's mode. ----

Matrix<Interval> operator+(const Matrix<Interval>& a, const Matrix<Interval>& b);
Matrix<Interval> operator-(const Matrix<Interval>& a, const Matrix<Interval>& b);
Matrix<Interval> operator*(const Matrix<Interval>& a, const Matrix<Interval>& b);
Matrix<Interval> operator*(Interval s, const Matrix<Interval>& a);
Matrix<Interval> operator*(const Matrix<Interval>& a, Interval s);

// The entry-wise tightest enclosure of a rational matrix.
Matrix<Interval> enclose(const Matrix<Rational>& a);

// ---- Exact linear algebra over the rationals. ----

// The reduced row echelon form of a and the column of each pivot (one per nonzero row, increasing).
struct RowEchelon {
    Matrix<Rational> reduced;
    std::vector<std::size_t> pivot_columns;
};
RowEchelon row_echelon(Matrix<Rational> a);

std::size_t rank(const Matrix<Rational>& a);
// Square matrices only (std::invalid_argument otherwise).
Rational determinant(const Matrix<Rational>& a);
// The unique x with a x = b (b: a.rows() x k, for k right-hand sides); nullopt when a is singular.
// a must be square and b must have as many rows (std::invalid_argument otherwise).
std::optional<Matrix<Rational>> solve(const Matrix<Rational>& a, const Matrix<Rational>& b);
// nullopt when a is singular.
std::optional<Matrix<Rational>> inverse(const Matrix<Rational>& a);
// A basis of {x : a x = 0} as the columns of an a.cols() x (a.cols() - rank(a)) matrix: one column per
// non-pivot column j of the reduced form, with x_j = 1 and the other free variables 0.
Matrix<Rational> nullspace(const Matrix<Rational>& a);

// ---- Double matrices: Gaussian elimination with partial pivoting, round-to-nearest. ----

// nullopt when a pivot is exactly zero (a is singular, or singular to working precision).
std::optional<Matrix<double>> solve(const Matrix<double>& a, const Matrix<double>& b);
double determinant(const Matrix<double>& a);

} // namespace frac::num
