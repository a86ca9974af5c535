#include "runtime/automata/dimension.hpp"

#include "ir/automaton_check.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace frac::rt {

namespace {

using num::Interval;
using num::Matrix;

// The root of rho(s) = 1 between lo (rho proven > 1) and hi (rho proven < 1), rho decreasing, bracketed
// by two one-sided bisections: the largest s proven below the root and the smallest proven above it.
// (One bisection would stall on an s the enclosure cannot decide, such as an exact root.)
template <class Rho>
Interval bracket_root(Rho&& rho, double lo, double hi, double tolerance) {
    auto squeeze = [&](double yes, double no, auto&& proven) {
        for (int it = 0; it < 200 && std::abs(no - yes) > tolerance / 2; ++it) {
            const double mid = yes + (no - yes) / 2;
            if (mid == yes || mid == no) break;
            (proven(rho(mid)) ? yes : no) = mid;
        }
        return yes;
    };
    const double below = squeeze(lo, hi, [](Interval b) { return b.lo > 1.0; });
    const double above = squeeze(hi, lo, [](Interval b) { return b.hi < 1.0; });
    return Interval(below, above);
}
using num::Rational;

std::string arc_title(const ir::Automaton& a, std::size_t i) {
    const ir::Arc& arc = a.arcs[i];
    return fmt::format("arc {} ({} -> {})", ir::arc_name(a, i), a.states[arc.from].name,
                       a.states[arc.to].name);
}

Matrix<Rational> gram(ir::Space s) {
    const Matrix<Rational> b = ir::direction_basis(s);
    return num::transpose(b) * b;
}

// Whether the linear part is injective: exactly when exact, else on the nearest doubles.
bool injective(const ir::Automaton& a, std::size_t i) {
    const Matrix<Interval> l = ir::linear_part(a, i);
    if (l.rows() < l.cols()) return false;
    if (l.cols() == 0) return true;
    if (const auto e = ir::exact_linear_part(a, i)) return num::rank(*e) == e->cols();
    Matrix<double> m(l.rows(), l.cols());
    for (std::size_t r = 0; r < l.rows(); ++r)
        for (std::size_t c = 0; c < l.cols(); ++c) m(r, c) = num::midpoint(l(r, c));
    return num::determinant(num::transpose(m) * m) != 0.0;
}

} // namespace

SimilarityRatio similarity_ratio(const ir::Automaton& a, std::size_t i) {
    const ir::Arc& arc = a.arcs.at(i);
    const ir::Space from = a.states.at(arc.from).space, to = a.states.at(arc.to).space;
    SimilarityRatio out;
    const Matrix<Rational> gf = gram(from), gt = gram(to);
    const std::string not_one =
        fmt::format("{} is not a similitude: it scales directions by different factors", arc_title(a, i));
    if (to.dimension == 0) { // a point: every map of it is a similitude of ratio 0
        out.similitude = out.exact = true;
        return out;
    }
    if (const auto l = ir::exact_linear_part(a, i)) {
        out.exact = true;
        const Matrix<Rational> x = num::transpose(*l) * gf * *l;
        const Rational r2 = x(0, 0) / gt(0, 0);
        if (!(x == r2 * gt)) {
            out.reason = not_one;
            return out;
        }
        out.similitude = true;
        const num::UpwardRounding up;
        out.ratio = num::sqrt(num::enclose(r2));
        return out;
    }
    const Matrix<Interval> l = ir::linear_part(a, i);
    const Matrix<Interval> x = num::transpose(l) * num::enclose(gf) * l;
    const num::UpwardRounding up;
    Interval r2 = Interval::entire();
    for (std::size_t r = 0; r < x.rows(); ++r)
        for (std::size_t c = 0; c < x.cols(); ++c) {
            const Rational g = gt(r, c);
            if (g.is_zero()) {
                if (!x(r, c).contains(0.0)) r2 = Interval::empty();
            } else {
                r2 = num::intersect(r2, num::div(x(r, c), num::enclose(g)));
            }
        }
    if (r2.is_empty()) {
        out.reason = not_one;
        return out;
    }
    out.similitude = true;
    out.ratio = num::sqrt(num::intersect(r2, Interval(0.0, num::inf)));
    return out;
}

SimilarityDimension similarity_dimension(const ir::Automaton& a, double tolerance) {
    const std::size_t n = a.states.size();
    if (a.initial >= n) throw std::invalid_argument("similarity_dimension: the initial state does not exist");
    for (const ir::Arc& arc : a.arcs)
        if (arc.from >= n || arc.to >= n)
            throw std::invalid_argument("similarity_dimension: an arc connects a missing state");
    const std::vector<bool> live = ir::reachable_states(a);
    int components = 0;
    const std::vector<int> comp = ir::strongly_connected_components(a, live, &components);

    SimilarityDimension out;
    out.method = n == 1 ? "Moran equation" : "Mauldin–Williams spectral radius";
    out.ratios.resize(a.arcs.size());
    for (std::size_t i = 0; i < a.arcs.size(); ++i) {
        const ir::Arc& arc = a.arcs[i];
        if (!live[arc.from]) continue;
        out.ratios[i] = similarity_ratio(a, i);
        if (comp[arc.from] == comp[arc.to]) {
            if (!out.ratios[i].similitude) {
                out.reason = out.ratios[i].reason;
                return out;
            }
        } else if (!injective(a, i)) {
            out.reason = fmt::format("{} is not injective, so it may lower the dimension (not a similitude)",
                                     arc_title(a, i));
            return out;
        }
    }

    Interval best{0.0, 0.0};
    bool any_cycle = false;
    for (int c = 0; c < components; ++c) {
        std::vector<std::size_t> members;
        std::vector<std::size_t> index(n, 0);
        for (std::size_t s = 0; s < n; ++s)
            if (comp[s] == c) {
                index[s] = members.size();
                members.push_back(s);
            }
        std::vector<std::size_t> inner;
        std::vector<std::size_t> out_degree(members.size(), 0);
        for (std::size_t i = 0; i < a.arcs.size(); ++i)
            if (live[a.arcs[i].from] && comp[a.arcs[i].from] == c && comp[a.arcs[i].to] == c) {
                inner.push_back(i);
                ++out_degree[index[a.arcs[i].from]];
            }
        if (inner.empty()) continue; // a transient state: no cycle through it
        any_cycle = true;
        // A single cycle (one inner arc per state) is a finite set of points: dimension 0.
        if (std::all_of(out_degree.begin(), out_degree.end(), [](std::size_t d) { return d == 1; })) continue;

        auto rho = [&](double s) {
            Matrix<Interval> m(members.size(), members.size());
            const num::UpwardRounding up;
            for (std::size_t i : inner) {
                const std::size_t r = index[a.arcs[i].from], k = index[a.arcs[i].to];
                const Interval ratio = out.ratios[i].ratio;
                const Interval term = s == 0.0 ? Interval(1.0) : num::pow(ratio, Interval(s));
                m(r, k) = num::add(m(r, k), term);
            }
            return ir::spectral_radius_bracket(m);
        };
        double lo = 0, hi = 1;
        if (!(rho(lo).lo > 1.0))
            throw std::runtime_error(
                "similarity_dimension: cannot prove that rho(M(0)) > 1 for a branching cycle");
        while (!(rho(hi).hi < 1.0)) {
            hi *= 2;
            if (hi > 1e6) {
                out.reason =
                    "the maps of a cycle do not contract (no s makes the spectral radius of M(s) < 1)";
                return out;
            }
        }
        const Interval root = bracket_root(rho, lo, hi, tolerance);
        best = Interval(std::max(best.lo, root.lo), std::max(best.hi, root.hi));
    }
    if (!any_cycle) {
        out.reason = "no state reachable from the initial state lies on a cycle";
        return out;
    }
    out.defined = true;
    out.bracket = best;
    out.value = best.lo + (best.hi - best.lo) / 2;
    return out;
}

SimilarityDimension fif_box_dimension(const ir::Automaton& a, const std::vector<std::vector<double>>& points,
                                      double tolerance) {
    SimilarityDimension out;
    out.method = a.states.size() == 1 ? "fractal interpolation function: sum |c_i| a_i^(D-1) = 1"
                                      : "recurrent fractal interpolation function: rho(M(D)) = 1";
    if (points.size() < 2 || points.front().size() != 2) {
        out.reason = "the theory gives the box dimension of the graph of a function (t, x), not of a curve";
        return out;
    }
    out.defined = true;
    out.bracket = Interval(1.0);
    out.value = 1;
    // Collinear points: the graph is the segment through them.
    const auto& p0 = points.front();
    const auto& pn = points.back();
    const double scale = std::abs(pn[0] - p0[0]) + std::abs(pn[1] - p0[1]);
    bool collinear = true;
    for (const auto& p : points)
        collinear = collinear && std::abs((pn[0] - p0[0]) * (p[1] - p0[1]) -
                                          (pn[1] - p0[1]) * (p[0] - p0[0])) <= 1e-12 * scale * scale;
    if (collinear) {
        out.method += " (collinear points: a segment, D = 1)";
        return out;
    }
    // Per strongly connected component of the ranges (the pieces are the labelled arcs; an RFIF's union
    // state reaches the ranges by unlabelled identities): the largest root, 1 when rho(M(1)) <= 1.
    const std::vector<bool> live = ir::reachable_states(a);
    int components = 0;
    const std::vector<int> comp = ir::strongly_connected_components(a, live, &components);
    for (int c = 0; c < components; ++c) {
        std::vector<std::size_t> index(a.states.size(), 0), inner;
        std::size_t members = 0;
        for (std::size_t q = 0; q < a.states.size(); ++q)
            if (comp[q] == c) index[q] = members++;
        for (std::size_t i = 0; i < a.arcs.size(); ++i)
            if (!a.arcs[i].label.empty() && live[a.arcs[i].from] && comp[a.arcs[i].from] == c &&
                comp[a.arcs[i].to] == c)
                inner.push_back(i);
        if (inner.empty()) continue;
        auto rho = [&](double dim) {
            Matrix<Interval> m(members, members);
            const num::UpwardRounding up;
            for (const std::size_t i : inner) {
                const auto& op = a.arcs[i].op.enclosure;
                const Interval ratio = num::abs(op(0, 0)), scaling = num::abs(op(1, 1));
                const Interval term =
                    num::mul(scaling, dim == 1.0 ? Interval(1.0) : num::pow(ratio, Interval(dim - 1.0)));
                const std::size_t r = index[a.arcs[i].from], k = index[a.arcs[i].to];
                m(r, k) = num::add(m(r, k), term);
            }
            return ir::spectral_radius_bracket(m);
        };
        if (!(rho(1.0).lo > 1.0)) continue; // D = 1 for this component
        if (!(rho(2.0).hi < 1.0)) {
            out.defined = false;
            out.reason = "rho(M(2)) is not below 1: the pieces do not shrink areas";
            return out;
        }
        const Interval root = bracket_root(rho, 1.0, 2.0, tolerance);
        out.bracket = Interval(std::max(out.bracket.lo, root.lo), std::max(out.bracket.hi, root.hi));
    }
    out.value = out.bracket.lo + (out.bracket.hi - out.bracket.lo) / 2;
    return out;
}

} // namespace frac::rt
