// Euler characteristics computed independently of the mesher (closed forms and cubical-complex counts),
// and the closed-mesh checks the mesh tests share (test_mesh.cpp, test_mesh_stdlib.cpp).
#pragma once

#include "runtime/mesh.hpp"
#include "test_mesh_shapes.hpp"

#include <catch2/catch.hpp>

#include <cstdint>
#include <functional>
#include <vector>

namespace frac::rt::test {

inline void require_closed(const Mesh& m, const MeshCheck& ck) {
    INFO("problem: " << ck.problem);
    CHECK(ck.problem.empty());
    CHECK(ck.watertight);
    CHECK(ck.manifold);
    CHECK(ck.oriented);
    CHECK(ck.degenerate == 0);
    CHECK(ck.unreferenced == 0);
    CHECK(ck.ok());
    CHECK(ck.faces == m.triangles.size());
    CHECK(ck.vertices == m.vertices.size());
    CHECK(ck.volume > 0);
}

// The level-j Sierpinski carpet C_j is a closed square with (8^j - 1) / 7 open holes: chi = 1 - (8^j - 1)
// / 7.
inline std::int64_t carpet_euler(int j) {
    std::int64_t eight = 1;
    for (int i = 0; i < j; ++i) eight *= 8;
    return 1 - (eight - 1) / 7;
}

// ---- The Euler characteristic of the Menger sponge, independently of the mesh ----
//
// For a compact 3-manifold M with boundary, chi(boundary M) = 2 chi(M). The level-k sponge M_k is
// the union of 20 copies of M_(k-1) at scale 1/3. By inclusion-exclusion over the copies: the 24
// face contacts (corner cube - edge cube) are level-(k-1) carpets; the 24 edge contacts (two edge
// cubes next to one corner cube) are segments, each also the triple intersection with that corner
// cube (+24 - 24); around each of the 8 corner cubes the three edge cubes meet at one point, which
// is also the quadruple intersection with the corner cube (+8 - 8). Hence
//   chi(M_k) = 20 chi(M_(k-1)) - 24 chi(C_(k-1)),  chi(M_0) = 1.
// chi(M_k) = 1, -4, -80, -1408, -26432 for k = 0..4 (closed form (192 - 21 * 20^k - 38 * 8^k) / 133).
inline std::int64_t menger_solid_euler(int k) {
    std::int64_t chi = 1;
    for (int i = 1; i <= k; ++i) chi = 20 * chi - 24 * carpet_euler(i - 1);
    return chi;
}

// A second, independent method: the alternating count V - E + F - C of the lattice vertices, edges,
// squares and cubes of the closed union of the chosen unit cubes [x, x+1] x [y, y+1] x [z, z+1],
// 0 <= x, y, z < n (a cubical complex whose Euler characteristic is that of the solid).
inline std::int64_t cubes_euler(std::int64_t n,
                                const std::function<bool(std::int64_t, std::int64_t, std::int64_t)>& kept) {
    const std::int64_t m = n + 2;
    std::vector<char> in(static_cast<std::size_t>(m * m * m), 0); // cell (x, y, z) at (x+1, y+1, z+1)
    const auto at = [&](std::int64_t x, std::int64_t y, std::int64_t z) -> char& {
        return in[static_cast<std::size_t>(((z + 1) * m + (y + 1)) * m + (x + 1))];
    };
    std::int64_t cubes = 0;
    for (std::int64_t z = 0; z < n; ++z)
        for (std::int64_t y = 0; y < n; ++y)
            for (std::int64_t x = 0; x < n; ++x)
                if (kept(x, y, z)) {
                    at(x, y, z) = 1;
                    ++cubes;
                }
    // A lattice k-cell belongs to the closed union when one of the cubes around it is kept.
    std::int64_t V = 0, E = 0, F = 0;
    for (std::int64_t z = 0; z <= n; ++z)
        for (std::int64_t y = 0; y <= n; ++y)
            for (std::int64_t x = 0; x <= n; ++x) {
                bool v = false;
                for (int t = 0; t < 8; ++t)
                    v = v || at(x - 1 + (t & 1), y - 1 + ((t >> 1) & 1), z - 1 + (t >> 2));
                V += v;
                const std::int64_t p[3] = {x, y, z};
                for (int d = 0; d < 3; ++d) {
                    // Edge from p along d: the 4 cubes with coordinate p[d] along d around it.
                    if (p[d] < n) {
                        bool e = false;
                        for (int t = 0; t < 4; ++t) {
                            std::int64_t q[3] = {x, y, z};
                            q[(d + 1) % 3] -= 1 - (t & 1);
                            q[(d + 2) % 3] -= 1 - (t >> 1);
                            e = e || at(q[0], q[1], q[2]);
                        }
                        E += e;
                    }
                    // Square at p normal to d: the cubes on both sides.
                    if (p[(d + 1) % 3] < n && p[(d + 2) % 3] < n) {
                        std::int64_t q[3] = {x, y, z};
                        q[d] -= 1;
                        F += at(x, y, z) || at(q[0], q[1], q[2]);
                    }
                }
            }
    return V - E + F - cubes;
}

inline std::int64_t menger_solid_euler_by_cells(const Menger& s) {
    return cubes_euler(s.n, [&](std::int64_t x, std::int64_t y, std::int64_t z) { return s.kept(x, y, z); });
}

} // namespace frac::rt::test
