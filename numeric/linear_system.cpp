#include "numeric/linear_system.hpp"

#include <algorithm>
#include <iterator>

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

struct LinearSystem::Reduced {
    struct Row {
        AffineForm form;
        std::vector<std::size_t> sources; // sorted, unique
    };
    std::vector<Row> rows;
    std::vector<std::optional<std::size_t>> pivot_row; // per variable
    std::optional<std::vector<std::size_t>> conflict;  // the sources of a row 0 = c, c != 0
};

namespace {

std::vector<std::size_t> merged(const std::vector<std::size_t>& a, const std::vector<std::size_t>& b) {
    std::vector<std::size_t> out;
    out.reserve(a.size() + b.size());
    std::set_union(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(out));
    return out;
}

} // namespace

// Gauss-Jordan elimination on sparse rows, taking the columns from the highest variable down, so the
// pivots are the latest variables that can be pivots (the reduced row echelon form of the columns in
// reverse order) and the free ones are the earliest.
LinearSystem::Reduced LinearSystem::reduce(const std::vector<bool>* keep) const {
    Reduced r;
    for (const Equation& e : equations_)
        if ((!keep || (*keep)[e.source]) && (!e.form.is_constant() || !e.form.constant.is_zero()))
            r.rows.push_back({e.form, {e.source}});
    r.pivot_row.assign(variables_, std::nullopt);
    std::vector<bool> is_pivot(r.rows.size(), false);
    for (std::size_t v = variables_; v-- > 0;) {
        std::optional<std::size_t> best;
        for (std::size_t i = 0; i < r.rows.size(); ++i)
            if (!is_pivot[i] && r.rows[i].form.terms.count(v) &&
                (!best || r.rows[i].form.terms.size() < r.rows[*best].form.terms.size()))
                best = i;
        if (!best) continue;
        Reduced::Row& p = r.rows[*best];
        p.form *= Rational(1) / p.form.terms.at(v);
        is_pivot[*best] = true;
        r.pivot_row[v] = *best;
        for (std::size_t i = 0; i < r.rows.size(); ++i) {
            if (i == *best) continue;
            auto it = r.rows[i].form.terms.find(v);
            if (it == r.rows[i].form.terms.end()) continue;
            const Rational factor = -it->second;
            r.rows[i].form.add_scaled(p.form, factor);
            r.rows[i].sources = merged(r.rows[i].sources, p.sources);
        }
    }
    for (std::size_t i = 0; i < r.rows.size(); ++i)
        if (!is_pivot[i] && !r.rows[i].form.constant.is_zero()) {
            if (!r.conflict || r.rows[i].sources.size() < r.conflict->size()) r.conflict = r.rows[i].sources;
        }
    return r;
}

LinearSolution LinearSystem::solve() const {
    LinearSolution s;
    Reduced r = reduce(nullptr);
    if (r.conflict) {
        // Deletion filter: drop each source whose removal leaves the rest still inconsistent.
        std::size_t sources = 0;
        for (const Equation& e : equations_) sources = std::max(sources, e.source + 1);
        std::vector<bool> keep(sources, false);
        for (std::size_t k : *r.conflict) keep[k] = true;
        for (std::size_t k : *r.conflict) {
            keep[k] = false;
            if (!reduce(&keep).conflict) keep[k] = true;
        }
        s.consistent = false;
        for (std::size_t k = 0; k < sources; ++k)
            if (keep[k]) s.conflict.push_back(k);
        return s;
    }
    s.values.resize(variables_);
    for (std::size_t v = 0; v < variables_; ++v) {
        if (!r.pivot_row[v]) {
            s.values[v] = AffineForm::variable(v);
            s.free.push_back(v);
            continue;
        }
        // The row is x_v + (the rest) = 0.
        AffineForm rest = r.rows[*r.pivot_row[v]].form;
        rest.terms.erase(v);
        s.values[v] = rest * Rational(-1);
        ++s.rank;
    }
    return s;
}

} // namespace frac::num
