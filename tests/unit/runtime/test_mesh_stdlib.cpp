// Exact covers and meshes of real models: the standard library's Menger sponge (menger_lattice, through
// the frontend and the interpreter) covered with split 3 down to its level proves exactly its 20^k unit
// cubes inside, and meshes to the same surface as the digit-exact test evaluator; the CSG example
// examples/menger_frame.frac meshes to a closed surface with the Euler characteristic derived below.
#include "backend/interp/interpreter.hpp"
#include "driver/pipeline.hpp"
#include "ir/tape.hpp"
#include "mesh_euler.hpp"
#include "runtime/rss.hpp"

#include <catch2/catch.hpp>

#include <memory>
#include <string>

using namespace frac;
using namespace frac::rt;
using frac::rt::test::carpet_euler;
using frac::rt::test::cubes_euler;
using frac::rt::test::Menger;
using frac::rt::test::menger_solid_euler;
using frac::rt::test::require_closed;

namespace {

struct Compiled {
    std::unique_ptr<front::Compilation> c;
    const front::ShapeInfo* shape = nullptr;
    std::unique_ptr<ir::Evaluator> eval;
};

Compiled compile(std::unique_ptr<front::Compilation> c, const std::string& shape) {
    Compiled m;
    m.c = std::move(c);
    if (!m.c->ok()) FAIL(m.c->diags.render(m.c->sources));
    m.shape = m.c->module.find_shape(shape);
    REQUIRE(m.shape);
    m.eval = interp::make_interpreter(ir::build_tape(m.c->module.graph, m.shape->root, m.shape->dimension));
    return m;
}

// The level-k sponge of the standard library in lattice units, over [0, 3^k]^3.
Compiled sponge(int k) {
    const std::string side = std::to_string(Menger(k, true).n);
    return compile(driver::compile_source("t.frac", "import \"solids\";\nshape s(x, y, z) over [0, " + side +
                                                        "] × [0, " + side + "] × [0, " + side +
                                                        "] = menger_lattice((x, y, z), " + std::to_string(k) +
                                                        ");"),
                   "s");
}

RssResult cover(Compiled& m, int depth, bool closed_inside) {
    RssOptions o;
    o.depth = depth;
    o.split = 3;
    o.closed_inside = closed_inside;
    return subdivide(*m.eval, m.shape->box, o);
}

std::uint64_t pow20(int k) {
    std::uint64_t p = 1;
    for (int i = 0; i < k; ++i) p *= 20;
    return p;
}

} // namespace

TEST_CASE("stdlib sponge: split 3 at depth k proves exactly the 20^k cubes of the level-k sponge",
          "[mesh][stdlib]") {
    for (int k = 1; k <= 4; ++k) { // k = 4: 160000 cubes, the mesh of test_mesh.cpp's depth-4 sponge
        INFO("level " << k);
        Compiled m = sponge(k);
        const RssResult r = cover(m, k, true);
        REQUIRE(r.inside == pow20(k));
        REQUIRE(r.levels[static_cast<std::size_t>(k)].inside == pow20(k));
        // Cell by cell: inside exactly where the digits say the unit cube is kept. Removed cubes touch
        // the sponge, so they are boundary cells, unless they lie in a hole's interior (then outside).
        const Menger digits(k, true);
        std::uint64_t checked = 0, wrong = 0;
        for (const Cell& c : r.cells) {
            if (c.level != k) continue;
            ++checked;
            wrong += (c.cls == CellClass::inside) != digits.kept(c.ix, c.iy, c.iz);
        }
        CHECK(checked == r.levels[static_cast<std::size_t>(k)].evaluated);
        CHECK(wrong == 0);

        // The mesh is the sponge's: closed, manifold, the sponge's Euler characteristic, and the same
        // vertices and triangles as the mesh of the digit-exact test evaluator's cover.
        const Mesh mesh = mesh_cover(r, MeshSelection::inside);
        const MeshCheck ck = check_mesh(mesh);
        require_closed(mesh, ck);
        CHECK(ck.components == 1);
        CHECK(ck.euler == 2 * menger_solid_euler(k));
        CHECK(enclosed_volume(mesh) == static_cast<double>(pow20(k)));
        Menger oracle(k, true);
        RssOptions o;
        o.depth = k;
        o.split = 3;
        const RssResult ro = subdivide(oracle, m.shape->box, o);
        const Mesh expected = mesh_cover(ro, MeshSelection::inside);
        CHECK(mesh.vertices == expected.vertices);
        CHECK(mesh.triangles == expected.triangles);

        // With the open rule (hi < 0, for boundary covers) the cubes whose faces lie on the surface,
        // where f = 0, are not inside: the closed rule is what makes the solid exact.
        if (k <= 3) {
            const RssResult open = cover(m, k, false);
            CHECK(open.inside < r.inside);
        }
    }
}

TEST_CASE("stdlib sponge: deeper covers add no inside cells", "[mesh][stdlib]") {
    // Level-2 sponge at depth 3: the 400 cubes are proven at level 2; the children of the removed
    // cubes lie in holes (f > 0 inside them), so none of them is inside.
    Compiled m = sponge(2);
    const RssResult r = cover(m, 3, true);
    CHECK(r.inside == 400);
    CHECK(r.levels[2].inside == 400);
    CHECK(r.levels[3].inside == 0);
    const MeshCheck ck = check_mesh(mesh_cover(r, MeshSelection::inside));
    CHECK(ck.ok());
    CHECK(ck.euler == 2 * menger_solid_euler(2));
}

TEST_CASE("stdlib sponge: the stdlib shape menger3 is the level-2 sponge", "[mesh][stdlib]") {
    Compiled m = compile(driver::compile_source("t.frac", "import \"solids\";"), "menger3");
    const RssResult r = cover(m, 2, true);
    CHECK(r.inside == 400);
    CHECK(check_mesh(mesh_cover(r, MeshSelection::inside)).euler == 2 * menger_solid_euler(2));
}

// ---- The CSG example: a level-3 sponge in a collar ----
//
// examples/menger_frame.frac: A = the sponge M_3 on [0, 27]^3, B = the collar, the slab
// [-9, 36]^2 x [0, 9] minus the open window (0, 27)^2 x R. chi(A u B) = chi(A) + chi(B) - chi(A n B):
//  - chi(A) = chi(M_3) = -1408;
//  - B is a square annulus times an interval, a solid torus: chi(B) = 0;
//  - A n B is the sponge's trace on the lower third of its four side faces. A side face of M_3 is the
//    carpet C_3; its lower third is the bottom row of three level-2 carpets C_2 (chi 1 - 9 = -8), glued
//    along two segments: 3 (-8) - 2 = -26 per face. The four faces meet along the four vertical corner
//    segments: chi(A n B) = 4 (-26) - 4 = -108 (in general 12 chi(C_(k-1)) - 12).
// So chi(A u B) = -1408 + 108 = -1300. A u B is a 3-manifold with boundary (the collar meets the sponge
// along whole unit faces: the sponge's face layer at z in [0, 3] has no removed cube, so no cubes of the
// two parts meet only along an edge or at a corner), and its surface has chi = 2 (-1300) = -2600.
TEST_CASE("CSG example: the sponge in its collar meshes to the exact Euler characteristic",
          "[mesh][stdlib]") {
    Compiled m = compile(driver::compile_file(std::string(FRAC_SOURCE_DIR) + "/examples/menger_frame.frac"),
                         "sponge_in_frame");
    const std::int64_t chi_sponge = menger_solid_euler(3);
    const std::int64_t chi_contact = 4 * (3 * carpet_euler(2) - 2) - 4;
    const std::int64_t chi = chi_sponge + 0 - chi_contact;
    CHECK(chi_contact == -108);
    CHECK(chi == -1300);

    // The same number from the cubical complex of the unit cubes, chosen by digits and integer bounds.
    const Menger digits(3, true);
    const auto solid = [&](std::int64_t x, std::int64_t y, std::int64_t z) { // lattice coordinates
        const bool in_sponge =
            x >= 0 && y >= 0 && z >= 0 && x < 27 && y < 27 && z < 27 && digits.kept(x, y, z);
        const bool in_collar = x >= -9 && x < 36 && y >= -9 && y < 36 && z >= 0 && z < 9 &&
                               !(x >= 0 && x < 27 && y >= 0 && y < 27);
        return in_sponge || in_collar;
    };
    CHECK(cubes_euler(81, [&](std::int64_t x, std::int64_t y, std::int64_t z) {
              return solid(x - 27, y - 27, z - 27);
          }) == chi);

    const RssResult r = cover(m, 4, true);
    const Mesh mesh = mesh_cover(r, MeshSelection::inside);
    const MeshCheck ck = check_mesh(mesh);
    require_closed(mesh, ck);
    CHECK(ck.components == 1);
    CHECK(mesh.stats.split_points == 0);
    CHECK(mesh.stats.nonmanifold_edges == 0);
    CHECK(ck.euler == 2 * chi);
    CHECK(enclosed_volume(mesh) == 8000.0 + (45.0 * 45 - 27 * 27) * 9);
    // Every unit cell of the cover is inside exactly where the solid has a unit cube.
    std::uint64_t wrong = 0;
    for (const Cell& c : r.cells)
        if (c.level == 4) wrong += (c.cls == CellClass::inside) != solid(c.ix - 27, c.iy - 27, c.iz - 27);
    CHECK(wrong == 0);
}
