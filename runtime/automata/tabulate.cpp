#include "runtime/automata/tabulate.hpp"

#include "ir/automaton_check.hpp"
#include "runtime/automata/points.hpp"
#include "runtime/automata/tree.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

namespace frac::rt {

namespace {

// The common arc count of the reachable states.
std::size_t arcs_per_state(const ir::Automaton& a) {
    require_well_formed(a);
    const std::vector<bool> live = ir::reachable_states(a);
    std::size_t n = 0;
    for (std::size_t s = 0; s < a.states.size(); ++s) {
        if (!live[s]) continue;
        const std::size_t k = a.arcs_from(s).size();
        if (n == 0) n = k;
        if (k == 0 || k != n)
            throw std::invalid_argument(
                fmt::format("tabulation needs the same number of arcs at every state: {} has {}, {} has {}",
                            a.states[a.initial].name, a.arcs_from(a.initial).size(), a.states[s].name, k));
    }
    return n;
}

// Visits the leaves at depth p in address order with the output value of each.
template <typename Leaf>
void tabulate_leaves(const ir::Automaton& a, int p, Leaf&& leaf) {
    const num::Matrix<double> out = output_matrix(a);
    std::vector<std::vector<double>> start(a.states.size());
    const std::vector<bool> live = ir::reachable_states(a);
    for (std::size_t s = 0; s < a.states.size(); ++s)
        if (live[s]) start[s] = attractor_point(a, s);
    std::vector<std::size_t> position(a.arcs.size()); // the arc's digit at its state
    for (std::size_t s = 0; s < a.states.size(); ++s) {
        const std::vector<std::size_t> arcs = a.arcs_from(s);
        for (std::size_t k = 0; k < arcs.size(); ++k) position[arcs[k]] = k;
    }
    std::vector<double> image, value(out.rows() - 1);
    std::vector<std::size_t> digits;
    walk_tree(a, {p, false}, [&](const TreeNode& node) {
        if (!node.leaf) return;
        const std::vector<double>& x = start[node.state];
        image.assign(node.op->rows(), 0.0);
        for (std::size_t r = 0; r < node.op->rows(); ++r)
            for (std::size_t c = 0; c < x.size(); ++c) image[r] += (*node.op)(r, c) * x[c];
        for (std::size_t r = 0; r + 1 < out.rows(); ++r) {
            double v = 0;
            for (std::size_t c = 0; c < image.size(); ++c) v += out(r, c) * image[c];
            value[r] = v;
        }
        digits.clear();
        for (std::size_t i : *node.address) digits.push_back(position[i]);
        leaf(digits, value);
    });
}

std::uint64_t checked_power(std::size_t base, int p, int factor) {
    if (p < 0 || p > 24)
        throw std::invalid_argument(fmt::format("tabulation depth {} is outside [0, 24]", p));
    const double count = std::pow(static_cast<double>(base), static_cast<double>(p) * factor);
    if (count > static_cast<double>(std::uint64_t{1} << 26))
        throw std::invalid_argument(
            fmt::format("tabulation at depth {} would have {:.3g} values (at most 2^26)", p, count));
    std::uint64_t n = 1;
    for (int i = 0; i < p; ++i) n *= base;
    return n;
}

} // namespace

std::vector<std::size_t> address_digits(std::uint64_t i, std::size_t base, int p) {
    if (base < 1 || p < 0) throw std::invalid_argument("address_digits needs base >= 1 and p >= 0");
    std::vector<std::size_t> d(static_cast<std::size_t>(p));
    for (std::size_t k = d.size(); k-- > 0;) {
        d[k] = static_cast<std::size_t>(i % base);
        i /= base;
    }
    if (i != 0) throw std::invalid_argument("address_digits: i >= base^p");
    return d;
}

std::vector<double> address_point(const ir::Automaton& a, const std::vector<std::size_t>& digits) {
    require_well_formed(a);
    std::size_t q = a.initial;
    num::Matrix<double> op =
        num::Matrix<double>::identity(static_cast<std::size_t>(a.states[q].space.coordinates()));
    for (std::size_t d : digits) {
        const std::vector<std::size_t> arcs = a.arcs_from(q);
        if (d >= arcs.size())
            throw std::invalid_argument(
                fmt::format("digit {} has no arc at state {} ({} arcs)", d, a.states[q].name, arcs.size()));
        op = op * a.arcs[arcs[d]].op.nearest;
        q = a.arcs[arcs[d]].to;
    }
    const std::vector<double> x = attractor_point(a, q);
    std::vector<double> column(op.rows(), 0.0);
    for (std::size_t r = 0; r < op.rows(); ++r)
        for (std::size_t c = 0; c < x.size(); ++c) column[r] += op(r, c) * x[c];
    return output_point(a, column);
}

Tabulation tabulate(const ir::Automaton& a, int p) {
    const std::size_t n = arcs_per_state(a);
    const std::uint64_t count = checked_power(n, p, 1);
    Tabulation t;
    t.base = n;
    t.p = p;
    t.dimension = a.output_dimension();
    t.values.resize(count);
    tabulate_leaves(a, p, [&](const std::vector<std::size_t>& digits, const std::vector<double>& v) {
        std::uint64_t i = 0;
        for (std::size_t d : digits) i = i * n + d;
        t.values[i] = v;
    });
    return t;
}

Tabulation tabulate_surface(const ir::Automaton& a, int p) {
    const std::size_t arcs = arcs_per_state(a);
    const auto n = static_cast<std::size_t>(std::lround(std::sqrt(static_cast<double>(arcs))));
    if (n * n != arcs)
        throw std::invalid_argument(
            fmt::format("a surface tabulation needs N^2 arcs per state (sigma * N + tau), not {}", arcs));
    const std::uint64_t side = checked_power(n, p, 2);
    Tabulation t;
    t.base = n;
    t.p = p;
    t.dimension = a.output_dimension();
    t.values.resize(side * side);
    tabulate_leaves(a, p, [&](const std::vector<std::size_t>& digits, const std::vector<double>& v) {
        std::uint64_t i = 0, j = 0;
        for (std::size_t d : digits) {
            i = i * n + d / n;
            j = j * n + d % n;
        }
        t.values[i * side + j] = v;
    });
    return t;
}

} // namespace frac::rt
