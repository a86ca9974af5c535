#include "frontend/topology.hpp"
#include "frontend/cell_import.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <functional>
#include <map>
#include <vector>

namespace frac::front {

namespace {

ExprPtr number(int v, Location loc) {
    auto e = std::make_unique<Expr>();
    e->kind = ExprKind::number;
    e->text = std::to_string(v);
    e->loc = loc;
    return e;
}

// A rows x cols 0/1 matrix with a 1 at (ones[c], c) for every column c.
ExprPtr selection(std::size_t rows, const std::vector<std::size_t>& ones, Location loc) {
    auto m = std::make_unique<Expr>();
    m->kind = ExprKind::matrix;
    m->loc = loc;
    for (std::size_t r = 0; r < rows; ++r) {
        auto row = std::make_unique<Expr>();
        row->kind = ExprKind::tuple;
        row->loc = loc;
        for (std::size_t c = 0; c < ones.size(); ++c) row->kids.push_back(number(ones[c] == r ? 1 : 0, loc));
        m->kids.push_back(std::move(row));
    }
    return m;
}

class Expander {
public:
    Expander(AutomatonDecl& a, Diagnostics& d) : a_(a), b_(*a.bcifs), d_(d) {}

    void run() {
        for (const TopologyDecl& t : std::vector<TopologyDecl>(b_.topologies)) {
            const std::size_t errors = d_.error_count();
            const StateDecl* cell = find_cell(t.cell, t.loc);
            const StateDecl* of = find_cell(t.of, t.of_loc);
            if (!cell || !of || d_.error_count() != errors) continue;
            origin_ = fmt::format("topology {} = {}({}{}) split {}", t.cell, t.kind, t.of,
                                  t.across.empty() ? "" : ", " + t.across,
                                  t.kind == "cube"   ? fmt::format("{} x {} x {}", t.n, t.m, t.l)
                                  : t.kind == "quad" ? fmt::format("{} x {}", t.n, t.m)
                                                     : std::to_string(t.n));
            if (t.kind == "edge")
                edge(t, *cell, *of);
            else if (t.kind == "quad") {
                const StateDecl* across = t.across.empty() ? of : find_cell(t.across, t.across_loc);
                if (across) quad(t, *cell, *of, *across);
            } else if (t.kind == "triangle")
                triangle(t, *cell, *of);
            else
                cube(t, *cell, *of);
        }
    }

private:
    const StateDecl* find_cell(const std::string& name, Location loc) {
        for (const StateDecl& s : a_.states)
            if (s.name == name) return &s;
        d_.error(loc, fmt::format("'{}' is no cell of this bcifs (a topology names cells declared before it)",
                                  name));
        return nullptr;
    }

    bool has(const std::string& cell, const std::string& name) const {
        return std::any_of(b_.operators.begin(), b_.operators.end(),
                           [&](const OperatorDecl& o) { return o.cell == cell && o.name == name; });
    }

    // Adds cell.name unless the model wrote it; value null: unknown.
    void op(const TopologyDecl& t, const std::string& cell, const std::string& name,
            const std::string& target, bool boundary, ExprPtr value) {
        if (has(cell, name)) return;
        OperatorDecl o;
        o.cell = cell;
        o.name = name;
        o.target = target;
        o.boundary = boundary;
        o.loc = o.target_loc = t.loc;
        o.value = std::move(value);
        o.generated = true;
        b_.operators.push_back(std::move(o));
    }

    FactorDecl factor(const std::string& cell, const std::string& name, Location loc) const {
        FactorDecl f;
        f.cell = cell;
        f.name = name;
        f.loc = loc;
        return f;
    }

    // left1 * left2 == right1 * right2, each an operator cell.name.
    void constraint(const TopologyDecl& t, std::pair<std::string, std::string> l1,
                    std::pair<std::string, std::string> l2, std::pair<std::string, std::string> r1,
                    std::pair<std::string, std::string> r2) {
        ConstraintDecl c;
        c.loc = t.loc;
        c.origin = origin_;
        c.left.push_back(factor(l1.first, l1.second, t.loc));
        c.left.push_back(factor(l2.first, l2.second, t.loc));
        c.right.push_back(factor(r1.first, r1.second, t.loc));
        c.right.push_back(factor(r2.first, r2.second, t.loc));
        b_.constraints.push_back(std::move(c));
    }

    static std::string T(int i) { return fmt::format("T{}", i); }

    void edge(const TopologyDecl& t, const StateDecl& e, const StateDecl& v) {
        // Boundary operators the model writes itself may embed any vertex cell (a B-spline's ends depend
        // on several control points); the generated ones take the first and last point.
        const bool written = has(e.name, "B0") && has(e.name, "B1") && has(v.name, "T0");
        if (!sizes_fit(t,
                       written ||
                           (e.space.barycentric && e.space.n >= 2 && v.space.barycentric && v.space.n == 1),
                       "edge(v): the edge is a cell of bary(k), k >= 2, and its vertex a cell of bary(1)",
                       e.space, "and", v.space))
            return;
        const std::size_t k = static_cast<std::size_t>(e.space.n);
        op(t, v.name, "T0", v.name, false, selection(1, {0}, t.loc));
        op(t, e.name, "B0", v.name, true, selection(k, {0}, t.loc));
        op(t, e.name, "B1", v.name, true, selection(k, {k - 1}, t.loc));
        for (int i = 0; i < t.n; ++i) op(t, e.name, T(i), e.name, false, nullptr);
        constraint(t, {e.name, "B0"}, {v.name, "T0"}, {e.name, "T0"}, {e.name, "B0"});
        constraint(t, {e.name, "B1"}, {v.name, "T0"}, {e.name, T(t.n - 1)}, {e.name, "B1"});
        for (int i = 0; i + 1 < t.n; ++i)
            constraint(t, {e.name, T(i)}, {e.name, "B1"}, {e.name, T(i + 1)}, {e.name, "B0"});
    }

    void quad(const TopologyDecl& t, const StateDecl& f, const StateDecl& e, const StateDecl& g) {
        // f in bary(k * h): k points along a row (the bottom and top sides, edge cell e split n), h rows
        // (the left and right sides, edge cell g split m); point p[k * row + column].
        const int k = e.space.n, h = g.space.n;
        if (!sizes_fit(t,
                       written_boundaries(f, 4) || (e.space.barycentric && g.space.barycentric &&
                                                    f.space.barycentric && f.space.n == k * h),
                       &e == &g ? "quad(e): the patch is a cell of bary(k * k) over an edge cell of bary(k)"
                                : "quad(e, g): the patch is a cell of bary(k * h) over edge cells of bary(k) "
                                  "and bary(h)",
                       f.space, "over", e.space))
            return;
        if (&e == &g && t.n != t.m) {
            d_.error(t.loc,
                     fmt::format("quad(e) split {} x {}: both sides are the one edge cell '{}', so they "
                                 "split alike (n x n); quad(e, g) takes a second edge cell for the left and "
                                 "right sides",
                                 t.n, t.m, e.name));
            return;
        }
        if (!edge_pieces(t, e, t.n) || !edge_pieces(t, g, t.m)) return;
        const auto side = [&](int first, int step, int count) {
            std::vector<std::size_t> ones;
            for (int p = 0; p < count; ++p) ones.push_back(static_cast<std::size_t>(first + p * step));
            return selection(static_cast<std::size_t>(k * h), ones, t.loc);
        };
        op(t, f.name, "B0", e.name, true, side(0, 1, k));           // bottom row
        op(t, f.name, "B1", g.name, true, side(0, k, h));           // left column
        op(t, f.name, "B2", g.name, true, side(k - 1, k, h));       // right column
        op(t, f.name, "B3", e.name, true, side(k * (h - 1), 1, k)); // top row
        const int n = t.n, m = t.m;
        const auto sub = [&](int i, int j) { return T(i + n * j); };
        for (int j = 0; j < m; ++j)
            for (int i = 0; i < n; ++i) op(t, f.name, sub(i, j), f.name, false, nullptr);
        for (int i = 0; i < n; ++i) {
            constraint(t, {f.name, "B0"}, {e.name, T(i)}, {f.name, sub(i, 0)}, {f.name, "B0"});
            constraint(t, {f.name, "B3"}, {e.name, T(i)}, {f.name, sub(i, m - 1)}, {f.name, "B3"});
        }
        for (int j = 0; j < m; ++j) {
            constraint(t, {f.name, "B1"}, {g.name, T(j)}, {f.name, sub(0, j)}, {f.name, "B1"});
            constraint(t, {f.name, "B2"}, {g.name, T(j)}, {f.name, sub(n - 1, j)}, {f.name, "B2"});
        }
        for (int j = 0; j < m; ++j)
            for (int i = 0; i < n; ++i) {
                if (i + 1 < n)
                    constraint(t, {f.name, sub(i, j)}, {f.name, "B2"}, {f.name, sub(i + 1, j)},
                               {f.name, "B1"});
                if (j + 1 < m)
                    constraint(t, {f.name, sub(i, j)}, {f.name, "B3"}, {f.name, sub(i, j + 1)},
                               {f.name, "B0"});
            }
    }

    // t in bary(k (k + 1) / 2) over the edge cell e (bary(k), split n): a triangular array of control
    // points p(i, j), i + j <= k - 1, at index j k - j (j - 1) / 2 + i; B0 the side j = 0 (i increasing),
    // B1 the side i = 0 (j increasing), B2 the side i + j = k - 1 (from (k-1, 0) to (0, k-1)). The
    // n^2 sub-triangles: the upward ones U(a, b), a + b <= n - 1, corners (a, b), (a+1, b), (a, b+1)
    // (in units of 1/n), numbered T0 ... first by b then a; then the downward ones D(a, b), a + b <=
    // n - 2, whose corners (a+1, b), (a, b+1), (a+1, b+1) take the places of the reference corners
    // (0, 0), (1, 0), (0, 1) — a reflection, chosen so that every shared side runs the same way in both
    // sub-triangles (no reversal of the edge cell is needed).
    void triangle(const TopologyDecl& t, const StateDecl& f, const StateDecl& e) {
        const int k = e.space.n;
        if (!sizes_fit(t,
                       written_boundaries(f, 3) ||
                           (e.space.barycentric && f.space.barycentric && f.space.n == k * (k + 1) / 2),
                       "triangle(e): the patch is a cell of bary(k (k + 1) / 2) over an edge cell of bary(k)",
                       f.space, "over", e.space))
            return;
        const int n = t.n;
        if (!edge_pieces(t, e, n)) return;
        const auto point = [&](int i, int j) {
            return static_cast<std::size_t>(j * k - j * (j - 1) / 2 + i);
        };
        std::vector<std::size_t> bottom, left, diagonal;
        for (int p = 0; p < k; ++p) {
            bottom.push_back(point(p, 0));
            left.push_back(point(0, p));
            diagonal.push_back(point(k - 1 - p, p));
        }
        const auto rows = static_cast<std::size_t>(f.space.n);
        op(t, f.name, "B0", e.name, true, selection(rows, bottom, t.loc));
        op(t, f.name, "B1", e.name, true, selection(rows, left, t.loc));
        op(t, f.name, "B2", e.name, true, selection(rows, diagonal, t.loc));
        std::map<std::pair<int, int>, std::string> up, down;
        int next = 0;
        for (int b = 0; b < n; ++b)
            for (int a = 0; a + b < n; ++a) up[{a, b}] = T(next++);
        for (int b = 0; b + 1 < n; ++b)
            for (int a = 0; a + b + 1 < n; ++a) down[{a, b}] = T(next++);
        for (int i = 0; i < next; ++i) op(t, f.name, T(i), f.name, false, nullptr);
        for (int p = 0; p < n; ++p) {
            constraint(t, {f.name, "B0"}, {e.name, T(p)}, {f.name, up[{p, 0}]}, {f.name, "B0"});
            constraint(t, {f.name, "B1"}, {e.name, T(p)}, {f.name, up[{0, p}]}, {f.name, "B1"});
            constraint(t, {f.name, "B2"}, {e.name, T(p)}, {f.name, up[{n - 1 - p, p}]}, {f.name, "B2"});
        }
        for (const auto& [ab, d] : down) {
            const auto [a, b] = ab;
            constraint(t, {f.name, d}, {f.name, "B0"}, {f.name, up[{a, b}]}, {f.name, "B2"});
            constraint(t, {f.name, d}, {f.name, "B1"}, {f.name, up[{a + 1, b}]}, {f.name, "B1"});
            constraint(t, {f.name, d}, {f.name, "B2"}, {f.name, up[{a, b + 1}]}, {f.name, "B0"});
        }
    }

    // `fits`, else an error: the rule the cells' spaces break, and what they are.
    bool sizes_fit(const TopologyDecl& t, bool fits, const char* rule, const SpaceDecl& cell,
                   const char* joiner, const SpaceDecl& of) {
        if (!fits) d_.error(t.loc, fmt::format("{}; here {} {} {}", rule, space(cell), joiner, space(of)));
        return fits;
    }

    // Whether the model wrote the boundary operators B0 ... B(count-1) of `cell` (then the topology
    // only generates the subdivision operators and the constraints, for cells of any size).
    bool written_boundaries(const StateDecl& cell, int count) const {
        for (int b = 0; b < count; ++b)
            if (!has(cell.name, fmt::format("B{}", b))) return false;
        return true;
    }

    // Whether the edge cell e has the pieces T0 ... T(n-1) a patch split n along its sides needs; an
    // error otherwise.
    bool edge_pieces(const TopologyDecl& t, const StateDecl& e, int n) {
        for (int i = 0; i < n; ++i)
            if (!has(e.name, T(i))) {
                d_.error(t.loc, fmt::format("{}({}) split {} needs the edge's operators {}.T0 ... {}.T{} (a "
                                            "topology {} = edge(...) split {} before it)",
                                            t.kind, e.name, n, e.name, e.name, n - 1, e.name, n));
                return false;
            }
        return true;
    }

    // c in bary(k^3) over the face cell f (bary(k^2), split n x n): control point p[k^2 z + k y + x];
    // faces B0 z = 0, B1 z = k-1, B2 y = 0, B3 y = k-1, B4 x = 0, B5 x = k-1, each face's (s, t) the two
    // other axes in increasing order (x, y), (x, z), (y, z), so faces agree along the cube's edges;
    // sub-cube T(i + n j + n^2 l) at (x, y, z) = (i, j, l).
    void cube(const TopologyDecl& t, const StateDecl& c, const StateDecl& f) {
        int k = 1;
        while (k * k < f.space.n) ++k;
        if (!sizes_fit(t,
                       written_boundaries(c, 6) || (c.space.barycentric && f.space.barycentric &&
                                                    k * k == f.space.n && c.space.n == k * k * k),
                       "cube(f): the volume is a cell of bary(k^3) over a face cell of bary(k^2)", c.space,
                       "over", f.space))
            return;
        const int n = t.n;
        if (t.m != n || t.l != n) {
            d_.error(t.loc,
                     fmt::format("cube(f) split {} x {} x {}: every face is the one cell '{}', so all axes "
                                 "split alike (n x n x n)",
                                 t.n, t.m, t.l, f.name));
            return;
        }
        for (int i = 0; i < n * n; ++i)
            if (!has(f.name, T(i))) {
                d_.error(t.loc,
                         fmt::format("cube({}) split {} needs the face's operators {}.T0 ... {}.T{} (a "
                                     "topology {} = quad(...) split {} x {} before it)",
                                     f.name, n, f.name, f.name, n * n - 1, f.name, n, n));
                return;
            }
        // Face a (0: z, 1: y, 2: x) at side 0 or k-1: its axes (s, t) in increasing order.
        struct Face {
            int normal, side;
        };
        const std::vector<Face> faces = {{2, 0}, {2, 1}, {1, 0}, {1, 1}, {0, 0}, {0, 1}};
        const auto axes = [](int normal) {
            return normal == 2 ? std::pair{0, 1} : normal == 1 ? std::pair{0, 2} : std::pair{1, 2};
        };
        const auto point = [&](int x, int y, int z) {
            return static_cast<std::size_t>(k * k * z + k * y + x);
        };
        for (std::size_t b = 0; b < faces.size(); ++b) {
            const auto [sa, ta] = axes(faces[b].normal);
            std::vector<std::size_t> ones;
            for (int row = 0; row < k; ++row)
                for (int col = 0; col < k; ++col) {
                    int xyz[3];
                    xyz[faces[b].normal] = faces[b].side ? k - 1 : 0;
                    xyz[sa] = col;
                    xyz[ta] = row;
                    ones.push_back(point(xyz[0], xyz[1], xyz[2]));
                }
            op(t, c.name, fmt::format("B{}", b), f.name, true,
               selection(static_cast<std::size_t>(k * k * k), ones, t.loc));
        }
        const auto sub = [&](int x, int y, int z) { return T(x + n * y + n * n * z); };
        for (int z = 0; z < n; ++z)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) op(t, c.name, sub(x, y, z), c.name, false, nullptr);
        for (std::size_t b = 0; b < faces.size(); ++b) {
            const auto [sa, ta] = axes(faces[b].normal);
            const std::string B = fmt::format("B{}", b);
            for (int j = 0; j < n; ++j)
                for (int i = 0; i < n; ++i) {
                    int xyz[3];
                    xyz[faces[b].normal] = faces[b].side ? n - 1 : 0;
                    xyz[sa] = i;
                    xyz[ta] = j;
                    constraint(t, {c.name, B}, {f.name, T(i + n * j)}, {c.name, sub(xyz[0], xyz[1], xyz[2])},
                               {c.name, B});
                }
        }
        for (int z = 0; z < n; ++z)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    if (x + 1 < n)
                        constraint(t, {c.name, sub(x, y, z)}, {c.name, "B5"}, {c.name, sub(x + 1, y, z)},
                                   {c.name, "B4"});
                    if (y + 1 < n)
                        constraint(t, {c.name, sub(x, y, z)}, {c.name, "B3"}, {c.name, sub(x, y + 1, z)},
                                   {c.name, "B2"});
                    if (z + 1 < n)
                        constraint(t, {c.name, sub(x, y, z)}, {c.name, "B1"}, {c.name, sub(x, y, z + 1)},
                                   {c.name, "B0"});
                }
    }

    static std::string space(const SpaceDecl& s) {
        return s.barycentric ? fmt::format("bary({})", s.n) : fmt::format("R{}", s.n);
    }

    AutomatonDecl& a_;
    BcifsDecl& b_;
    Diagnostics& d_;
    std::string origin_;
};

} // namespace

void expand_topology(Program& program, Diagnostics& diags) {
    // A bcifs that takes cells from another is completed after it (cell_import.hpp): depth first, with
    // the bcifs being completed marked so that a circle is an error, not a recursion without end.
    enum class Progress { started, done };
    std::map<const Item*, Progress> progress;
    std::map<std::string, Item*> by_name;
    for (Item& it : program.items)
        if (it.automaton && it.automaton->bcifs) by_name.emplace(it.name, &it);
    std::function<void(Item&)> complete = [&](Item& it) {
        progress[&it] = Progress::started;
        import_cells(
            *it.automaton,
            [&](const std::string& name, Location loc) -> const Item* {
                const auto found = by_name.find(name);
                if (found == by_name.end()) {
                    diags.error(loc, fmt::format("'{}' is no bcifs (a cell is taken from a bcifs: cell l = "
                                                 "spline.e;)",
                                                 name));
                    return nullptr;
                }
                const auto p = progress.find(found->second);
                if (p != progress.end() && p->second == Progress::started) {
                    diags.error(loc,
                                found->second == &it
                                    ? fmt::format("bcifs '{}' cannot take cells from itself", name)
                                    : fmt::format("taking cells from '{}' is circular: '{}' takes cells, "
                                                  "directly or not, from '{}'",
                                                  name, name, it.name));
                    return nullptr;
                }
                if (p == progress.end()) complete(*found->second);
                return found->second;
            },
            diags);
        Expander(*it.automaton, diags).run();
        progress[&it] = Progress::done;
    };
    for (Item& it : program.items)
        if (it.automaton && it.automaton->bcifs && !progress.count(&it)) complete(it);
}

std::string print_constraints(const Program& program, std::uint32_t file) {
    std::string out;
    for (const Item& it : program.items) {
        if (!it.automaton || !it.automaton->bcifs || it.loc.file != file) continue;
        const BcifsDecl& b = *it.automaton->bcifs;
        out += fmt::format("bcifs {}\n", it.name);
        for (const OperatorDecl& o : b.operators)
            out += fmt::format("  {} {}.{} {} {} = {}{}\n", o.boundary ? "boundary" : "subdivide", o.cell,
                               o.name, o.boundary ? "from" : "->", o.target,
                               o.value             ? print_expr(*o.value)
                               : !o.source.empty() ? fmt::format("{}.{}.{}", o.source, o.source_cell, o.name)
                                                   : "?",
                               o.generated ? "  (generated)" : "");
        for (const ConstraintDecl& c : b.constraints)
            out += fmt::format("  {} == {}{}\n", print_product(c.left), print_product(c.right),
                               c.origin.empty() ? "" : "  (" + c.origin + ")");
    }
    return out;
}

} // namespace frac::front
