// check_mesh and enclosed_volume: what a mesh from mesh_cover (mesh_build.cpp) must be, verified
// independently of how it was built (watertight, edge- and vertex-manifold, consistently oriented).
#include "runtime/mesh.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

namespace frac::rt {

using u32 = std::uint32_t;
using u64 = std::uint64_t;

double enclosed_volume(const Mesh& mesh) {
    if (mesh.vertices.empty()) return 0;
    // Relative to a vertex, so that a mesh far from the origin loses no precision.
    const auto o = mesh.vertices[0];
    long double sum = 0;
    for (const auto& t : mesh.triangles) {
        long double p[3][3];
        for (int i = 0; i < 3; ++i)
            for (int e = 0; e < 3; ++e)
                p[i][e] = static_cast<long double>(
                              mesh.vertices[t[static_cast<std::size_t>(i)]][static_cast<std::size_t>(e)]) -
                          o[static_cast<std::size_t>(e)];
        sum += p[0][0] * (p[1][1] * p[2][2] - p[1][2] * p[2][1]) -
               p[0][1] * (p[1][0] * p[2][2] - p[1][2] * p[2][0]) +
               p[0][2] * (p[1][0] * p[2][1] - p[1][1] * p[2][0]);
    }
    return static_cast<double>(sum / 6);
}

namespace {

struct UnionFind {
    std::vector<u32> parent;
    explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), u32{0}); }
    u32 find(u32 x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
    }
    void unite(u32 a, u32 b) {
        a = find(a);
        b = find(b);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
};

} // namespace

MeshCheck check_mesh(const Mesh& mesh) {
    MeshCheck ck;
    const std::size_t nv = mesh.vertices.size(), nt = mesh.triangles.size();
    ck.faces = nt;
    const auto problem = [&](std::string text) {
        if (ck.problem.empty()) ck.problem = std::move(text);
    };
    for (std::size_t i = 0; i < nt; ++i)
        for (const u32 v : mesh.triangles[i])
            if (v >= nv) {
                ck.problem = fmt::format("triangle {} uses vertex {} of {}", i, v, nv);
                return ck;
            }

    // Degenerate triangles: a repeated vertex or zero area.
    for (std::size_t i = 0; i < nt; ++i) {
        const auto& t = mesh.triangles[i];
        bool bad = t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
        if (!bad) {
            const auto &p = mesh.vertices[t[0]], &q = mesh.vertices[t[1]], &s = mesh.vertices[t[2]];
            const double e1[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
            const double e2[3] = {s[0] - p[0], s[1] - p[1], s[2] - p[2]};
            const double c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                                 e1[0] * e2[1] - e1[1] * e2[0]};
            bad = c[0] == 0 && c[1] == 0 && c[2] == 0;
        }
        if (bad) {
            ++ck.degenerate;
            problem(fmt::format("triangle {} ({}, {}, {}) is degenerate", i, t[0], t[1], t[2]));
        }
    }

    // Edges: one key per triangle side, (lower vertex, higher vertex, direction bit), sorted; the
    // sides of an undirected edge are then adjacent. Vertex ids below 2^31 fit in 63 bits.
    if (nv >= (u64{1} << 31)) {
        ck.problem = fmt::format("{} vertices: too many to check", nv);
        return ck;
    }
    std::vector<u64> half;
    half.reserve(3 * nt);
    for (const auto& t : mesh.triangles)
        for (int k = 0; k < 3; ++k) {
            const u32 a = t[static_cast<std::size_t>(k)], b = t[(k + 1) % 3];
            half.push_back(u64{std::min(a, b)} << 32 | u64{std::max(a, b)} << 1 | (a < b ? 1u : 0u));
        }
    std::sort(half.begin(), half.end());
    bool closed = true, edge_manifold = true, oriented = true;
    for (std::size_t i = 0; i < half.size();) {
        std::size_t j = i;
        u64 forward = 0;
        for (; j < half.size() && half[j] >> 1 == half[i] >> 1; ++j) forward += half[j] & 1;
        const u64 uses = j - i;
        const auto a = static_cast<u32>(half[i] >> 32), b = static_cast<u32>((half[i] >> 1) & 0x7fffffffu);
        i = j;
        if (a == b) continue; // degenerate, reported above
        ++ck.edges;
        if (uses < 2) {
            ++ck.boundary_edges;
            closed = false;
            problem(fmt::format("edge ({}, {}) has 1 triangle: the mesh is open", a, b));
        } else if (uses > 2) {
            closed = edge_manifold = false;
            problem(fmt::format("edge ({}, {}) has {} triangles (non-manifold edge)", a, b, uses));
        } else if (forward != 1) {
            oriented = false;
            problem(fmt::format(
                "edge ({}, {}) is used twice in the same direction (inconsistent orientation)", a, b));
        }
    }
    half = {};

    // Vertex fans: the link of a vertex (edge b-c of each triangle a-b-c at a) must be one cycle,
    // or one path on an open boundary.
    std::vector<u64> start(nv + 1, 0);
    for (const auto& t : mesh.triangles)
        for (const u32 v : t) ++start[v + 1];
    for (std::size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
    std::vector<std::array<u32, 2>> link(3 * nt);
    {
        std::vector<u64> fill(start.begin(), start.end() - 1);
        for (const auto& t : mesh.triangles)
            for (int k = 0; k < 3; ++k)
                link[fill[t[static_cast<std::size_t>(k)]]++] = {t[(k + 1) % 3], t[(k + 2) % 3]};
    }
    bool vertex_manifold = true;
    std::vector<u32> ends, parent, degree;
    for (std::size_t v = 0; v < nv; ++v) {
        const u64 b = start[v], e = start[v + 1];
        if (b == e) {
            ++ck.unreferenced;
            continue;
        }
        ++ck.vertices;
        ends.clear();
        for (u64 i = b; i < e; ++i) ends.insert(ends.end(), link[i].begin(), link[i].end());
        std::sort(ends.begin(), ends.end());
        ends.erase(std::unique(ends.begin(), ends.end()), ends.end());
        const auto local = [&](u32 x) {
            return static_cast<u32>(std::lower_bound(ends.begin(), ends.end(), x) - ends.begin());
        };
        parent.resize(ends.size());
        std::iota(parent.begin(), parent.end(), u32{0});
        degree.assign(ends.size(), 0);
        const auto find = [&](u32 x) {
            while (parent[x] != x) x = parent[x] = parent[parent[x]];
            return x;
        };
        for (u64 i = b; i < e; ++i) {
            const u32 x = local(link[i][0]), y = local(link[i][1]);
            ++degree[x];
            ++degree[y];
            parent[find(x)] = find(y);
        }
        std::size_t roots = 0, odd = 0;
        bool over = false;
        for (u32 k = 0; k < ends.size(); ++k) {
            roots += find(k) == k ? 1 : 0;
            odd += degree[k] == 1 ? 1 : 0;
            over = over || degree[k] > 2;
        }
        if (roots != 1 || over || odd > 2) {
            vertex_manifold = false;
            problem(fmt::format("vertex {}: its {} triangles form {} fans (non-manifold vertex)", v, e - b,
                                roots));
        }
    }
    link = {};

    UnionFind uf(nv);
    for (const auto& t : mesh.triangles) {
        uf.unite(t[0], t[1]);
        uf.unite(t[1], t[2]);
    }
    for (std::size_t v = 0; v < nv; ++v)
        if (start[v + 1] > start[v] && uf.find(static_cast<u32>(v)) == v) ++ck.components;

    ck.watertight = closed;
    ck.manifold = edge_manifold && vertex_manifold;
    ck.oriented = oriented;
    ck.volume = enclosed_volume(mesh);
    if (ck.faces > 0 && !(ck.volume > 0))
        problem(fmt::format("the enclosed volume is {}: the normals point inwards", ck.volume));
    ck.euler = static_cast<std::int64_t>(ck.vertices) - static_cast<std::int64_t>(ck.edges) +
               static_cast<std::int64_t>(ck.faces);
    return ck;
}

} // namespace frac::rt
