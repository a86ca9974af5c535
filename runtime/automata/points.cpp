#include "runtime/automata/points.hpp"

#include "ir/automaton_check.hpp"

#include <fmt/format.h>

#include <stdexcept>

namespace frac::rt {

namespace {

// Solves (C P B - I) c = -C P o for the fixed point o + B c of the affine map P of a space (o: the
// last unit vector, a point of both kinds of space; C o = 0, so c = C x for the point x).
template <typename T>
std::optional<num::Matrix<T>> fixed_point(const num::Matrix<T>& p, ir::Space s, const num::Matrix<T>& basis,
                                          const num::Matrix<T>& coords) {
    const std::size_t n = static_cast<std::size_t>(s.coordinates()), d = n - 1;
    num::Matrix<T> o(n, 1);
    o(n - 1, 0) = T(1);
    num::Matrix<T> lhs = coords * p * basis;
    for (std::size_t i = 0; i < d; ++i) lhs(i, i) = lhs(i, i) - T(1);
    num::Matrix<T> rhs = coords * p * o;
    for (std::size_t i = 0; i < d; ++i) rhs(i, 0) = T(0) - rhs(i, 0);
    if (d == 0) return o;
    const auto c = num::solve(lhs, rhs);
    if (!c) return std::nullopt;
    return basis * *c + o;
}

template <typename T>
num::Matrix<T> convert(const num::Matrix<num::Rational>& m) {
    if constexpr (std::is_same_v<T, num::Rational>) {
        return m;
    } else {
        num::Matrix<double> out(m.rows(), m.cols());
        for (std::size_t r = 0; r < m.rows(); ++r)
            for (std::size_t c = 0; c < m.cols(); ++c) out(r, c) = m(r, c).to_double();
        return out;
    }
}

template <typename T>
std::optional<num::Matrix<T>> point_along(const ir::Automaton& a, const std::vector<std::size_t>& path,
                                          std::size_t cycle_start) {
    auto op = [&](std::size_t arc) -> num::Matrix<T> {
        if constexpr (std::is_same_v<T, num::Rational>)
            return *a.arcs[arc].op.exact;
        else
            return a.arcs[arc].op.nearest;
    };
    const std::size_t q = a.arcs[path[cycle_start]].from;
    const ir::Space s = a.states[q].space;
    num::Matrix<T> p = num::Matrix<T>::identity(static_cast<std::size_t>(s.coordinates()));
    for (std::size_t i = cycle_start; i < path.size(); ++i) p = p * op(path[i]);
    auto x =
        fixed_point<T>(p, s, convert<T>(ir::direction_basis(s)), convert<T>(ir::direction_coordinates(s)));
    if (!x) return std::nullopt;
    for (std::size_t i = cycle_start; i-- > 0;) *x = op(path[i]) * *x;
    return x;
}

bool all_exact(const ir::Automaton& a, const std::vector<std::size_t>& path) {
    for (std::size_t i : path)
        if (!a.arcs[i].op.exact) return false;
    return true;
}

void require_cycle(const std::vector<std::size_t>& path, std::size_t cycle_start) {
    if (cycle_start >= path.size()) throw std::invalid_argument("periodic_point: the cycle is empty");
}

} // namespace

void require_well_formed(const ir::Automaton& a) {
    const std::size_t n = a.states.size();
    if (a.initial >= n) throw std::invalid_argument("the initial state does not exist");
    for (std::size_t i = 0; i < a.arcs.size(); ++i) {
        const ir::Arc& arc = a.arcs[i];
        if (arc.from >= n || arc.to >= n ||
            arc.op.rows() != static_cast<std::size_t>(a.states[arc.from].space.coordinates()) ||
            arc.op.cols() != static_cast<std::size_t>(a.states[arc.to].space.coordinates()))
            throw std::invalid_argument(
                fmt::format("arc {} does not fit the states it connects", ir::arc_name(a, i)));
    }
}

std::vector<double> attractor_point(const ir::Automaton& a, std::size_t state) {
    std::vector<std::size_t> path;                            // the first arcs taken
    std::vector<std::size_t> seen(a.states.size(), SIZE_MAX); // position of each state on the path
    std::size_t q = state;
    while (seen.at(q) == SIZE_MAX) {
        seen[q] = path.size();
        const std::vector<std::size_t> out = a.arcs_from(q);
        if (out.empty())
            throw std::invalid_argument(
                fmt::format("state {} has no transitions: its attractor is empty", a.states[q].name));
        path.push_back(out.front());
        q = a.arcs[out.front()].to;
    }
    const auto x = periodic_point(a, path, seen[q]);
    if (!x)
        throw std::invalid_argument(
            fmt::format("the cycle {} has no unique fixed point (it does not contract)",
                        ir::path_text(a, std::vector(path.begin() + seen[q], path.end()))));
    return *x;
}

std::optional<std::vector<double>>
periodic_point(const ir::Automaton& a, const std::vector<std::size_t>& path, std::size_t cycle_start) {
    require_cycle(path, cycle_start);
    if (all_exact(a, path)) {
        const auto x = point_along<num::Rational>(a, path, cycle_start);
        if (!x) return std::nullopt;
        std::vector<double> out(x->rows());
        for (std::size_t r = 0; r < x->rows(); ++r) out[r] = (*x)(r, 0).to_double();
        return out;
    }
    const auto x = point_along<double>(a, path, cycle_start);
    if (!x) return std::nullopt;
    std::vector<double> out(x->rows());
    for (std::size_t r = 0; r < x->rows(); ++r) out[r] = (*x)(r, 0);
    return out;
}

std::optional<num::Matrix<num::Rational>>
exact_periodic_point(const ir::Automaton& a, const std::vector<std::size_t>& path, std::size_t cycle_start) {
    require_cycle(path, cycle_start);
    if (!all_exact(a, path)) return std::nullopt;
    return point_along<num::Rational>(a, path, cycle_start);
}

num::Matrix<double> output_matrix(const ir::Automaton& a) {
    if (a.projection) return a.projection->nearest;
    return num::Matrix<double>::identity(
        static_cast<std::size_t>(a.states.at(a.initial).space.coordinates()));
}

std::vector<double> output_point(const ir::Automaton& a, const std::vector<double>& column) {
    const num::Matrix<double> p = output_matrix(a);
    if (p.cols() != column.size()) throw std::invalid_argument("output_point: the column has the wrong size");
    std::vector<double> out(p.rows() - 1, 0.0);
    for (std::size_t r = 0; r + 1 < p.rows(); ++r)
        for (std::size_t c = 0; c < column.size(); ++c) out[r] += p(r, c) * column[c];
    return out;
}

} // namespace frac::rt
