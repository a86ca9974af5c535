#include "runtime/automata/surface.hpp"

#include "ir/automaton_check.hpp"
#include "runtime/automata/points.hpp"
#include "runtime/limits.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <map>
#include <numeric>
#include <stdexcept>
#include <type_traits>

namespace frac::rt {

namespace {

using Index = std::int64_t;
using num::Matrix;
using num::Rational;

// The depth in [0, 24], at most 2^26 of what `count()` counts (vertices or triangles), an output in R3
// or less: the checks every tessellation makes before its work. Returns the output dimension.
template <class Count>
int check_tessellation(const ir::Automaton& a, int depth, Count&& count, const char* what,
                       const Matrix<double>* output = nullptr) {
    if (depth < 0 || depth > 24)
        throw std::invalid_argument(fmt::format("tessellation depth {} is outside [0, 24]", depth));
    const double n = count();
    if (n > static_cast<double>(std::uint64_t{1} << 26))
        throw std::invalid_argument(
            fmt::format("a tessellation at depth {} would have {:.3g} {} (at most 2^26)", depth, n, what));
    const int out_dim = output ? static_cast<int>(output->rows()) - 1 : a.output_dimension();
    if (out_dim > 3)
        throw std::invalid_argument(
            fmt::format("{} is drawn in R{}: a mesh needs R3 or less", a.name, out_dim));
    return out_dim;
}

// The points of depth 2 along each shared side are compared by the layout check.
constexpr int check_depth = 2;

Index power(std::size_t n, int p) {
    Index r = 1;
    for (int i = 0; i < p; ++i) r *= static_cast<Index>(n);
    return r;
}

// Grid extent along t at resolution n^m: a curve has no t axis.
Index extent_t(const CellLayout& l, int m) {
    return l.dimension == 2 ? power(l.n_t, m) : 0;
}

// Cell-local coordinates -> the child's own (the inverse of the placement) within an l_s x l_t cell.
std::array<Index, 2> unplace(const CellPlacement& c, Index x, Index y, Index ls, Index lt) {
    if (c.flip_s) x = ls - x;
    if (c.flip_t) y = lt - y;
    return c.swap ? std::array<Index, 2>{y, x} : std::array<Index, 2>{x, y};
}

std::size_t cell_of(const CellLayout& l, Index x, Index y, Index cell_s, Index cell_t) {
    const auto i = std::min<Index>(x / cell_s, static_cast<Index>(l.n_s) - 1);
    const Index j = cell_t == 0 ? 0 : std::min<Index>(y / cell_t, static_cast<Index>(l.n_t) - 1);
    return static_cast<std::size_t>(i) * l.n_t + static_cast<std::size_t>(j);
}

std::string corner_text(const CellLayout& l, Index cs, Index ct) {
    return l.dimension == 2 ? fmt::format("({}, {})", cs, ct) : fmt::format("{}", cs);
}

// Points of the states' parameter grids in their own homogeneous coordinates, through the layout:
// in rationals (T = Rational, every operator exact) or in doubles.
template <typename T>
class Geometry {
public:
    Geometry(const ir::Automaton& a, const SurfaceLayout& l) : a_(a), l_(l), corners_(a.states.size()) {
        if constexpr (std::is_same_v<T, double>)
            for (std::size_t q = 0; q < l.corners.size() && q < corners_.size(); ++q)
                for (std::size_t c = 0; c < 4; ++c)
                    if (!l.corners[q][c].empty()) corners_[q][c] = Matrix<double>::column(l.corners[q][c]);
    }

    // The corners computed so far, rounded.
    std::vector<std::array<std::vector<double>, 4>> corners() const {
        std::vector<std::array<std::vector<double>, 4>> out(corners_.size());
        for (std::size_t q = 0; q < corners_.size(); ++q)
            for (std::size_t c = 0; c < 4; ++c)
                if (const auto& p = corners_[q][c]) {
                    for (std::size_t r = 0; r < p->rows(); ++r) {
                        if constexpr (std::is_same_v<T, Rational>)
                            out[q][c].push_back((*p)(r, 0).to_double());
                        else
                            out[q][c].push_back((*p)(r, 0));
                    }
                }
        return out;
    }

    const Matrix<T>& op(std::size_t arc) const {
        if constexpr (std::is_same_v<T, Rational>)
            return *a_.arcs[arc].op.exact;
        else
            return a_.arcs[arc].op.nearest;
    }

    // Corner (cs, ct) of state q: the point at the address that always takes the corner's cell.
    const Matrix<T>& corner(std::size_t q, Index cs, Index ct) {
        auto& slot = corners_[q][static_cast<std::size_t>(cs + 2 * ct)];
        if (slot) return *slot;
        std::vector<std::size_t> path;
        std::vector<std::array<Index, 3>> seen; // (state, cs, ct) before each arc of the path
        std::size_t s = q;
        Index x = cs, y = ct;
        std::size_t start = 0;
        while (true) {
            const auto again = std::find(seen.begin(), seen.end(), std::array<Index, 3>{Index(s), x, y});
            if (again != seen.end()) {
                start = static_cast<std::size_t>(again - seen.begin());
                break;
            }
            seen.push_back({Index(s), x, y});
            // The corner lies in the corner cell, at that cell's same corner.
            const CellLayout& l = *l_.states[s];
            const std::size_t k = (x == 0 ? 0 : l.n_s - 1) * l.n_t + (y == 0 ? 0 : l.n_t - 1);
            const CellPlacement& c = l.cells[k];
            const auto child = unplace(c, x, y, 1, extent_t(l, 0));
            path.push_back(c.arc);
            s = a_.arcs[c.arc].to;
            x = child[0];
            y = child[1];
        }
        std::optional<Matrix<T>> p;
        if constexpr (std::is_same_v<T, Rational>) {
            p = exact_periodic_point(a_, path, start);
        } else if (const auto v = periodic_point(a_, path, start)) {
            p = Matrix<double>::column(*v);
        }
        if (!p)
            throw std::invalid_argument(
                fmt::format("corner {} of state {} is not defined: the cycle {} has no unique fixed point",
                            corner_text(*l_.states[q], cs, ct), a_.states[q].name,
                            ir::path_text(a_, std::vector(path.begin() + static_cast<std::ptrdiff_t>(start),
                                                          path.end()))));
        slot = std::move(p);
        return *slot;
    }

    // The point at (x, y) of state q's grid of resolution n^m, through the lower cell on shared sides.
    const Matrix<T>& point(std::size_t q, int m, Index x, Index y) {
        const CellLayout& l = *l_.states[q];
        if (m == 0) return corner(q, x, y);
        const std::array<Index, 4> key{Index(q), m, x, y};
        if (const auto it = points_.find(key); it != points_.end()) return it->second;
        const Index cs = power(l.n_s, m - 1), ct = extent_t(l, m - 1);
        const std::size_t k = cell_of(l, x, y, cs, ct);
        return points_[key] = point_via(q, k, m - 1, x - static_cast<Index>(k / l.n_t) * cs,
                                        y - static_cast<Index>(k % l.n_t) * ct);
    }

    // The point at (x, y) of cell k's own grid of resolution n^m, mapped by the cell's operator.
    Matrix<T> point_via(std::size_t q, std::size_t k, int m, Index x, Index y) {
        const CellLayout& l = *l_.states[q];
        const CellPlacement& c = l.cells[k];
        const auto child = unplace(c, x, y, power(l.n_s, m), extent_t(l, m));
        return op(c.arc) * point(a_.arcs[c.arc].to, m, child[0], child[1]);
    }

private:
    const ir::Automaton& a_;
    const SurfaceLayout& l_;
    std::vector<std::array<std::optional<Matrix<T>>, 4>> corners_;
    std::map<std::array<Index, 4>, Matrix<T>> points_; // point(q, m, x, y) for m > 0
};

bool same_point(const Matrix<Rational>& p, const Matrix<Rational>& q) {
    return p == q;
}

bool same_point(const Matrix<double>& p, const Matrix<double>& q) {
    double scale = 1, diff = 0;
    for (std::size_t r = 0; r < p.rows(); ++r) {
        scale = std::max({scale, std::abs(p(r, 0)), std::abs(q(r, 0))});
        diff = std::max(diff, std::abs(p(r, 0) - q(r, 0)));
    }
    return diff <= 1e-9 * scale;
}

std::string cell_text(const ir::Automaton& a, const CellLayout& l, std::size_t k) {
    const std::string arc = ir::arc_name(a, l.cells[k].arc);
    return l.dimension == 2 ? fmt::format("({}, {}) [{}]", k / l.n_t, k % l.n_t, arc)
                            : fmt::format("{} [{}]", k, arc);
}

// Adjacent sub-cells agree at the points of depth check_depth along their common side.
template <typename T>
void check_joins(const ir::Automaton& a, SurfaceLayout& layout, const std::vector<std::size_t>& states) {
    layout.corners.clear();
    Geometry<T> g(a, layout);
    for (const std::size_t q : states) {
        const CellLayout& l = *layout.states[q];
        const Index es = power(l.n_s, check_depth), et = extent_t(l, check_depth);
        const auto fail = [&](std::size_t k1, std::size_t k2, const std::string& where) {
            throw std::invalid_argument(
                fmt::format("sub-cells {} and {} of state {} do not meet: their common side differs at {}",
                            cell_text(a, l, k1), cell_text(a, l, k2), a.states[q].name, where));
        };
        for (std::size_t i = 0; i < l.n_s; ++i)
            for (std::size_t j = 0; j < l.n_t; ++j) {
                const std::size_t k = i * l.n_t + j;
                for (std::size_t y = 0; i + 1 < l.n_s && y <= static_cast<std::size_t>(et); ++y)
                    if (!same_point(g.point_via(q, k, check_depth, es, Index(y)),
                                    g.point_via(q, k + l.n_t, check_depth, 0, Index(y))))
                        fail(k, k + l.n_t,
                             l.dimension == 2 ? fmt::format("t = {}/{} of the cells", y, et) : "their end");
                for (std::size_t x = 0;
                     l.dimension == 2 && j + 1 < l.n_t && x <= static_cast<std::size_t>(es); ++x)
                    if (!same_point(g.point_via(q, k, check_depth, Index(x), et),
                                    g.point_via(q, k + 1, check_depth, Index(x), 0)))
                        fail(k, k + 1, fmt::format("s = {}/{} of the cells", x, es));
            }
        for (Index cs = 0; cs < 2; ++cs)
            for (Index ct = 0; ct <= extent_t(l, 0); ++ct) g.corner(q, cs, ct);
    }
    layout.corners = g.corners();
}

// The states the layout reaches from the root, checking each one's shape.
std::vector<std::size_t> laid_out_states(const ir::Automaton& a, const SurfaceLayout& layout) {
    require_well_formed(a);
    if (layout.root >= a.states.size() || layout.states.size() != a.states.size())
        throw std::invalid_argument("the layout does not fit the automaton's states");
    if (!layout.states[layout.root])
        throw std::invalid_argument(
            fmt::format("the layout has no cells for state {}", a.states[layout.root].name));
    const CellLayout& root = *layout.states[layout.root];
    std::vector<std::size_t> order{layout.root};
    std::vector<bool> seen(a.states.size(), false);
    seen[layout.root] = true;
    for (std::size_t n = 0; n < order.size(); ++n) {
        const std::size_t q = order[n];
        const std::string& name = a.states[q].name;
        if (!layout.states[q])
            throw std::invalid_argument(
                fmt::format("state {} is reached but the layout does not cut it", name));
        const CellLayout& l = *layout.states[q];
        if (l.dimension != 1 && l.dimension != 2)
            throw std::invalid_argument(
                fmt::format("state {}: a layout is a curve (1) or a patch (2)", name));
        if (l.n_s < 2 || (l.dimension == 2 ? l.n_t < 2 : l.n_t != 1))
            throw std::invalid_argument(fmt::format(
                "state {}: {} cells per axis; a curve needs n >= 2 pieces, a patch n_s, n_t >= 2", name,
                l.dimension == 2 ? fmt::format("{} x {}", l.n_s, l.n_t) : fmt::format("{}", l.n_s)));
        if (l.dimension != root.dimension || l.n_s != root.n_s || l.n_t != root.n_t)
            throw std::invalid_argument(fmt::format(
                "state {} is cut {} x {} but state {} is cut {} x {}: a tessellation needs the same cells at "
                "every state",
                name, l.n_s, l.n_t, a.states[layout.root].name, root.n_s, root.n_t));
        const std::vector<std::size_t> arcs = a.arcs_from(q);
        if (l.cells.size() != l.n_s * l.n_t || arcs.size() != l.cells.size())
            throw std::invalid_argument(fmt::format("state {}: {} cells for {} x {} sub-cells and {} arcs",
                                                    name, l.cells.size(), l.n_s, l.n_t, arcs.size()));
        std::vector<bool> used(a.arcs.size(), false);
        for (const CellPlacement& c : l.cells) {
            if (c.arc >= a.arcs.size() || a.arcs[c.arc].from != q || used[c.arc])
                throw std::invalid_argument(
                    fmt::format("state {}: the cells must use each of its arcs once", name));
            used[c.arc] = true;
            if (c.swap && (l.dimension != 2 || l.n_s != l.n_t))
                throw std::invalid_argument(
                    fmt::format("state {}: a swapped cell needs a square patch layout", name));
            if (c.flip_t && l.dimension != 2)
                throw std::invalid_argument(fmt::format("state {}: a curve has no t to reverse", name));
            const std::size_t to = a.arcs[c.arc].to;
            if (!seen[to]) {
                seen[to] = true;
                order.push_back(to);
            }
        }
    }
    return order;
}

bool all_exact(const ir::Automaton& a, const std::vector<std::size_t>& states) {
    for (const std::size_t q : states)
        for (const std::size_t i : a.arcs_from(q))
            if (!a.arcs[i].op.exact) return false;
    return true;
}

// A layout cutting every given state the same way, cells in the given arc order (root) or model order.
SurfaceLayout uniform_layout(const ir::Automaton& a, int dimension, std::size_t n_s, std::size_t n_t,
                             const std::vector<std::size_t>& root_arcs) {
    SurfaceLayout l;
    l.root = a.initial;
    l.states.resize(a.states.size());
    const std::vector<bool> live = ir::reachable_states(a);
    for (std::size_t q = 0; q < a.states.size(); ++q) {
        if (!live[q]) continue;
        CellLayout c;
        c.dimension = dimension;
        c.n_s = n_s;
        c.n_t = n_t;
        for (const std::size_t i : q == a.initial ? root_arcs : a.arcs_from(q)) c.cells.push_back({i});
        l.states[q] = std::move(c);
    }
    return l;
}

std::string layout_name(int dimension, std::size_t n_s, std::size_t n_t) {
    return dimension == 2 ? fmt::format("a {} x {} patch", n_s, n_t)
                          : fmt::format("a curve of {} pieces", n_s);
}

} // namespace

void check_layout(const ir::Automaton& a, SurfaceLayout& layout) {
    const std::vector<std::size_t> states = laid_out_states(a, layout);
    layout.exact = all_exact(a, states);
    if (layout.exact)
        check_joins<Rational>(a, layout, states);
    else
        check_joins<double>(a, layout, states);
}

SurfaceLayout infer_layout(const ir::Automaton& a, const LayoutRequest& request) {
    require_well_formed(a);
    const std::vector<std::size_t> root_arcs = a.arcs_from(a.initial);
    const std::size_t k = root_arcs.size();
    const std::vector<bool> live = ir::reachable_states(a);
    for (std::size_t q = 0; q < a.states.size(); ++q)
        if (live[q] && a.arcs_from(q).size() != k)
            throw std::invalid_argument(fmt::format("cannot infer the layout of {}: state {} has {} arcs but "
                                                    "state {} has {}; a tessellation needs "
                                                    "the same cells at every state",
                                                    a.name, a.states[q].name, a.arcs_from(q).size(),
                                                    a.states[a.initial].name, k));
    // The shapes to try: the request's, else a square patch (k a square) and then a curve.
    struct Shape {
        int dimension;
        std::size_t n_s, n_t;
    };
    std::vector<Shape> shapes;
    if (request.n_s != 0) {
        const int dim = request.dimension != 0 ? request.dimension : (request.n_t > 1 ? 2 : 1);
        shapes.push_back({dim, request.n_s, dim == 2 ? request.n_t : 1});
    } else {
        const auto root = static_cast<std::size_t>(std::lround(std::sqrt(static_cast<double>(k))));
        if (request.dimension != 1 && root >= 2 && root * root == k) shapes.push_back({2, root, root});
        if (request.dimension != 2) shapes.push_back({1, k, 1});
    }
    if (shapes.empty())
        throw std::invalid_argument(fmt::format(
            "cannot infer the layout of {}: its initial state {} has {} arcs, not n x n; give --layout NxM",
            a.name, a.states[a.initial].name, k));
    // The root's arc orders to try: as requested, model order, or every order of a lone state's arcs.
    std::vector<std::vector<std::size_t>> orders;
    if (!request.cells.empty()) {
        std::vector<std::size_t> order;
        for (const std::string& label : request.cells) {
            const auto it = std::find_if(root_arcs.begin(), root_arcs.end(),
                                         [&](std::size_t i) { return a.arcs[i].label == label; });
            if (it == root_arcs.end())
                throw std::invalid_argument(
                    fmt::format("state {} has no arc labelled {}", a.states[a.initial].name, label));
            order.push_back(*it);
        }
        orders.push_back(order);
    } else {
        std::vector<std::size_t> order = root_arcs;
        bool lone = true;
        for (const std::size_t i : root_arcs) lone = lone && a.arcs[i].to == a.initial;
        do orders.push_back(order);
        while (lone && k <= 4 && std::next_permutation(order.begin(), order.end()));
    }
    std::string first_failure;
    for (const Shape& s : shapes)
        for (const auto& order : orders) {
            SurfaceLayout l = uniform_layout(a, s.dimension, s.n_s, s.n_t, order);
            try {
                check_layout(a, l);
            } catch (const std::invalid_argument& e) {
                if (first_failure.empty())
                    first_failure =
                        fmt::format("as {}: {}", layout_name(s.dimension, s.n_s, s.n_t), e.what());
                continue;
            }
            std::vector<std::string> labels;
            for (const std::size_t i : order) labels.push_back(ir::arc_name(a, i));
            l.how = fmt::format("{}, cells {} ({} joins)", layout_name(s.dimension, s.n_s, s.n_t),
                                fmt::join(labels, " "), l.exact ? "exact" : "to 1e-9");
            return l;
        }
    if (request.n_s != 0 || !request.cells.empty())
        throw std::invalid_argument(
            fmt::format("the layout given for {} does not hold ({})", a.name, first_failure));
    throw std::invalid_argument(fmt::format(
        "cannot infer the layout of {} from its operators ({}); give it with --layout NxM and --cells",
        a.name, first_failure));
}

Tessellation tessellate(const ir::Automaton& a, const SurfaceLayout& layout, int depth,
                        const num::Matrix<double>* output) {
    const std::vector<std::size_t> states = laid_out_states(a, layout);
    const CellLayout& root = *layout.states[layout.root];
    const int out_dim = check_tessellation(
        a, depth,
        [&] {
            return (std::pow(static_cast<double>(root.n_s), depth) + 1) *
                   (root.dimension == 2 ? std::pow(static_cast<double>(root.n_t), depth) + 1 : 1);
        },
        "vertices", output);

    Tessellation t;
    t.dimension = root.dimension;
    t.depth = depth;
    t.output_dimension = out_dim;
    t.side_s = static_cast<std::size_t>(power(root.n_s, depth)) + 1;
    t.side_t = static_cast<std::size_t>(extent_t(root, depth)) + 1;
    t.vertices.resize(t.side_s * t.side_t);
    std::vector<std::uint8_t> written(t.vertices.size(), 0);

    // Each state's grid of depth m in its own coordinates (from its corners, exact then rounded when
    // the operators are exact): the walk composes down to depth p - m and maps these points.
    const int m = std::min(depth, root.dimension == 2 ? 3 : 6);
    const Index gs = power(root.n_s, m), gt = extent_t(root, m);
    std::vector<std::vector<double>> grid(a.states.size()); // point g's n_q coordinates at g * n_q
    Geometry<double> geometry(a, layout);
    for (const std::size_t q : states) {
        const auto n = static_cast<std::size_t>(a.states[q].space.coordinates());
        grid[q].resize(static_cast<std::size_t>((gs + 1) * (gt + 1)) * n);
        for (Index x = 0; x <= gs; ++x)
            for (Index y = 0; y <= gt; ++y) {
                const Matrix<double>& p = geometry.point(q, m, x, y);
                for (std::size_t r = 0; r < n; ++r)
                    grid[q][static_cast<std::size_t>(x * (gt + 1) + y) * n + r] = p(r, 0);
            }
    }

    // Composites P T_1 ... T_d (output rows only, 3 x n_q, row-major), one buffer per level.
    const Matrix<double> out = output ? *output : output_matrix(a);
    std::size_t widest = 0;
    for (const std::size_t q : states)
        widest = std::max(widest, static_cast<std::size_t>(a.states[q].space.coordinates()));
    std::vector<std::vector<double>> composite(static_cast<std::size_t>(depth - m) + 1,
                                               std::vector<double>(3 * widest, 0.0));
    const std::size_t n0 = out.cols();
    for (int r = 0; r < out_dim; ++r)
        for (std::size_t c = 0; c < n0; ++c)
            composite[0][static_cast<std::size_t>(r) * n0 + c] = out(static_cast<std::size_t>(r), c);

    // A node's grid coordinates map to the global grid by O + R (x, y).
    struct Frame {
        Index o[2];
        Index r[2][2];
    };
    const auto walk = [&](auto&& self, std::size_t q, int level, const Frame& f) -> void {
        const auto n = static_cast<std::size_t>(a.states[q].space.coordinates());
        const double* mq = composite[static_cast<std::size_t>(level)].data();
        if (level == depth - m) {
            const std::vector<double>& g = grid[q];
            for (Index x = 0; x <= gs; ++x)
                for (Index y = 0; y <= gt; ++y) {
                    const Index i = f.o[0] + f.r[0][0] * x + f.r[0][1] * y;
                    const Index j = f.o[1] + f.r[1][0] * x + f.r[1][1] * y;
                    const auto v = static_cast<std::size_t>(i) * t.side_t + static_cast<std::size_t>(j);
                    if (written[v]) continue;
                    written[v] = 1;
                    const double* p = &g[static_cast<std::size_t>(x * (gt + 1) + y) * n];
                    for (std::size_t r = 0; r < 3; ++r) {
                        double sum = 0;
                        for (std::size_t c = 0; c < n; ++c) sum += mq[r * n + c] * p[c];
                        t.vertices[v][r] = sum;
                    }
                }
            return;
        }
        const CellLayout& l = *layout.states[q];
        const Index ls = power(l.n_s, depth - level - 1), lt = extent_t(l, depth - level - 1);
        double* child = composite[static_cast<std::size_t>(level) + 1].data();
        for (std::size_t k = 0; k < l.cells.size(); ++k) {
            const CellPlacement& c = l.cells[k];
            const std::size_t to = a.arcs[c.arc].to;
            const Matrix<double>& op = a.arcs[c.arc].op.nearest;
            const std::size_t nc = op.cols();
            for (std::size_t r = 0; r < 3; ++r)
                for (std::size_t j = 0; j < nc; ++j) {
                    double sum = 0;
                    for (std::size_t i = 0; i < n; ++i) sum += mq[r * n + i] * op(i, j);
                    child[r * nc + j] = sum;
                }
            // The child's (u, v) sit in the cell at (k_s ls, k_t lt) + flips + P (u, v).
            const Index off[2] = {static_cast<Index>(k / l.n_t) * ls + (c.flip_s ? ls : 0),
                                  static_cast<Index>(k % l.n_t) * lt + (c.flip_t ? lt : 0)};
            const Index sign[2] = {c.flip_s ? -1 : 1, c.flip_t ? -1 : 1};
            Frame g;
            for (int r = 0; r < 2; ++r) {
                g.o[r] = f.o[r] + f.r[r][0] * off[0] + f.r[r][1] * off[1];
                // R P with P = diag(sign) S, S the swap (or identity).
                for (int col = 0; col < 2; ++col) {
                    const int from = c.swap ? 1 - col : col; // the row of P with a nonzero in this column
                    g.r[r][col] = f.r[r][from] * sign[from];
                }
            }
            self(self, to, level + 1, g);
        }
    };
    walk(walk, layout.root, 0, Frame{{0, 0}, {{1, 0}, {0, 1}}});
    if (std::find(written.begin(), written.end(), 0) != written.end())
        throw std::logic_error("tessellate: a grid vertex was not reached");
    require_finite_vertices(t.vertices);
    return t;
}

void require_finite_vertices(const std::vector<std::array<double, 3>>& vertices) {
    for (const std::array<double, 3>& v : vertices)
        if (!(std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2])))
            throw RangeError("the tessellation leaves the range of doubles (a vertex is not finite): scale "
                             "the model's coordinates down");
}

Mesh surface_mesh(const Tessellation& t) {
    if (t.dimension != 2) throw std::invalid_argument("a curve has no triangles: write it as a polyline");
    Mesh mesh;
    mesh.vertices = t.vertices;
    mesh.triangles.reserve(2 * (t.side_s - 1) * (t.side_t - 1));
    for (std::size_t i = 0; i + 1 < t.side_s; ++i)
        for (std::size_t j = 0; j + 1 < t.side_t; ++j) {
            const auto v00 = static_cast<std::uint32_t>(i * t.side_t + j), v01 = v00 + 1;
            const auto v10 = static_cast<std::uint32_t>(v00 + t.side_t), v11 = v10 + 1;
            mesh.triangles.push_back({v00, v10, v11});
            mesh.triangles.push_back({v00, v11, v01});
        }
    return mesh;
}

PatchSurface tessellate_patches(const ir::Automaton& a, int depth) {
    require_well_formed(a);
    const std::vector<std::size_t> arcs = a.arcs_from(a.initial);
    for (const ir::Arc& arc : a.arcs)
        if (arc.to == a.initial)
            throw std::invalid_argument(
                fmt::format("{}: the initial state {} is reached again, so its arcs are no set of patches",
                            a.name, a.states[a.initial].name));
    const ir::Operator out = a.projection
                                 ? *a.projection
                                 : ir::Operator::from_exact(num::Matrix<Rational>::identity(
                                       static_cast<std::size_t>(a.states[a.initial].space.coordinates())));
    PatchSurface result;
    std::vector<Tessellation> patches;
    for (const std::size_t i : arcs) {
        // The patch alone: its state first, drawn through the projection and the arc's operator.
        ir::Automaton patch = a;
        patch.name = fmt::format("{} {}", a.name, ir::arc_name(a, i));
        patch.initial = a.arcs[i].to;
        const ir::Operator& op = a.arcs[i].op;
        patch.projection = out.exact && op.exact ? ir::Operator::from_exact(*out.exact * *op.exact)
                                                 : ir::Operator::from_enclosure(out.enclosure * op.enclosure);
        const SurfaceLayout layout = infer_layout(patch);
        if (layout.states[patch.initial]->dimension != 2)
            throw std::invalid_argument(
                fmt::format("{}: arc {} leads to a curve, not a patch", a.name, ir::arc_name(a, i)));
        patches.push_back(tessellate(patch, layout, depth));
    }
    result.patches = patches.size();

    // All vertices in patch order; sides as lists of global indices.
    std::vector<std::size_t> first(patches.size() + 1, 0);
    for (std::size_t k = 0; k < patches.size(); ++k) first[k + 1] = first[k] + patches[k].vertices.size();
    std::vector<std::array<double, 3>> all;
    all.reserve(first.back());
    for (const Tessellation& t : patches) all.insert(all.end(), t.vertices.begin(), t.vertices.end());
    double extent = 0;
    for (const auto& v : all)
        for (const double c : v) extent = std::max(extent, std::abs(c));
    const double tolerance = 1e-9 * (1 + extent);
    const auto near = [&](std::size_t u, std::size_t v) {
        for (std::size_t r = 0; r < 3; ++r)
            if (std::abs(all[u][r] - all[v][r]) > tolerance) return false;
        return true;
    };
    std::vector<std::vector<std::size_t>> sides;
    for (std::size_t k = 0; k < patches.size(); ++k) {
        const Tessellation& t = patches[k];
        for (int side = 0; side < 4; ++side) {
            std::vector<std::size_t> list;
            const std::size_t count = side < 2 ? t.side_t : t.side_s;
            for (std::size_t c = 0; c < count; ++c) {
                const std::size_t i = side == 0 ? 0 : side == 1 ? t.side_s - 1 : c;
                const std::size_t j = side < 2 ? c : side == 2 ? 0 : t.side_t - 1;
                list.push_back(first[k] + i * t.side_t + j);
            }
            sides.push_back(std::move(list));
        }
    }
    // Joins: equal sides, in the same or the reverse order; each vertex then takes the lowest index.
    std::vector<std::size_t> same(all.size());
    std::iota(same.begin(), same.end(), std::size_t{0});
    const auto find = [&](std::size_t v) {
        while (same[v] != v) v = same[v] = same[same[v]];
        return v;
    };
    for (std::size_t x = 0; x < sides.size(); ++x)
        for (std::size_t y = x + 1; y < sides.size(); ++y) {
            const auto& p = sides[x];
            const auto& q = sides[y];
            if (x / 4 == y / 4 || p.size() != q.size()) continue;
            for (const bool reversed : {false, true}) {
                bool equal = true;
                for (std::size_t c = 0; c < p.size() && equal; ++c)
                    equal = near(p[c], q[reversed ? q.size() - 1 - c : c]);
                if (!equal) continue;
                ++result.joins;
                for (std::size_t c = 0; c < p.size(); ++c) {
                    const std::size_t u = find(p[c]), v = find(q[reversed ? q.size() - 1 - c : c]);
                    same[std::max(u, v)] = std::min(u, v);
                }
                break;
            }
        }
    std::vector<std::uint32_t> index(all.size());
    for (std::size_t v = 0; v < all.size(); ++v)
        if (find(v) == v) {
            index[v] = static_cast<std::uint32_t>(result.mesh.vertices.size());
            result.mesh.vertices.push_back(all[v]);
        }
    for (std::size_t k = 0; k < patches.size(); ++k)
        for (const auto& tri : surface_mesh(patches[k]).triangles) {
            std::array<std::uint32_t, 3> joined{};
            for (std::size_t c = 0; c < 3; ++c) joined[c] = index[find(first[k] + tri[c])];
            result.mesh.triangles.push_back(joined);
        }
    return result;
}

void write_polyline_svg(const Tessellation& t, const std::string& path) {
    double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
    for (const auto& v : t.vertices) {
        x0 = std::min(x0, v[0]);
        x1 = std::max(x1, v[0]);
        y0 = std::min(y0, v[1]);
        y1 = std::max(y1, v[1]);
    }
    // A 1024-unit view on the longer side with a 16-unit margin; y points up.
    const double span = std::max({x1 - x0, y1 - y0, 1e-300}), scale = (1024 - 32) / span;
    const int w = static_cast<int>(std::ceil((x1 - x0) * scale)) + 32;
    const int h = static_cast<int>(std::ceil((y1 - y0) * scale)) + 32;
    std::ofstream os(path);
    if (!os) throw std::runtime_error(fmt::format("cannot write {}", path));
    os << fmt::format(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" viewBox=\"0 0 {} {}\">\n"
        "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n<polyline fill=\"none\" stroke=\"#1f77b4\" "
        "stroke-width=\"1\" points=\"",
        w, h, w, h);
    for (std::size_t i = 0; i < t.vertices.size(); ++i)
        os << fmt::format("{}{:.3f},{:.3f}", i == 0 ? "" : " ", 16 + (t.vertices[i][0] - x0) * scale,
                          h - 16 - (t.vertices[i][1] - y0) * scale);
    os << "\"/>\n</svg>\n";
    if (!os) throw std::runtime_error(fmt::format("cannot write {}", path));
}

void write_polyline_obj(const Tessellation& t, const std::string& path) {
    std::ofstream os(path);
    if (!os) throw std::runtime_error(fmt::format("cannot write {}", path));
    os << fmt::format("# frac curve: {} vertices\n", t.vertices.size());
    for (const auto& v : t.vertices) os << fmt::format("v {} {} {}\n", v[0], v[1], v[2]);
    os << 'l';
    for (std::size_t i = 0; i < t.vertices.size(); ++i) os << ' ' << i + 1;
    os << '\n';
    if (!os) throw std::runtime_error(fmt::format("cannot write {}", path));
}

Mesh tessellate_triangle_patch(const ir::Automaton& a, const ir::TrianglePatch& patch, int depth) {
    require_well_formed(a);
    if (patch.state != a.initial)
        throw std::invalid_argument(fmt::format("{}: the triangle patch {} is not the initial state", a.name,
                                                a.states[patch.state].name));
    const double triangles = std::pow(static_cast<double>(patch.n), 2.0 * depth);
    const int out_dim = check_tessellation(
        a, depth, [&] { return triangles; }, "triangles");
    // Global grid points (i, j), i + j <= N, N = n^p, numbered row by row (j), then i.
    const Index side = power(static_cast<std::size_t>(patch.n), depth);
    const auto vertex_index = [&](Index i, Index j) {
        return static_cast<std::size_t>(j * (side + 1) - j * (j - 1) / 2 + i);
    };
    Mesh mesh;
    mesh.vertices.resize(static_cast<std::size_t>((side + 1) * (side + 2) / 2));
    std::vector<std::uint8_t> written(mesh.vertices.size(), 0);
    mesh.triangles.reserve(static_cast<std::size_t>(triangles));

    // A node's local corner (x, y) of its reference triangle sits at O + R (x, y) in the global grid,
    // x, y in units of the node's side h; its composite P T_1 ... T_d maps its weights to the output.
    struct Frame {
        Index o[2];
        Index r[2][2];
    };
    const std::size_t m = static_cast<std::size_t>(a.states[patch.state].space.coordinates());
    const Matrix<double> out = output_matrix(a);
    std::vector<std::vector<double>> composite(static_cast<std::size_t>(depth) + 1,
                                               std::vector<double>(out.rows() * m, 0.0));
    for (std::size_t r = 0; r < out.rows(); ++r)
        for (std::size_t c = 0; c < m; ++c) composite[0][r * m + c] = out(r, c);
    const auto walk = [&](auto&& self, int level, Index h, const Frame& f) -> void {
        const double* mq = composite[static_cast<std::size_t>(level)].data();
        if (level == depth) {
            // The three corners: the composite's columns at the corner weights, each grid point once.
            const Index local[3][2] = {{0, 0}, {1, 0}, {0, 1}};
            std::array<std::uint32_t, 3> tri{};
            for (int c = 0; c < 3; ++c) {
                const Index i = f.o[0] + f.r[0][0] * local[c][0] + f.r[0][1] * local[c][1];
                const Index j = f.o[1] + f.r[1][0] * local[c][0] + f.r[1][1] * local[c][1];
                const std::size_t v = vertex_index(i, j);
                tri[static_cast<std::size_t>(c)] = static_cast<std::uint32_t>(v);
                if (written[v]) continue;
                written[v] = 1;
                for (int r = 0; r < std::min(out_dim, 3); ++r)
                    mesh.vertices[v][static_cast<std::size_t>(r)] =
                        mq[static_cast<std::size_t>(r) * m + patch.corners[static_cast<std::size_t>(c)]];
            }
            // Counter-clockwise in the parameter plane: a reflected frame swaps two corners.
            if (f.r[0][0] * f.r[1][1] - f.r[0][1] * f.r[1][0] < 0) std::swap(tri[1], tri[2]);
            mesh.triangles.push_back(tri);
            return;
        }
        const Index child = h / patch.n;
        double* next = composite[static_cast<std::size_t>(level) + 1].data();
        const auto descend = [&](std::size_t arc, Index x, Index y, bool reflected) {
            const Matrix<double>& t = a.arcs[arc].op.nearest;
            for (std::size_t r = 0; r < out.rows(); ++r)
                for (std::size_t c = 0; c < m; ++c) {
                    double sum = 0;
                    for (std::size_t k = 0; k < m; ++k) sum += mq[r * m + k] * t(k, c);
                    next[r * m + c] = sum;
                }
            Frame g;
            g.o[0] = f.o[0] + f.r[0][0] * x + f.r[0][1] * y;
            g.o[1] = f.o[1] + f.r[1][0] * x + f.r[1][1] * y;
            // A downward child's x runs along (-1, 1) and its y along (0, 1) of its parent's frame.
            for (int row = 0; row < 2; ++row) {
                g.r[row][0] = reflected ? f.r[row][1] - f.r[row][0] : f.r[row][0];
                g.r[row][1] = f.r[row][1];
            }
            self(self, level + 1, child, g);
        };
        std::size_t k = 0;
        for (Index b = 0; b < patch.n; ++b)
            for (Index c = 0; b + c < patch.n; ++c) descend(patch.up[k++], c * child, b * child, false);
        k = 0;
        for (Index b = 0; b + 1 < patch.n; ++b)
            for (Index c = 0; b + c + 1 < patch.n; ++c)
                descend(patch.down[k++], (c + 1) * child, b * child, true);
    };
    walk(walk, 0, side, Frame{{0, 0}, {{1, 0}, {0, 1}}});
    require_finite_vertices(mesh.vertices);
    return mesh;
}

} // namespace frac::rt
