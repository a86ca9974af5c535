#include "runtime/automata/solid.hpp"

#include "ir/automaton_check.hpp"
#include "runtime/automata/points.hpp"
#include "runtime/automata/surface.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <unordered_map>
#include <vector>

namespace frac::rt {

namespace {

using num::Matrix;

constexpr double max_vertices = static_cast<double>(std::uint64_t{1} << 26);

// A face to tessellate: the face cell, drawn through `output` (homogeneous rows over its space).
struct FacePlacement {
    std::size_t state = 0;
    Matrix<double> output;
    int depth = 0;
};

// Merges points closer than `tolerance` (in every coordinate) into one index: a hash grid of cells of
// the tolerance's size, each point looked up in the 27 cells around it.
class PointMerger {
public:
    explicit PointMerger(double tolerance) : tolerance_(tolerance) {}

    std::uint32_t add(const std::array<double, 3>& p) {
        const std::array<std::int64_t, 3> cell = cell_of(p);
        for (std::int64_t dx = -1; dx <= 1; ++dx)
            for (std::int64_t dy = -1; dy <= 1; ++dy)
                for (std::int64_t dz = -1; dz <= 1; ++dz) {
                    const auto it = cells_.find(key({cell[0] + dx, cell[1] + dy, cell[2] + dz}));
                    if (it == cells_.end()) continue;
                    for (const std::uint32_t v : it->second)
                        if (near(points_[v], p)) return v;
                }
        const auto v = static_cast<std::uint32_t>(points_.size());
        points_.push_back(p);
        cells_[key(cell)].push_back(v);
        return v;
    }
    std::vector<std::array<double, 3>>& points() { return points_; }

private:
    std::array<std::int64_t, 3> cell_of(const std::array<double, 3>& p) const {
        std::array<std::int64_t, 3> c{};
        for (std::size_t r = 0; r < 3; ++r) c[r] = static_cast<std::int64_t>(std::floor(p[r] / tolerance_));
        return c;
    }
    static std::uint64_t key(const std::array<std::int64_t, 3>& c) {
        std::uint64_t h = 1469598103934665603ull;
        for (const std::int64_t x : c) h = (h ^ static_cast<std::uint64_t>(x)) * 1099511628211ull;
        return h;
    }
    bool near(const std::array<double, 3>& p, const std::array<double, 3>& q) const {
        for (std::size_t r = 0; r < 3; ++r)
            if (std::abs(p[r] - q[r]) > tolerance_) return false;
        return true;
    }

    double tolerance_;
    std::vector<std::array<double, 3>> points_;
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cells_;
};

// Turns triangles so that each one crossing a shared edge runs it the other way from its neighbour
// (a breadth-first walk per component), then each component outwards: positive enclosed volume.
void orient(Mesh& mesh) {
    const std::size_t n = mesh.triangles.size();
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::size_t>> by_edge;
    for (std::size_t t = 0; t < n; ++t)
        for (int c = 0; c < 3; ++c) {
            const std::uint32_t u = mesh.triangles[t][c], v = mesh.triangles[t][(c + 1) % 3];
            by_edge[{std::min(u, v), std::max(u, v)}].push_back(t);
        }
    const auto runs = [&](std::size_t t, std::uint32_t u, std::uint32_t v) {
        for (int c = 0; c < 3; ++c)
            if (mesh.triangles[t][c] == u && mesh.triangles[t][(c + 1) % 3] == v) return true;
        return false;
    };
    std::vector<int> component(n, -1);
    std::vector<std::vector<std::size_t>> members;
    for (std::size_t seed = 0; seed < n; ++seed) {
        if (component[seed] >= 0) continue;
        const int id = static_cast<int>(members.size());
        members.emplace_back(std::vector<std::size_t>{seed});
        component[seed] = id;
        for (std::size_t i = 0; i < members.back().size(); ++i) {
            const std::size_t t = members.back()[i];
            for (int c = 0; c < 3; ++c) {
                const std::uint32_t u = mesh.triangles[t][c], v = mesh.triangles[t][(c + 1) % 3];
                const auto& around = by_edge[{std::min(u, v), std::max(u, v)}];
                if (around.size() != 2) continue; // a rim or a non-manifold edge: nothing to follow
                const std::size_t o = around[0] == t ? around[1] : around[0];
                if (component[o] >= 0) continue;
                if (runs(o, u, v)) std::swap(mesh.triangles[o][1], mesh.triangles[o][2]);
                component[o] = id;
                members.back().push_back(o);
            }
        }
    }
    for (const auto& part : members) {
        Mesh piece;
        piece.vertices = mesh.vertices;
        for (const std::size_t t : part) piece.triangles.push_back(mesh.triangles[t]);
        if (enclosed_volume(piece) < 0)
            for (const std::size_t t : part) std::swap(mesh.triangles[t][1], mesh.triangles[t][2]);
    }
}

} // namespace

bool reaches_volume(const ir::Automaton& a) {
    const std::vector<bool> live = ir::reachable_states(a);
    return std::any_of(a.volume_cells.begin(), a.volume_cells.end(),
                       [&](const ir::VolumeCell& v) { return v.state < live.size() && live[v.state]; });
}

SolidMesh tessellate_solid(const ir::Automaton& a, int depth) {
    require_well_formed(a);
    if (depth < 0 || depth > 24)
        throw std::invalid_argument(fmt::format("tessellation depth {} is outside [0, 24]", depth));
    std::vector<const ir::VolumeCell*> volume(a.states.size(), nullptr);
    for (const ir::VolumeCell& v : a.volume_cells)
        if (v.state < volume.size()) volume[v.state] = &v;
    const Matrix<double> out = output_matrix(a);
    if (out.rows() > 4)
        throw std::invalid_argument(
            fmt::format("{} is drawn in R{}: a mesh needs R3 or less", a.name, out.rows() - 1));

    // Each face cell's layout, inferred once (it does not depend on where the face is drawn).
    std::vector<std::optional<SurfaceLayout>> layouts(a.states.size());
    std::vector<std::optional<ir::Automaton>> alone(a.states.size());
    const auto layout_of = [&](std::size_t f) -> const SurfaceLayout& {
        if (!layouts[f]) {
            alone[f] = a;
            alone[f]->initial = f;
            alone[f]->projection.reset();
            layouts[f] = infer_layout(*alone[f]);
            if (layouts[f]->states[f]->dimension != 2)
                throw std::invalid_argument(fmt::format("{}: the face cell {} is a curve, not a quad patch",
                                                        a.name, a.states[f].name));
        }
        return *layouts[f];
    };

    SolidMesh result;
    std::vector<FacePlacement> faces;
    double vertices = 0;
    const auto walk = [&](auto&& self, std::size_t q, int remaining, int level,
                          const Matrix<double>& m) -> void {
        if (const ir::VolumeCell* v = volume[q]) {
            ++result.blocks;
            result.layers = std::max(result.layers, level + 1);
            for (const std::size_t e : v->faces) {
                const ir::Arc& b = a.embeddings.at(e);
                const CellLayout& l = *layout_of(b.to).states[b.to];
                vertices += (std::pow(static_cast<double>(l.n_s), remaining) + 1) *
                            (std::pow(static_cast<double>(l.n_t), remaining) + 1);
                if (vertices > max_vertices)
                    throw std::invalid_argument(fmt::format(
                        "the mesh of {} at depth {} would have more than 2^26 vertices", a.name, depth));
                faces.push_back({b.to, m * b.op.nearest, remaining});
            }
            return;
        }
        for (const std::size_t i : a.arcs_from(q)) {
            const ir::Arc& arc = a.arcs[i];
            const bool block = volume[arc.to] != nullptr;
            if (!block && remaining == 0) continue;
            self(self, arc.to, block ? remaining : remaining - 1, block ? level : level + 1,
                 m * arc.op.nearest);
        }
    };
    walk(walk, a.initial, depth, 0, out);
    if (result.blocks == 0)
        throw std::invalid_argument(
            fmt::format("{}: no volume cell (a cube topology's cell) is reached from {}", a.name,
                        a.states[a.initial].name));
    result.faces = faces.size();

    // Every face's grid, merged into one set of vertices; its squares as vertex quadruples.
    std::vector<Tessellation> grids;
    grids.reserve(faces.size());
    double extent = 0;
    for (const FacePlacement& f : faces) {
        grids.push_back(tessellate(*alone[f.state], *layouts[f.state], f.depth, &f.output));
        for (const auto& p : grids.back().vertices)
            for (const double c : p) extent = std::max(extent, std::abs(c));
    }
    PointMerger merger(1e-9 * (1 + extent));
    std::vector<std::array<std::uint32_t, 4>> squares;
    for (const Tessellation& t : grids) {
        std::vector<std::uint32_t> index(t.vertices.size());
        for (std::size_t v = 0; v < t.vertices.size(); ++v) index[v] = merger.add(t.vertices[v]);
        for (std::size_t i = 0; i + 1 < t.side_s; ++i)
            for (std::size_t j = 0; j + 1 < t.side_t; ++j) {
                const std::size_t v00 = i * t.side_t + j;
                squares.push_back(
                    {index[v00], index[v00 + t.side_t], index[v00 + t.side_t + 1], index[v00 + 1]});
            }
    }
    // Squares with the same four vertices come in pairs from two faces that touch: inside the solid.
    std::vector<std::pair<std::array<std::uint32_t, 4>, std::size_t>> keys(squares.size());
    for (std::size_t s = 0; s < squares.size(); ++s) {
        keys[s] = {squares[s], s};
        std::sort(keys[s].first.begin(), keys[s].first.end());
    }
    std::sort(keys.begin(), keys.end());
    std::vector<bool> inside(squares.size(), false);
    for (std::size_t s = 0; s < keys.size();) {
        std::size_t e = s;
        while (e < keys.size() && keys[e].first == keys[s].first) ++e;
        if (e - s == 2) {
            inside[keys[s].second] = inside[keys[s + 1].second] = true;
            ++result.inner;
        }
        s = e;
    }
    // Triangles of the squares left, and only the vertices they use.
    std::vector<std::uint32_t> renumber(merger.points().size(), UINT32_MAX);
    const auto use = [&](std::uint32_t v) {
        if (renumber[v] == UINT32_MAX) {
            renumber[v] = static_cast<std::uint32_t>(result.mesh.vertices.size());
            result.mesh.vertices.push_back(merger.points()[v]);
        }
        return renumber[v];
    };
    for (std::size_t s = 0; s < squares.size(); ++s) {
        if (inside[s]) continue;
        const auto& q = squares[s];
        // A square with a side of length 0 (a collapsed corner) gives one triangle or none.
        for (const std::array<std::uint32_t, 3> t :
             {std::array{q[0], q[1], q[2]}, std::array{q[0], q[2], q[3]}})
            if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
                result.mesh.triangles.push_back({use(t[0]), use(t[1]), use(t[2])});
    }
    orient(result.mesh);
    require_finite_vertices(result.mesh.vertices);
    return result;
}

} // namespace frac::rt
