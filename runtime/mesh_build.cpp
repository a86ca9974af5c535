// Surface mesh of a 3D cover. Outline of the construction (see mesh.hpp for the contract):
//
// 1. Lattice faces, plane by plane. For an axis a and a lattice plane a = p, the selected leaves
//    ending at p ("negative side") and starting at p ("positive side") project onto the plane as
//    disjoint squares. Leaves tile the root box, so where neither side has a square a leaf spans
//    the plane (no face). A face with outward normal +a lies where the negative side is selected
//    and the positive side is not; -a the other way round. A sweep over the plane's squares (in the
//    in-plane coordinate v) keeps the cross-section of both sides as sorted runs and yields the two
//    face regions as maximal runs, merged with the identical runs of the following rows into
//    rectangles. Only the leaves touching the plane are visited: no dense 3D grid.
//
// 2. Vertex copies. For a lattice point P, the 8 cells around it (octants) determine the 12 unit
//    faces through P that lie on the surface. Around each of the 6 edge rays from P, 0, 2 or 4 of
//    those faces meet; 4 means two selected cells meeting only along that edge (non-manifold). Two
//    faces are linked at a ray when they are the only two there, or, with four, when they bound the
//    same selected cell (the selected cells are taken as slightly apart). Every face has two rays,
//    every ray links its faces in pairs, so the linked faces form disjoint cycles: the fans of the
//    surface at P. Each cycle is one vertex copy, so every vertex's fan is a single disc. The
//    256-entry table PointTable holds the cycles per configuration.
//
// 3. Non-manifold edges. Along an edge where two selected cells meet only at the edge, the two
//    surface sheets are distinct edges of the mesh if some end point has distinct copies for them;
//    otherwise (both end points are single fans, e.g. two slabs joined by two diagonal pillars) the
//    edge is split by a midpoint with one copy per sheet.
//
// 4. Triangulation without T-junctions. A vertex of the mesh lying on a rectangle's side must be a
//    vertex of that rectangle's triangulation. All vertices except rectangle centres and edge
//    midpoints are rectangle corners, so each rectangle takes every rectangle corner on its sides
//    (found in three sorted "line" indices). No corner lies inside a rectangle and no surface edge
//    crosses one (a face region of one orientation has the same two cells on both sides of every
//    interior line). The rectangle with its side points is a convex polygon with collinear points;
//    it is triangulated as a strip between two opposite sides when the other two sides carry no
//    extra point, else as a fan from a corner whose two sides carry none, else as a fan from its
//    centre. None of these makes a degenerate triangle or puts a vertex inside an edge.
//
// Determinism: every step runs in a fixed order (planes, sweep, sorted indices), so the mesh, and
// the file bytes, depend only on the cover.
#include "runtime/mesh.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <tuple>
#include <unordered_map>

namespace frac::rt {

namespace {

using u32 = std::uint32_t;
using u64 = std::uint64_t;
using Clock = std::chrono::steady_clock;

constexpr u32 no_index = std::numeric_limits<u32>::max();
constexpr std::uint8_t no_cycle = 255;

// ---- Local configurations around a lattice point ----------------------------------------------
//
// Octant t = ox | oy << 1 | oz << 2 of the 2x2x2 cells around a point: o = 1 for the cell on the
// positive side of the point along that axis. A configuration is the 8-bit set of selected
// octants. Face f = 4a + q of the 12 unit faces through the point: normal axis a and quadrant
// q = o_lo | o_hi << 1 over the two other axes (lower axis first); it separates the octants with
// o_a = 0 and o_a = 1. Ray r = 2d + s: the unit edge from the point along axis d, s = 1 positive.

// The two in-plane axes of a plane normal to a, lower first. In a plane sweep they are the
// coordinates u (lower) and v (higher).
constexpr int axis_u(int a) {
    return a == 0 ? 1 : 0;
}
constexpr int axis_v(int a) {
    return a == 2 ? 1 : 2;
}

struct PointTable {
    std::uint8_t cycle[256][12];  // fan (vertex copy) of a surface face, no_cycle off the surface
    std::uint8_t cycles[256];     // number of fans
    bool nonmanifold[256][6];     // ray with four surface faces (two cells meeting at the edge)
    bool sheets_distinct[256][6]; // ... whose two sheets belong to different fans here

    PointTable() {
        for (int cfg = 0; cfg < 256; ++cfg) build(cfg);
    }

private:
    static bool selected(int cfg, int t) { return (cfg >> t) & 1; }
    static int lower_octant(int f) {
        const int a = f / 4, q = f % 4;
        return ((q & 1) << axis_u(a)) | (((q >> 1) & 1) << axis_v(a));
    }
    static bool on_surface(int cfg, int f) {
        const int t0 = lower_octant(f);
        return selected(cfg, t0) != selected(cfg, t0 | (1 << (f / 4)));
    }
    // The selected one of the two cells a surface face separates.
    static int selected_octant(int cfg, int f) {
        const int t0 = lower_octant(f);
        return selected(cfg, t0) ? t0 : t0 | (1 << (f / 4));
    }

    void build(int cfg) {
        int parent[12];
        std::iota(parent, parent + 12, 0);
        const std::function<int(int)> find = [&](int x) {
            return parent[x] == x ? x : parent[x] = find(parent[x]);
        };
        const auto unite = [&](int x, int y) { parent[find(x)] = find(y); };
        int pairs[6][2][2] = {}; // per non-manifold ray: the two faces of each sheet
        for (int d = 0; d < 3; ++d)
            for (int s = 0; s < 2; ++s) {
                const int ray = 2 * d + s;
                int faces[4], n = 0;
                for (int a = 0; a < 3; ++a) {
                    if (a == d) continue;
                    for (int ow = 0; ow < 2; ++ow) {
                        // Quadrant bits over axis_u(a), axis_v(a): one of them is d (set to s).
                        const int bu = axis_u(a) == d ? s : ow, bv = axis_v(a) == d ? s : ow;
                        const int f = 4 * a + bu + 2 * bv;
                        if (on_surface(cfg, f)) faces[n++] = f;
                    }
                }
                nonmanifold[cfg][ray] = n == 4;
                if (n == 2) unite(faces[0], faces[1]);
                if (n == 4) {
                    // Link the faces bounding the same selected cell: the cells are kept apart.
                    int k = 0;
                    for (int i = 0; i < 4; ++i)
                        for (int j = i + 1; j < 4; ++j)
                            if (selected_octant(cfg, faces[i]) == selected_octant(cfg, faces[j])) {
                                unite(faces[i], faces[j]);
                                pairs[ray][k][0] = faces[i];
                                pairs[ray][k][1] = faces[j];
                                ++k;
                            }
                }
            }
        // Number the fans by their smallest face, for a deterministic copy order.
        int id_of_root[12];
        std::fill(id_of_root, id_of_root + 12, -1);
        int next = 0;
        for (int f = 0; f < 12; ++f) {
            if (!on_surface(cfg, f)) {
                cycle[cfg][f] = no_cycle;
                continue;
            }
            const int root = find(f);
            if (id_of_root[root] < 0) id_of_root[root] = next++;
            cycle[cfg][f] = static_cast<std::uint8_t>(id_of_root[root]);
        }
        cycles[cfg] = static_cast<std::uint8_t>(next);
        for (int ray = 0; ray < 6; ++ray)
            sheets_distinct[cfg][ray] =
                nonmanifold[cfg][ray] && cycle[cfg][pairs[ray][0][0]] != cycle[cfg][pairs[ray][1][0]];
    }
};

const PointTable& point_table() {
    static const PointTable table;
    return table;
}

// ---- Plane sweep --------------------------------------------------------------------------------

struct Square {
    u32 u0, u1, v0, v1; // [u0, u1) x [v0, v1) in lattice units
};
struct Run {
    u32 u0, u1; // unit columns [u0, u1)
};
struct Active {
    u32 u0, u1, v1;
};
struct Open {
    u32 u0, u1, v0;
};

// A merged face: [u0, u1] x [v0, v1] in the plane axis = p; outward normal +axis when plus.
struct Rect {
    u32 p, u0, u1, v0, v1;
    std::uint8_t axis, plus;
};

// A rectangle corner with the configuration of the 8 cells around it.
struct Corner {
    std::array<u32, 3> x;
    std::uint8_t cfg;
};

bool covered(const std::vector<Run>& runs, u64 column) {
    const auto it =
        std::upper_bound(runs.begin(), runs.end(), column, [](u64 c, const Run& r) { return c < r.u0; });
    return it != runs.begin() && column < std::prev(it)->u1;
}

// Disjoint sorted squares of one side -> maximal runs of the current cross-section.
void runs_of(const std::vector<Active>& act, std::vector<Run>& out) {
    out.clear();
    for (const Active& s : act) {
        if (!out.empty() && out.back().u1 == s.u0)
            out.back().u1 = s.u1;
        else
            out.push_back({s.u0, s.u1});
    }
}

// a \ b for sorted disjoint maximal runs; the result is again maximal runs.
void subtract(const std::vector<Run>& a, const std::vector<Run>& b, std::vector<Run>& out) {
    out.clear();
    std::size_t j = 0;
    for (const Run& r : a) {
        while (j < b.size() && b[j].u1 <= r.u0) ++j;
        u32 lo = r.u0;
        for (std::size_t k = j; lo < r.u1;) {
            if (k == b.size() || b[k].u0 >= r.u1) {
                out.push_back({lo, r.u1});
                break;
            }
            if (b[k].u0 > lo) out.push_back({lo, b[k].u0});
            lo = std::max(lo, b[k].u1);
            ++k;
        }
    }
}

// Sweeps one plane. Reused across planes to keep its buffers.
class PlaneSweep {
public:
    PlaneSweep(std::vector<Rect>& rects, std::vector<Corner>& corners, u64& unit_faces)
        : rects_(rects), corners_(corners), unit_faces_(unit_faces) {}

    // neg / pos: the squares of the selected leaves ending / starting at the plane, each sorted by
    // (v0, u0).
    void run(int axis, u32 p, const std::vector<Square>& neg, const std::vector<Square>& pos) {
        axis_ = axis;
        p_ = p;
        for (auto* v : {&act_[0], &act_[1]}) v->clear();
        for (auto* v : {&prev_[0], &prev_[1], &cur_[0], &cur_[1]}) v->clear();
        open_[0].clear();
        open_[1].clear();
        const std::size_t first_corner = corners_.size();
        const std::vector<Square>* side[2] = {&neg, &pos};
        std::size_t next[2] = {0, 0};
        for (;;) {
            u64 v = std::numeric_limits<u64>::max();
            for (int s = 0; s < 2; ++s) {
                if (next[s] < side[s]->size()) v = std::min<u64>(v, (*side[s])[next[s]].v0);
                for (const Active& a : act_[s]) v = std::min<u64>(v, a.v1);
            }
            if (v == std::numeric_limits<u64>::max()) break;
            const auto vv = static_cast<u32>(v);
            for (int s = 0; s < 2; ++s) {
                advance(act_[s], *side[s], next[s], vv);
                runs_of(act_[s], cur_[s]);
            }
            subtract(cur_[0], cur_[1], face_[1]); // negative side selected: outward +axis
            subtract(cur_[1], cur_[0], face_[0]); // positive side selected: outward -axis
            update(open_[1], face_[1], true, vv);
            update(open_[0], face_[0], false, vv);
            std::swap(prev_[0], cur_[0]);
            std::swap(prev_[1], cur_[1]);
        }
        // Most corners are shared by several rectangles of the plane: keep one record per point.
        const auto first = corners_.begin() + static_cast<std::ptrdiff_t>(first_corner);
        std::sort(first, corners_.end(), [](const Corner& a, const Corner& b) { return a.x < b.x; });
        corners_.erase(
            std::unique(first, corners_.end(), [](const Corner& a, const Corner& b) { return a.x == b.x; }),
            corners_.end());
    }

private:
    // Drops the squares ending at v and merges in those starting at v (sorted by u0).
    void advance(std::vector<Active>& act, const std::vector<Square>& sq, std::size_t& next, u32 v) {
        act.erase(std::remove_if(act.begin(), act.end(), [v](const Active& a) { return a.v1 <= v; }),
                  act.end());
        if (next >= sq.size() || sq[next].v0 != v) return;
        merged_.clear();
        std::size_t i = 0;
        while (i < act.size() || (next < sq.size() && sq[next].v0 == v)) {
            if (next < sq.size() && sq[next].v0 == v && (i == act.size() || sq[next].u0 < act[i].u0)) {
                merged_.push_back({sq[next].u0, sq[next].u1, sq[next].v1});
                ++next;
            } else {
                merged_.push_back(act[i++]);
            }
        }
        act.swap(merged_);
    }

    // Keeps the open rectangles whose run continues, closes the others at v, opens the new runs.
    void update(std::vector<Open>& open, const std::vector<Run>& runs, bool plus, u32 v) {
        kept_.clear();
        std::size_t i = 0, j = 0;
        while (i < open.size() || j < runs.size()) {
            if (i < open.size() && j < runs.size() && open[i].u0 == runs[j].u0 && open[i].u1 == runs[j].u1) {
                kept_.push_back(open[i]);
                ++i;
                ++j;
            } else if (j == runs.size() || (i < open.size() && open[i].u0 <= runs[j].u0)) {
                const Open& o = open[i++];
                rects_.push_back({p_, o.u0, o.u1, o.v0, v, static_cast<std::uint8_t>(axis_),
                                  static_cast<std::uint8_t>(plus)});
                unit_faces_ += static_cast<u64>(o.u1 - o.u0) * (v - o.v0);
                corner(o.u0, v);
                corner(o.u1, v);
            } else {
                kept_.push_back({runs[j].u0, runs[j].u1, v});
                corner(runs[j].u0, v);
                corner(runs[j].u1, v);
                ++j;
            }
        }
        open.swap(kept_);
    }

    // Records the point (u, v) of the plane with its cell configuration: rows v - 1 and v are the
    // previous and the current cross-section, columns u - 1 and u.
    void corner(u32 u, u32 v) {
        const int a = axis_, au = axis_u(a), av = axis_v(a);
        int cfg = 0;
        for (int s = 0; s < 2; ++s)
            for (int du = 0; du < 2; ++du) {
                if (u == 0 && du == 0) continue;
                const u64 column = static_cast<u64>(u) - 1 + static_cast<u64>(du);
                const int base = (s << a) | (du << au);
                if (covered(prev_[s], column)) cfg |= 1 << base;
                if (covered(cur_[s], column)) cfg |= 1 << (base | (1 << av));
            }
        Corner c;
        c.x[static_cast<std::size_t>(a)] = p_;
        c.x[static_cast<std::size_t>(au)] = u;
        c.x[static_cast<std::size_t>(av)] = v;
        c.cfg = static_cast<std::uint8_t>(cfg);
        corners_.push_back(c);
    }

    std::vector<Rect>& rects_;
    std::vector<Corner>& corners_;
    u64& unit_faces_;
    int axis_ = 0;
    u32 p_ = 0;
    std::vector<Active> act_[2], merged_;
    std::vector<Run> prev_[2], cur_[2], face_[2]; // index 0: negative side / outward -axis
    std::vector<Open> open_[2], kept_;
};

// ---- Selected leaves, grouped for the sweeps ----------------------------------------------------

struct Lattice {
    int depth = 0, split = 2;
    u64 n = 1;                            // split^depth: unit cells per axis
    std::vector<u64> cell_size;           // per level, in lattice units
    std::vector<u32> selected;            // indices into r.cells, grouped by level, each level in cell order
    std::vector<std::size_t> level_begin; // depth + 2 offsets into selected
};

bool is_selected(CellClass c, MeshSelection s) {
    switch (s) {
    case MeshSelection::inside: return c == CellClass::inside;
    case MeshSelection::inside_and_boundary: return c == CellClass::inside || c == CellClass::boundary;
    case MeshSelection::boundary: return c == CellClass::boundary;
    }
    return false;
}

void require_3d_cells(const Cover& r, const char* what) {
    if (r.dimension() != 3) throw std::invalid_argument(fmt::format("{} needs a 3D cover", what));
    if (r.cells.empty())
        throw std::invalid_argument(
            fmt::format("{} needs the cells: run subdivide with keep_cells = true", what));
}

Lattice make_lattice(const Cover& r, MeshSelection selection) {
    require_3d_cells(r, "mesh_cover");
    Lattice L;
    L.depth = r.depth;
    L.split = r.split;
    if (L.depth < 0 || L.split < 2 || L.split > 4)
        throw std::invalid_argument("mesh_cover: the cover's depth or split is out of range");
    L.n = r.cells_per_axis(L.depth);
    // Doubled lattice coordinates (0..2n) must fit in 32 bits; the cell indices too.
    if (2 * L.n >= (u64{1} << 32) || r.cells.size() >= no_index)
        throw std::invalid_argument("mesh_cover: the cover is too large (2 * split^depth or its cell count "
                                    "exceeds 32 bits)");
    for (int k = 0; k <= L.depth; ++k) L.cell_size.push_back(L.n / r.cells_per_axis(k));
    L.level_begin.assign(static_cast<std::size_t>(L.depth) + 2, 0);
    int level = 0;
    for (std::size_t i = 0; i < r.cells.size(); ++i) {
        const Cell& c = r.cells[i];
        if (c.level < level || c.level > L.depth)
            throw std::invalid_argument("mesh_cover: the cells are not ordered by level");
        while (level < c.level) L.level_begin[static_cast<std::size_t>(++level)] = L.selected.size();
        if (is_selected(c.cls, selection)) L.selected.push_back(static_cast<u32>(i));
    }
    while (level <= L.depth) L.level_begin[static_cast<std::size_t>(++level)] = L.selected.size();
    return L;
}

u32 cell_coord(const Cell& c, int axis) {
    return axis == 0 ? c.ix : axis == 1 ? c.iy : c.iz;
}

// The selected cells of one level ordered by their coordinate along `axis`, stably (so that within
// a plane they stay ordered by (v, u)), and the ranges of equal coordinate.
struct LevelOrder {
    std::vector<u32> cells;
    struct Group {
        u32 key;
        std::size_t begin, end;
    };
    std::vector<Group> groups;
};

LevelOrder order_level(const Cover& r, const u32* sel, std::size_t count, int axis, u64 per_axis) {
    LevelOrder lo;
    lo.cells.assign(sel, sel + count);
    const auto key = [&](u32 i) { return cell_coord(r.cells[i], axis); };
    const auto by_key = [&](u32 x, u32 y) { return key(x) < key(y); };
    // Subdivision results store each level z-major, hence already ordered by iz.
    if (axis == 2 && !std::is_sorted(lo.cells.begin(), lo.cells.end(), by_key)) {
        std::stable_sort(lo.cells.begin(), lo.cells.end(), by_key);
    } else if (axis != 2) {
        if (per_axis <= 4 * static_cast<u64>(count) + 1024) { // counting sort
            std::vector<std::size_t> start(static_cast<std::size_t>(per_axis) + 1, 0);
            for (std::size_t i = 0; i < count; ++i) ++start[key(sel[i]) + 1];
            for (std::size_t k = 1; k < start.size(); ++k) start[k] += start[k - 1];
            for (std::size_t i = 0; i < count; ++i) lo.cells[start[key(sel[i])]++] = sel[i];
        } else {
            std::stable_sort(lo.cells.begin(), lo.cells.end(), by_key);
        }
    }
    for (std::size_t i = 0; i < lo.cells.size();) {
        std::size_t j = i;
        const u32 k = key(lo.cells[i]);
        while (j < lo.cells.size() && key(lo.cells[j]) == k) ++j;
        lo.groups.push_back({k, i, j});
        i = j;
    }
    return lo;
}

// Runs the sweeps of every plane normal to `axis`.
void sweep_axis(const Cover& r, const Lattice& L, int axis, PlaneSweep& sweep) {
    const int au = axis_u(axis), av = axis_v(axis);
    std::vector<LevelOrder> orders(static_cast<std::size_t>(L.depth) + 1);
    std::vector<u64> planes;
    for (int k = 0; k <= L.depth; ++k) {
        const auto ks = static_cast<std::size_t>(k);
        const std::size_t b = L.level_begin[ks], e = L.level_begin[ks + 1];
        if (b == e) continue;
        orders[ks] = order_level(r, L.selected.data() + b, e - b, axis, r.cells_per_axis(k));
        for (const auto& g : orders[ks].groups) {
            planes.push_back(g.key * L.cell_size[ks]);
            planes.push_back((g.key + u64{1}) * L.cell_size[ks]);
        }
    }
    std::sort(planes.begin(), planes.end());
    planes.erase(std::unique(planes.begin(), planes.end()), planes.end());

    std::vector<std::size_t> cursor(orders.size(), 0);
    std::vector<Square> side[2];
    for (const u64 p : planes) {
        side[0].clear();
        side[1].clear();
        for (std::size_t k = 0; k < orders.size(); ++k) {
            const LevelOrder& o = orders[k];
            const u64 s = L.cell_size[k];
            if (o.groups.empty()) continue;
            // p on the level's grid: cells with key j start at p, with key j - 1 end at p. Off the
            // grid: cells with key j span the plane; they count on both sides (no face, but the
            // cell configurations at the plane's points need them).
            const u64 j = p / s;
            const bool on_grid = p % s == 0;
            std::size_t& c = cursor[k];
            while (c < o.groups.size() && o.groups[c].key + u64{on_grid ? 1u : 0u} < j) ++c;
            for (std::size_t g = c; g < o.groups.size() && o.groups[g].key <= j; ++g) {
                const bool starts = o.groups[g].key == j;
                for (int sd = 0; sd < 2; ++sd) {
                    if (on_grid && (sd == 1) != starts) continue;
                    for (std::size_t i = o.groups[g].begin; i < o.groups[g].end; ++i) {
                        const Cell& cell = r.cells[o.cells[i]];
                        const auto u = static_cast<u32>(cell_coord(cell, au) * s);
                        const auto v = static_cast<u32>(cell_coord(cell, av) * s);
                        side[sd].push_back({u, static_cast<u32>(u + s), v, static_cast<u32>(v + s)});
                    }
                }
            }
        }
        // One level's squares come in cell order, which is (v, u) order; several levels interleave.
        const auto by_row = [](const Square& x, const Square& y) {
            return std::tie(x.v0, x.u0) < std::tie(y.v0, y.u0);
        };
        for (auto& sq : side)
            if (!std::is_sorted(sq.begin(), sq.end(), by_row)) std::sort(sq.begin(), sq.end(), by_row);
        sweep.run(axis, static_cast<u32>(p), side[0], side[1]);
    }
}

// ---- Triangulation ------------------------------------------------------------------------------

// Sort key of a point for the line index along axis d: (lower other axis, higher other axis, d).
std::array<u32, 3> line_key(const std::array<u32, 3>& x, int d) {
    return {x[static_cast<std::size_t>(axis_u(d))], x[static_cast<std::size_t>(axis_v(d))],
            x[static_cast<std::size_t>(d)]};
}

struct MidKey {
    std::array<u32, 3> x2; // doubled coordinates
    u32 sheet;             // the selected octant the sheet bounds
    bool operator==(const MidKey&) const = default;
};
struct MidHash {
    std::size_t operator()(const MidKey& k) const {
        u64 h = k.x2[0];
        h = h * 0x9E3779B97F4A7C15ull ^ k.x2[1];
        h = h * 0x9E3779B97F4A7C15ull ^ k.x2[2];
        h = h * 0x9E3779B97F4A7C15ull ^ k.sheet;
        return static_cast<std::size_t>(h ^ (h >> 29));
    }
};

class Triangulator {
public:
    Triangulator(const std::vector<Corner>& corners, const std::vector<Rect>& rects, Mesh& mesh)
        : corners_(corners), rects_(rects), tri_(mesh.triangles), stats_(mesh.stats), table_(point_table()) {
        // Line indices: corners (sorted by x, y, z) already form the index along z; along x and y the
        // keys are stored with the corner index, so that searches read one array.
        for (int d = 0; d < 2; ++d) {
            auto& idx = line_[d];
            idx.resize(corners_.size());
            for (std::size_t i = 0; i < corners_.size(); ++i)
                idx[i] = {line_key(corners_[i].x, d), static_cast<u32>(i)};
            std::sort(idx.begin(), idx.end(),
                      [](const LineEntry& a, const LineEntry& b) { return a.key < b.key; });
        }
        // Vertex ids: the copies of each corner point in point order (every copy is used: each fan at
        // a point belongs to a rectangle with the point on its boundary), then the centres and
        // midpoints in the order they are made.
        copy_base_.resize(corners_.size() + 1);
        u64 copies = 0;
        for (std::size_t c = 0; c < corners_.size(); ++c) {
            copy_base_[c] = static_cast<u32>(copies);
            copies += table_.cycles[corners_[c].cfg];
            if (copies >= no_index)
                throw std::length_error("mesh_cover: too many vertices for 32-bit indices");
        }
        copy_base_[corners_.size()] = static_cast<u32>(copies);
    }

    void run() {
        for (std::size_t i = 0; i < rects_.size(); ++i) rect(i);
        stats_.nonmanifold_edges = nonmanifold_sides_ / 4; // each such edge bounds four rectangles
        stats_.split_edges = mids_.size() / 2;             // two sheets, one midpoint each
    }

    // Copies of corner c: ids copy_base()[c] .. copy_base()[c + 1] - 1, in fan order.
    std::vector<u32>& copy_base() { return copy_base_; }
    // Doubled lattice coordinates of the centres and midpoints, ids copy_base().back() + i.
    std::vector<std::array<u32, 3>>& extra() { return extra_; }

private:
    struct BPoint {
        u32 pid; // provisional vertex id
        u32 t2;  // doubled coordinate along the side
    };

    // Corner indices on the line along axis d through `x`, with coordinate d in [lo, hi], ascending.
    void points_on(int d, std::array<u32, 3> x, u32 lo, u32 hi, std::vector<u32>& out) const {
        out.clear();
        x[static_cast<std::size_t>(d)] = lo;
        const auto key = line_key(x, d);
        const auto collect = [&](const auto& index, auto key_of, auto corner_of) {
            auto it =
                std::lower_bound(index.begin(), index.end(), key,
                                 [&](const auto& e, const std::array<u32, 3>& k) { return key_of(e) < k; });
            for (; it != index.end(); ++it) {
                const std::array<u32, 3> k = key_of(*it);
                if (k[0] != key[0] || k[1] != key[1] || k[2] > hi) break;
                out.push_back(corner_of(*it, it - index.begin()));
            }
        };
        if (d == 2)
            collect(
                corners_, [](const Corner& c) { return c.x; },
                [](const Corner&, std::ptrdiff_t i) { return static_cast<u32>(i); });
        else
            collect(
                line_[d], [](const LineEntry& e) { return e.key; },
                [](const LineEntry& e, std::ptrdiff_t) { return e.corner; });
    }

    u32 copy_of(u32 c, const Rect& R) const {
        const Corner& P = corners_[c];
        const int a = R.axis;
        const u32 pu = P.x[static_cast<std::size_t>(axis_u(a))],
                  pv = P.x[static_cast<std::size_t>(axis_v(a))];
        const int f = 4 * a + (pu < R.u1 ? 1 : 0) + 2 * (pv < R.v1 ? 1 : 0);
        const std::uint8_t k = table_.cycle[P.cfg][f];
        if (k == no_cycle) throw std::logic_error("mesh_cover: a rectangle corner is not on the surface");
        return copy_base_[c] + k;
    }

    // One side of R: from corner `from` along axis d towards `to` (exclusive), its points and the
    // midpoints of its split edges. w_side: 1 when R lies on the positive side of the line along
    // the in-plane axis w perpendicular to d.
    void side(const Rect& R, int d, std::array<u32, 3> at, u32 from, u32 to, int w_side,
              std::vector<BPoint>& out) {
        out.clear();
        const bool up = from < to;
        points_on(d, at, std::min(from, to), std::max(from, to), pts_);
        if (pts_.size() < 2 || corners_[pts_.front()].x[static_cast<std::size_t>(d)] != std::min(from, to) ||
            corners_[pts_.back()].x[static_cast<std::size_t>(d)] != std::max(from, to))
            throw std::logic_error("mesh_cover: a rectangle corner is missing from the corner index");
        if (!up) std::reverse(pts_.begin(), pts_.end());
        const int a = R.axis, w = 3 - a - d;
        for (std::size_t i = 0; i + 1 < pts_.size(); ++i) {
            const u32 c = pts_[i];
            out.push_back({copy_of(c, R), 2 * corners_[c].x[static_cast<std::size_t>(d)]});
            const u32 lo = up ? c : pts_[i + 1], hi = up ? pts_[i + 1] : c;
            const std::uint8_t cl = corners_[lo].cfg, ch = corners_[hi].cfg;
            if (!table_.nonmanifold[cl][2 * d + 1]) continue;
            ++nonmanifold_sides_;
            if (table_.sheets_distinct[cl][2 * d + 1] || table_.sheets_distinct[ch][2 * d]) continue;
            // Both ends are single fans: split the edge, one midpoint per sheet.
            MidKey key;
            for (std::size_t e = 0; e < 3; ++e) key.x2[e] = corners_[lo].x[e] + corners_[hi].x[e];
            key.sheet = (1u << d) | ((R.plus ? 0u : 1u) << a) | (static_cast<u32>(w_side) << w);
            const auto [it, inserted] = mids_.try_emplace(key, 0);
            if (inserted) it->second = new_vertex(key.x2);
            out.push_back({it->second, key.x2[static_cast<std::size_t>(d)]});
        }
    }

    u32 new_vertex(const std::array<u32, 3>& x2) {
        const u64 id = u64{copy_base_.back()} + extra_.size();
        if (id >= no_index) throw std::length_error("mesh_cover: too many vertices for 32-bit indices");
        extra_.push_back(x2);
        return static_cast<u32>(id);
    }

    void emit(u32 a, u32 b, u32 c) {
        if (flip_)
            tri_.push_back({a, c, b});
        else
            tri_.push_back({a, b, c});
    }

    // Strip between chain A and chain B, both ascending along the same direction, spanning the
    // same range, on opposite sides. Counter-clockwise when A is the side on the right of B going
    // along the direction (as set up by the caller).
    void strip(const std::vector<BPoint>& A, const std::vector<BPoint>& B) {
        std::size_t i = 0, j = 0;
        while (i + 1 < A.size() || j + 1 < B.size()) {
            if (j + 1 == B.size() || (i + 1 < A.size() && A[i + 1].t2 <= B[j + 1].t2)) {
                emit(A[i].pid, A[i + 1].pid, B[j].pid);
                ++i;
            } else {
                emit(A[i].pid, B[j + 1].pid, B[j].pid);
                ++j;
            }
        }
    }

    void rect(std::size_t index) {
        const Rect& R = rects_[index];
        const int a = R.axis, au = axis_u(a), av = axis_v(a);
        // (u, v, a) is right-handed for a = 0, 2 and left-handed for a = 1; sides are listed
        // counter-clockwise in (u, v), which faces +a exactly when right-handed.
        flip_ = (a == 1) == (R.plus != 0);
        std::array<u32, 3> x{};
        x[static_cast<std::size_t>(a)] = R.p;
        auto at = [&](u32 u, u32 v) {
            std::array<u32, 3> y = x;
            y[static_cast<std::size_t>(au)] = u;
            y[static_cast<std::size_t>(av)] = v;
            return y;
        };
        side(R, au, at(R.u0, R.v0), R.u0, R.u1, 1, sides_[0]); // bottom, u ascending
        side(R, av, at(R.u1, R.v0), R.v0, R.v1, 0, sides_[1]); // right, v ascending
        side(R, au, at(R.u1, R.v1), R.u1, R.u0, 0, sides_[2]); // top, u descending
        side(R, av, at(R.u0, R.v1), R.v1, R.v0, 1, sides_[3]); // left, v descending
        const auto extra = [&](int k) { return sides_[k].size() > 1; };

        if (!extra(1) && !extra(3)) { // strip bottom -> top
            chain_a_ = sides_[0];
            chain_a_.push_back(sides_[1][0]);
            chain_b_.assign(sides_[2].rbegin(), sides_[2].rend());
            chain_b_.insert(chain_b_.begin(), sides_[3][0]);
            strip(chain_a_, chain_b_);
            return;
        }
        if (!extra(0) && !extra(2)) { // strip left -> right
            chain_a_ = sides_[1];
            chain_a_.push_back(sides_[2][0]);
            chain_b_.assign(sides_[3].rbegin(), sides_[3].rend());
            chain_b_.insert(chain_b_.begin(), sides_[0][0]);
            strip(chain_a_, chain_b_);
            return;
        }
        ring_.clear();
        for (int k = 0; k < 4; ++k) ring_.insert(ring_.end(), sides_[k].begin(), sides_[k].end());
        for (int k = 0; k < 4; ++k) {
            if (extra(k) || extra((k + 3) % 4)) continue;
            // Fan from corner k: its two sides carry no extra point, so no triangle is flat.
            std::size_t start = 0;
            for (int j = 0; j < k; ++j) start += sides_[j].size();
            const std::size_t m = ring_.size();
            for (std::size_t t = 1; t + 1 < m; ++t)
                emit(ring_[start].pid, ring_[(start + t) % m].pid, ring_[(start + t + 1) % m].pid);
            return;
        }
        std::array<u32, 3> c2{};
        c2[static_cast<std::size_t>(a)] = 2 * R.p;
        c2[static_cast<std::size_t>(au)] = R.u0 + R.u1;
        c2[static_cast<std::size_t>(av)] = R.v0 + R.v1;
        const u32 centre = new_vertex(c2);
        for (std::size_t t = 0; t < ring_.size(); ++t)
            emit(centre, ring_[t].pid, ring_[(t + 1) % ring_.size()].pid);
    }

    const std::vector<Corner>& corners_;
    const std::vector<Rect>& rects_;
    std::vector<std::array<u32, 3>>& tri_;
    MeshStats& stats_;
    const PointTable& table_;
    struct LineEntry {
        std::array<u32, 3> key; // line_key
        u32 corner;
    };
    std::vector<LineEntry> line_[2]; // along x and along y (z uses the corner order itself)
    std::vector<u32> copy_base_;
    std::vector<std::array<u32, 3>> extra_;
    std::unordered_map<MidKey, u32, MidHash> mids_;
    u64 nonmanifold_sides_ = 0;
    bool flip_ = false;
    std::vector<u32> pts_;
    std::vector<BPoint> sides_[4], chain_a_, chain_b_, ring_;
};

// x0 + (x1 - x0) * i / n, exact at both ends.
double lattice_coord(Interval axis, u64 i, u64 n) {
    if (i == 0) return axis.lo;
    if (i == n) return axis.hi;
    return axis.lo + (axis.hi - axis.lo) * static_cast<double>(i) / static_cast<double>(n);
}

} // namespace

Mesh mesh_cover(const Cover& r, MeshSelection selection, std::uint64_t max_triangles) {
    const auto start = Clock::now();
    const Lattice L = make_lattice(r, selection);
    Mesh mesh;
    mesh.stats.cells = L.selected.size();
    if (L.selected.empty()) return mesh;

    std::vector<Rect> rects;
    std::vector<Corner> corners;
    {
        PlaneSweep sweep(rects, corners, mesh.stats.unit_faces);
        for (int axis = 0; axis < 3; ++axis) sweep_axis(r, L, axis, sweep);
    }
    mesh.stats.rectangles = rects.size();
    // About 2.5 triangles per rectangle (measured; below 21/8 on every mesh of the tests).
    const u64 expected_triangles = static_cast<u64>(rects.size()) * 21 / 8;
    if (max_triangles > 0 && expected_triangles > max_triangles)
        throw LimitError(fmt::format("about {} triangles ({} merged faces; about {:.3g} GB), more than the "
                                     "limit of {} triangles",
                                     expected_triangles, rects.size(),
                                     static_cast<double>(expected_triangles) * 36 / 1e9, max_triangles),
                         static_cast<double>(expected_triangles), max_triangles);

    // One entry per distinct point; the configuration is a property of the point, so copies found
    // from different rectangles must agree.
    std::sort(corners.begin(), corners.end(), [](const Corner& a, const Corner& b) { return a.x < b.x; });
    std::size_t m = 0;
    for (std::size_t i = 0; i < corners.size(); ++i) {
        if (m > 0 && corners[m - 1].x == corners[i].x) {
            if (corners[m - 1].cfg != corners[i].cfg)
                throw std::logic_error("mesh_cover: inconsistent cell configuration at a lattice point");
            continue;
        }
        corners[m++] = corners[i];
    }
    corners.resize(m);
    corners.shrink_to_fit();
    const PointTable& table = point_table();
    for (const Corner& c : corners) mesh.stats.split_points += table.cycles[c.cfg] > 1 ? 1 : 0;

    std::vector<u32> copy_base;
    std::vector<std::array<u32, 3>> extra;
    {
        // About 2.5 triangles per rectangle; reserving avoids a doubling of the largest array.
        mesh.triangles.reserve(expected_triangles + 16);
        Triangulator tri(corners, rects, mesh);
        tri.run();
        copy_base = std::move(tri.copy_base());
        extra = std::move(tri.extra());
    } // frees the line indices
    rects = {};

    // Place the vertices: the copies of each corner point, then the centres and midpoints.
    const u64 n2 = 2 * L.n;
    const auto place = [&](const std::array<u64, 3>& x2) {
        return std::array<double, 3>{lattice_coord(r.root[0], x2[0], n2), lattice_coord(r.root[1], x2[1], n2),
                                     lattice_coord(r.root[2], x2[2], n2)};
    };
    mesh.vertices.reserve(copy_base.back() + extra.size());
    for (std::size_t c = 0; c < corners.size(); ++c) {
        const auto x = place({2 * u64{corners[c].x[0]}, 2 * u64{corners[c].x[1]}, 2 * u64{corners[c].x[2]}});
        for (u32 k = copy_base[c]; k < copy_base[c + 1]; ++k) mesh.vertices.push_back(x);
    }
    for (const auto& x2 : extra) mesh.vertices.push_back(place({x2[0], x2[1], x2[2]}));
    mesh.stats.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return mesh;
}

double selected_volume(const Cover& r, MeshSelection selection) {
    require_3d_cells(r, "selected_volume");
    const long double w[3] = {static_cast<long double>(r.root[0].hi) - r.root[0].lo,
                              static_cast<long double>(r.root[1].hi) - r.root[1].lo,
                              static_cast<long double>(r.root[2].hi) - r.root[2].lo};
    std::vector<u64> count(static_cast<std::size_t>(r.depth) + 1, 0);
    for (const Cell& c : r.cells)
        if (is_selected(c.cls, selection) && c.level <= r.depth) ++count[c.level];
    long double v = 0;
    for (int k = 0; k <= r.depth; ++k) {
        const auto n = static_cast<long double>(r.cells_per_axis(k));
        v += static_cast<long double>(count[static_cast<std::size_t>(k)]) / (n * n * n);
    }
    return static_cast<double>(v * w[0] * w[1] * w[2]);
}

} // namespace frac::rt
