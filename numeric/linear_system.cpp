#include "numeric/linear_system.hpp"

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCore>
#include <Eigen/SparseQR>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <set>

namespace frac::num {

AffineForm AffineForm::variable(std::size_t v) {
    AffineForm f;
    f.terms.emplace(v, Rational(1));
    return f;
}

void AffineForm::add_scaled(const AffineForm& o, const Rational& s) {
    if (s.is_zero()) return;
    constant += o.constant * s;
    for (const auto& [v, a] : o.terms) {
        auto [it, inserted] = terms.emplace(v, a * s);
        if (inserted) continue;
        it->second += a * s;
        if (it->second.is_zero()) terms.erase(it);
    }
}

AffineForm& AffineForm::operator+=(const AffineForm& o) {
    add_scaled(o, Rational(1));
    return *this;
}

AffineForm& AffineForm::operator-=(const AffineForm& o) {
    add_scaled(o, Rational(-1));
    return *this;
}

AffineForm& AffineForm::operator*=(const Rational& s) {
    if (s.is_zero()) return *this = AffineForm{};
    constant *= s;
    for (auto& [v, a] : terms) a *= s;
    return *this;
}

void LinearSystem::add(AffineForm form, std::size_t source) {
    equations_.push_back({std::move(form), source});
}

namespace {

// The elimination's arithmetic. Exact: every nonzero coefficient is a pivot, the sparsest row the best
// (least fill-in). Floating point: a coefficient of at most the tolerance is zero, and the largest
// coefficient of the column is the pivot (partial pivoting), the sparser row on ties.
struct ExactField {
    using Value = Rational;
    static Value from(const Rational& r) { return r; }
    static Rational to_rational(const Value& v) { return v; }
    bool is_zero(const Value& v) const { return v.is_zero(); }
    bool better(const Value&, std::size_t terms, const Value&, std::size_t best_terms) const {
        return terms < best_terms;
    }
};

struct FloatField {
    using Value = double;
    double tolerance;
    static Value from(const Rational& r) { return r.to_double(); }
    static Rational to_rational(Value v) { return Rational::from_double(v); }
    bool is_zero(Value v) const { return std::abs(v) <= tolerance; }
    bool better(Value a, std::size_t terms, Value best, std::size_t best_terms) const {
        return std::abs(a) > std::abs(best) || (std::abs(a) == std::abs(best) && terms < best_terms);
    }
};

template <class Field>
struct Row {
    using Value = typename Field::Value;
    Value constant{};
    std::map<std::size_t, Value> terms;
    std::vector<std::size_t> sources; // sorted, unique

    // this += s * o, dropping the coefficients that become zero; `rows_with` (the rows each variable has
    // a term in) gains this row, `self`, where a term appears and loses it where one is dropped.
    void add_scaled(const Row& o, const Value& s, const Field& field, std::size_t self,
                    std::vector<std::set<std::size_t>>& rows_with) {
        constant += o.constant * s;
        for (const auto& [v, a] : o.terms) {
            auto [it, inserted] = terms.emplace(v, a * s);
            if (!inserted) it->second += a * s;
            if (field.is_zero(it->second)) {
                terms.erase(it);
                if (!inserted) rows_with[v].erase(self);
            } else if (inserted) {
                rows_with[v].insert(self);
            }
        }
    }
};

template <class Field>
struct Reduced {
    std::vector<Row<Field>> rows;
    std::vector<std::optional<std::size_t>> pivot_row; // per variable
    std::optional<std::vector<std::size_t>> conflict;  // the sources of a row 0 = c, c != 0
};

std::vector<std::size_t> merged(const std::vector<std::size_t>& a, const std::vector<std::size_t>& b) {
    std::vector<std::size_t> out;
    out.reserve(a.size() + b.size());
    std::set_union(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(out));
    return out;
}

// Gauss-Jordan elimination on sparse rows of the equations whose source is in `keep` (every one when
// null), taking the columns from the highest variable down, so the pivots are the latest variables that
// can be pivots (the reduced row echelon form of the columns in reverse order) and the free ones are the
// earliest. When inconsistent, the sources that combined into 0 = c.
template <class Field>
Reduced<Field> reduce(const Field& field, const std::vector<LinearSystem::Equation>& equations,
                      std::size_t variables, const std::vector<bool>* keep) {
    Reduced<Field> r;
    for (const LinearSystem::Equation& e : equations) {
        if (keep && !(*keep)[e.source]) continue;
        Row<Field> row;
        row.constant = Field::from(e.form.constant);
        for (const auto& [v, a] : e.form.terms) {
            const auto x = Field::from(a);
            if (!field.is_zero(x)) row.terms.emplace(v, x);
        }
        row.sources = {e.source};
        if (!row.terms.empty() || !field.is_zero(row.constant)) r.rows.push_back(std::move(row));
    }
    r.pivot_row.assign(variables, std::nullopt);
    std::vector<bool> is_pivot(r.rows.size(), false);
    // The rows with a term in each variable, increasing, kept up to date through the fill-in: the pivot
    // search and the elimination visit only those rows, not every row for every variable.
    std::vector<std::set<std::size_t>> rows_with(variables);
    for (std::size_t i = 0; i < r.rows.size(); ++i)
        for (const auto& term : r.rows[i].terms) rows_with[term.first].insert(rows_with[term.first].end(), i);
    for (std::size_t v = variables; v-- > 0;) {
        std::optional<std::size_t> best;
        for (std::size_t i : rows_with[v]) {
            if (is_pivot[i]) continue;
            const auto it = r.rows[i].terms.find(v);
            if (!best || field.better(it->second, r.rows[i].terms.size(), r.rows[*best].terms.at(v),
                                      r.rows[*best].terms.size()))
                best = i;
        }
        if (!best) continue;
        Row<Field>& p = r.rows[*best];
        const auto inverse = typename Field::Value(1) / p.terms.at(v);
        p.constant *= inverse;
        for (auto& [u, a] : p.terms) a *= inverse;
        p.terms[v] = typename Field::Value(1);
        is_pivot[*best] = true;
        r.pivot_row[v] = *best;
        const std::vector<std::size_t> with_v(rows_with[v].begin(), rows_with[v].end());
        for (std::size_t i : with_v) {
            if (i == *best) continue;
            const auto factor = -r.rows[i].terms.at(v);
            r.rows[i].add_scaled(p, factor, field, i, rows_with);
            r.rows[i].terms.erase(v); // exactly eliminated, whatever rounding left
            r.rows[i].sources = merged(r.rows[i].sources, p.sources);
        }
        rows_with[v] = {*best}; // every term in v but the pivot's is gone
    }
    for (std::size_t i = 0; i < r.rows.size(); ++i)
        if (!is_pivot[i] && !field.is_zero(r.rows[i].constant)) {
            if (!r.conflict || r.rows[i].sources.size() < r.conflict->size()) r.conflict = r.rows[i].sources;
        }
    return r;
}

// The numerical rank of the equations' coefficient matrix by a sparse Householder QR with numerical
// column pivoting (Eigen's SparseQR, fill-reducing COLAMD order): a column whose remaining norm is at
// most `tolerance` counts as dependent.
std::size_t qr_rank(const std::vector<LinearSystem::Equation>& equations, std::size_t variables,
                    double tolerance) {
    std::vector<Eigen::Triplet<double>> entries;
    for (std::size_t i = 0; i < equations.size(); ++i)
        for (const auto& [v, x] : equations[i].form.terms)
            entries.emplace_back(static_cast<int>(i), static_cast<int>(v), x.to_double());
    Eigen::SparseMatrix<double> a(static_cast<Eigen::Index>(equations.size()),
                                  static_cast<Eigen::Index>(variables));
    a.setFromTriplets(entries.begin(), entries.end());
    a.makeCompressed();
    Eigen::SparseQR<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> qr;
    qr.setPivotThreshold(tolerance);
    qr.compute(a);
    return static_cast<std::size_t>(qr.rank());
}

template <class Field>
LinearSolution solve_with(const Field& field, const std::vector<LinearSystem::Equation>& equations,
                          std::size_t variables) {
    LinearSolution s;
    Reduced<Field> r = reduce(field, equations, variables, nullptr);
    if (r.conflict) {
        // Deletion filter: drop each source whose removal leaves the rest still inconsistent.
        std::size_t sources = 0;
        for (const LinearSystem::Equation& e : equations) sources = std::max(sources, e.source + 1);
        std::vector<bool> keep(sources, false);
        for (std::size_t k : *r.conflict) keep[k] = true;
        for (std::size_t k : *r.conflict) {
            keep[k] = false;
            if (!reduce(field, equations, variables, &keep).conflict) keep[k] = true;
        }
        s.consistent = false;
        for (std::size_t k = 0; k < sources; ++k)
            if (keep[k]) s.conflict.push_back(k);
        return s;
    }
    s.values.resize(variables);
    for (std::size_t v = 0; v < variables; ++v) {
        if (!r.pivot_row[v]) {
            s.values[v] = AffineForm::variable(v);
            s.free.push_back(v);
            continue;
        }
        // The row is x_v + (the rest) = 0.
        const Row<Field>& row = r.rows[*r.pivot_row[v]];
        AffineForm& x = s.values[v];
        x.constant = -Field::to_rational(row.constant);
        for (const auto& [u, a] : row.terms)
            if (u != v) x.terms.emplace(u, -Field::to_rational(a));
        ++s.rank;
    }
    return s;
}

} // namespace

LinearSolution LinearSystem::solve(std::optional<double> tolerance) const {
    if (!tolerance) return solve_with(ExactField{}, equations_, variables_);
    LinearSolution s = solve_with(FloatField{*tolerance}, equations_, variables_);
    if (s.consistent &&
        static_cast<double>(equations_.size()) * static_cast<double>(variables_) <= qr_check_limit) {
        s.qr_checked = true;
        s.qr_rank = qr_rank(equations_, variables_, *tolerance);
        if (s.qr_rank != s.rank) {
            const std::size_t rank = s.rank, qr = s.qr_rank;
            s = LinearSolution{};
            s.ill_conditioned = true;
            s.rank = rank;
            s.qr_rank = qr;
        }
    }
    return s;
}

} // namespace frac::num
