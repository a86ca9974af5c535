// 3D test evaluators for the mesh and slice tests (test_mesh.cpp, test_slice.cpp): sets of lattice cubes and
// the Menger sponge, written directly with the numeric core (see shapes.hpp for the style). The digit-exact
// sponge is the oracle the standard library's menger_lattice is compared with (test_mesh_stdlib.cpp).
#pragma once

#include "shapes.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <set>
#include <vector>

namespace frac::rt::test {

// f = -1 on the union U of chosen closed unit cubes of the lattice {0..n-1}^3 laid over the root
// box (each axis [lo, lo + n * cell] with a power-of-two cell, so lattice coordinates of grid
// points are exact), f = +1 elsewhere. The box enclosure is exact up to the cells the box touches:
// -1 when the box lies in U, +1 when it touches no chosen cube, [-1, 1] otherwise. Cells of any
// level that lie wholly in U are therefore inside, so covers mix levels.
class CubeSet : public TestShape {
public:
    CubeSet(int n, double lo, double cell) : TestShape(3), n(n), lo(lo), cell(cell) {}
    void add(int x, int y, int z) { chosen.insert({x, y, z}); }
    bool has(int x, int y, int z) const { return chosen.count({x, y, z}) > 0; }

    double eval_point(const double* p) override {
        int j[3];
        for (int a = 0; a < 3; ++a) {
            const double t = (p[a] - lo) / cell;
            if (t < 0 || t > n) return 1;
            j[a] = std::min(n - 1, static_cast<int>(std::floor(t)));
        }
        return has(j[0], j[1], j[2]) ? -1 : 1;
    }
    Interval eval_box(const Interval* b) override {
        num::UpwardRounding up;
        int cov_lo[3], cov_hi[3], touch_lo[3], touch_hi[3];
        bool in_root = true;
        for (int a = 0; a < 3; ++a) {
            // Outward lattice coordinates of the box.
            const Interval t = num::div(num::sub(b[a], Interval(lo)), Interval(cell));
            const double fl = std::floor(t.lo), ce = std::ceil(t.hi);
            cov_lo[a] = static_cast<int>(fl);
            cov_hi[a] = std::max(cov_lo[a], static_cast<int>(ce) - 1);
            touch_lo[a] = std::max(0, static_cast<int>(std::ceil(t.lo)) - 1);
            touch_hi[a] = std::min(n - 1, static_cast<int>(std::floor(t.hi)));
            in_root = in_root && cov_lo[a] >= 0 && cov_hi[a] <= n - 1;
        }
        bool all = in_root, any = false;
        for (int z = touch_lo[2]; z <= touch_hi[2]; ++z)
            for (int y = touch_lo[1]; y <= touch_hi[1]; ++y)
                for (int x = touch_lo[0]; x <= touch_hi[0]; ++x) {
                    const bool c = has(x, y, z);
                    any = any || c;
                    const bool covering = x >= cov_lo[0] && x <= cov_hi[0] && y >= cov_lo[1] &&
                                          y <= cov_hi[1] && z >= cov_lo[2] && z <= cov_hi[2];
                    if (covering && !c) all = false;
                }
        if (all) return Interval(-1);
        if (!any) return Interval(1);
        return {-1, 1};
    }
    std::unique_ptr<Evaluator> clone() const override { return std::make_unique<CubeSet>(*this); }

    int n;
    double lo, cell;
    std::set<std::array<int, 3>> chosen;
};

// The level-k Menger sponge M_k over the root [0, 3^k]^3: unit cube (x, y, z) is kept when no base-3
// digit position has two digits equal to 1. The classification is by digits, exact on the integer
// grid of the root (with split 3 and depth k every cell box is an exact lattice cube).
//  - kept_inside (f = -1 on the closed M_k, +1 elsewhere): the 20^k kept unit cubes are inside
//    cells; removed cubes touch M_k, so they stay undecided down to the depth (boundary cells),
//    except those deep inside a hole.
//  - !kept_inside (f = +1 on the closed holes, -1 on the interior of M_k): the holes are outside
//    at the level they appear, the kept unit cubes are boundary cells. A cheaper tree (27 * 20^(j-1)
//    cells at level j) with the same solid as the union of inside and boundary cells.
class Menger : public TestShape {
public:
    Menger(int k, bool kept_inside) : TestShape(3), k(k), kept_inside(kept_inside) {
        n = 1;
        for (int i = 0; i < k; ++i) n *= 3;
    }

    // Unit cube j (per axis) is kept.
    bool kept(std::int64_t x, std::int64_t y, std::int64_t z) const {
        for (int i = 0; i < k; ++i) {
            if ((x % 3 == 1) + (y % 3 == 1) + (z % 3 == 1) >= 2) return false;
            x /= 3;
            y /= 3;
            z /= 3;
        }
        return true;
    }

    double eval_point(const double* p) override {
        for (int a = 0; a < 3; ++a)
            if (!(p[a] >= 0 && p[a] <= static_cast<double>(n))) return 1;
        // The unit cubes whose closed box holds p (several on faces, edges and corners).
        std::int64_t lo[3], hi[3];
        bool on_root_boundary = false;
        for (int a = 0; a < 3; ++a) {
            hi[a] = std::min<std::int64_t>(n - 1, static_cast<std::int64_t>(std::floor(p[a])));
            lo[a] = std::max<std::int64_t>(0, static_cast<std::int64_t>(std::ceil(p[a])) - 1);
            on_root_boundary = on_root_boundary || p[a] == 0 || p[a] == static_cast<double>(n);
        }
        bool any = false, all = !on_root_boundary;
        for (auto z = lo[2]; z <= hi[2]; ++z)
            for (auto y = lo[1]; y <= hi[1]; ++y)
                for (auto x = lo[0]; x <= hi[0]; ++x) {
                    const bool c = kept(x, y, z);
                    any = any || c;
                    all = all && c;
                }
        return (kept_inside ? any : all) ? -1 : 1;
    }

    Interval eval_box(const Interval* b) override {
        if (kept_inside) {
            // Within one closed unit cube?
            std::int64_t j[3];
            bool single = true;
            for (int a = 0; a < 3; ++a) {
                j[a] = static_cast<std::int64_t>(std::floor(b[a].lo));
                single = single && j[a] >= 0 && j[a] < n && b[a].hi <= static_cast<double>(j[a] + 1);
            }
            if (single && kept(j[0], j[1], j[2])) return Interval(-1);
            return touches(b, 0, {0, 0, 0}, n) ? Interval(-1, 1) : Interval(1);
        }
        // Within one closed hole (a removed cube of some level)?
        for (int i = 1; i <= k; ++i) {
            const std::int64_t size = n / pow3(i);
            std::int64_t j[3];
            bool single = true;
            for (int a = 0; a < 3; ++a) {
                j[a] = static_cast<std::int64_t>(std::floor(b[a].lo / static_cast<double>(size)));
                single = single && j[a] >= 0 && b[a].hi <= static_cast<double>((j[a] + 1) * size);
            }
            if (!single) break;
            if ((j[0] % 3 == 1) + (j[1] % 3 == 1) + (j[2] % 3 == 1) >= 2) return Interval(1);
        }
        return {-1, 1};
    }
    std::unique_ptr<Evaluator> clone() const override { return std::make_unique<Menger>(*this); }

    int k;
    bool kept_inside;
    std::int64_t n;

private:
    static std::int64_t pow3(int i) {
        std::int64_t p = 1;
        for (int t = 0; t < i; ++t) p *= 3;
        return p;
    }
    // Does the closed box touch a kept unit cube inside the kept cube at `origin` of side `size`?
    bool touches(const Interval* b, int level, std::array<std::int64_t, 3> origin, std::int64_t size) const {
        if (level == k) return true;
        const std::int64_t s = size / 3;
        for (int z = 0; z < 3; ++z)
            for (int y = 0; y < 3; ++y)
                for (int x = 0; x < 3; ++x) {
                    if ((x == 1) + (y == 1) + (z == 1) >= 2) continue;
                    const std::array<std::int64_t, 3> o = {origin[0] + x * s, origin[1] + y * s,
                                                           origin[2] + z * s};
                    bool meets = true;
                    for (int a = 0; a < 3; ++a)
                        meets = meets && b[a].hi >= static_cast<double>(o[static_cast<std::size_t>(a)]) &&
                                b[a].lo <= static_cast<double>(o[static_cast<std::size_t>(a)] + s);
                    if (meets && touches(b, level + 1, o, s)) return true;
                }
        return false;
    }
};

} // namespace frac::rt::test
