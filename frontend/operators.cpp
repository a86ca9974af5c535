#include "frontend/operators.hpp"

#include "frontend/diagnostics.hpp"

namespace frac::front {

namespace {

bool all_exact(const std::vector<std::vector<Entry>>& rows) {
    for (const auto& row : rows)
        for (const Entry& e : row)
            if (!e.exact) return false;
    return true;
}

// The homogeneous (d + 1) × (d + 1) matrix with linear part `linear` (d × d) and translation `shift`.
ir::Operator affine(const std::vector<std::vector<Entry>>& linear, const std::vector<Entry>& shift) {
    const std::size_t d = shift.size();
    std::vector<std::vector<Entry>> rows(d + 1, std::vector<Entry>(d + 1, Entry::of(0)));
    for (std::size_t r = 0; r < d; ++r) {
        for (std::size_t c = 0; c < d; ++c) rows[r][c] = linear[r][c];
        rows[r][d] = shift[r];
    }
    rows[d][d] = Entry::of(1);
    return operator_of(rows);
}

std::vector<std::vector<Entry>> diagonal(const std::vector<Entry>& values) {
    std::vector<std::vector<Entry>> m(values.size(), std::vector<Entry>(values.size(), Entry::of(0)));
    for (std::size_t i = 0; i < values.size(); ++i) m[i][i] = values[i];
    return m;
}

LinearValue of_dimension(int d, ir::Operator m) {
    LinearValue v;
    v.transform = true;
    v.dimension = d;
    (d == 2 ? v.r2 : v.r3) = std::move(m);
    return v;
}

} // namespace

const ir::Operator& LinearValue::in(int d) const {
    const std::optional<ir::Operator>& m = !transform || d == 2 ? r2 : r3;
    if (!m) throw InternalError("an operator lowered in a dimension the type checker did not allow");
    return *m;
}

LinearValue LinearValue::matrix(ir::Operator m) {
    LinearValue v;
    v.r2 = std::move(m);
    return v;
}

ir::Operator operator_of(const std::vector<std::vector<Entry>>& rows) {
    const std::size_t n = rows.size(), k = rows.empty() ? 0 : rows[0].size();
    if (all_exact(rows)) {
        num::Matrix<num::Rational> m(n, k);
        for (std::size_t r = 0; r < n; ++r)
            for (std::size_t c = 0; c < k; ++c) m(r, c) = *rows[r][c].exact;
        return ir::Operator::from_exact(m);
    }
    num::Matrix<num::Interval> m(n, k);
    for (std::size_t r = 0; r < n; ++r)
        for (std::size_t c = 0; c < k; ++c) m(r, c) = rows[r][c].enclosure;
    return ir::Operator::from_enclosure(m);
}

ir::Operator compose(const ir::Operator& a, const ir::Operator& b) {
    if (a.exact && b.exact) return ir::Operator::from_exact(*a.exact * *b.exact);
    return ir::Operator::from_enclosure(a.enclosure * b.enclosure);
}

ir::Operator scale_by(const Entry& s, const ir::Operator& a) {
    if (s.exact && a.exact) return ir::Operator::from_exact(*s.exact * *a.exact);
    return ir::Operator::from_enclosure(s.enclosure * a.enclosure);
}

ir::Operator add(const ir::Operator& a, const ir::Operator& b, bool subtract) {
    if (a.exact && b.exact)
        return ir::Operator::from_exact(subtract ? *a.exact - *b.exact : *a.exact + *b.exact);
    return ir::Operator::from_enclosure(subtract ? a.enclosure - b.enclosure : a.enclosure + b.enclosure);
}

namespace {

num::Rational times(const num::Rational& a, const num::Rational& b) {
    return a * b;
}
num::Interval times(num::Interval a, num::Interval b) {
    return num::mul(a, b); // outward rounded
}

template <class T>
num::Matrix<T> kronecker_of(const num::Matrix<T>& a, const num::Matrix<T>& b) {
    num::Matrix<T> k(a.rows() * b.rows(), a.cols() * b.cols());
    for (std::size_t r1 = 0; r1 < a.rows(); ++r1)
        for (std::size_t c1 = 0; c1 < a.cols(); ++c1)
            for (std::size_t r2 = 0; r2 < b.rows(); ++r2)
                for (std::size_t c2 = 0; c2 < b.cols(); ++c2)
                    k(r1 * b.rows() + r2, c1 * b.cols() + c2) = times(a(r1, c1), b(r2, c2));
    return k;
}

} // namespace

ir::Operator kronecker(const ir::Operator& a, const ir::Operator& b) {
    if (a.exact && b.exact) return ir::Operator::from_exact(kronecker_of(*a.exact, *b.exact));
    return ir::Operator::from_enclosure(kronecker_of(a.enclosure, b.enclosure));
}

LinearValue compose(const LinearValue& a, const LinearValue& b) {
    if (a.transform && b.transform) {
        LinearValue v;
        v.transform = true;
        v.dimension = a.dimension ? a.dimension : b.dimension;
        if (a.r2 && b.r2) v.r2 = compose(*a.r2, *b.r2);
        if (a.r3 && b.r3) v.r3 = compose(*a.r3, *b.r3);
        return v;
    }
    // A transform beside a matrix takes the dimension the matrix gives it: rows - 1 on the left of a
    // product, columns - 1 on its right (types.cpp).
    const int da = a.transform ? static_cast<int>(b.in(0).rows()) - 1 : 0;
    const int db = b.transform ? static_cast<int>(a.in(0).cols()) - 1 : 0;
    return LinearValue::matrix(compose(a.in(a.transform ? da : 0), b.in(b.transform ? db : 0)));
}

LinearValue translate(const std::vector<Entry>& v) {
    const int d = static_cast<int>(v.size());
    std::vector<Entry> ones(v.size(), Entry::of(1));
    return of_dimension(d, affine(diagonal(ones), v));
}

LinearValue scale(const std::vector<Entry>& s) {
    if (s.size() > 1) {
        const int d = static_cast<int>(s.size());
        return of_dimension(d, affine(diagonal(s), std::vector<Entry>(s.size(), Entry::of(0))));
    }
    LinearValue v;
    v.transform = true;
    v.r2 = affine(diagonal({s[0], s[0]}), {Entry::of(0), Entry::of(0)});
    v.r3 = affine(diagonal({s[0], s[0], s[0]}), {Entry::of(0), Entry::of(0), Entry::of(0)});
    return v;
}

LinearValue rotate(const Entry& cosine, const Entry& sine) {
    Entry minus_sine = sine;
    if (minus_sine.exact) minus_sine.exact = -*minus_sine.exact;
    minus_sine.enclosure = num::neg(sine.enclosure);
    return of_dimension(2, affine({{cosine, minus_sine}, {sine, cosine}}, {Entry::of(0), Entry::of(0)}));
}

LinearValue shear(const Entry& kx, const Entry& ky) {
    return of_dimension(2, affine({{Entry::of(1), kx}, {ky, Entry::of(1)}}, {Entry::of(0), Entry::of(0)}));
}

LinearValue identity() {
    return scale({Entry::of(1)});
}

ir::Operator controls(const std::vector<std::vector<Entry>>& points) {
    const std::size_t d = points.at(0).size();
    std::vector<std::vector<Entry>> rows(d + 1, std::vector<Entry>(points.size(), Entry::of(1)));
    for (std::size_t c = 0; c < points.size(); ++c)
        for (std::size_t r = 0; r < d; ++r) rows[r][c] = points[c][r];
    return operator_of(rows);
}

} // namespace frac::front
