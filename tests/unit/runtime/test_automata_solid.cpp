// Meshes of solids (runtime/automata/solid.hpp): a tri-quadratic Bezier block (a bcifs cube topology)
// and seed 002 sec. 3.3's arborescent condensation. With an affine control grid the Bezier solid is
// exactly its box, so the enclosed volumes, vertex counts and shared squares have exact values.
#include "driver/pipeline.hpp"
#include "runtime/automata/solid.hpp"
#include "runtime/mesh.hpp"

#include <catch2/catch.hpp>
#include <fmt/format.h>

#include <cmath>
#include <string>

using namespace frac;

namespace {

const char* const edges = R"(
const half0 = [[1, 1/2, 1/4], [0, 1/2, 1/2], [0, 0, 1/4]];
const half1 = [[1/4, 0, 0], [1/2, 1/2, 0], [1/4, 1/2, 1]];
const third0 = [[1, 2/3, 4/9], [0, 1/3, 4/9], [0, 0, 1/9]];
const third1 = [[4/9, 2/9, 1/9], [4/9, 5/9, 4/9], [1/9, 2/9, 4/9]];
const third2 = [[1/9, 0, 0], [4/9, 1/3, 0], [4/9, 2/3, 1]];
const whole = [[1, 0, 0], [0, 1, 0], [0, 0, 1]];
)";

// The 27 control points p[9z + 3y + x] of the box [0, 2sx] x [0, 2sy] x [0, 2sz] (an affine grid).
std::string box_controls(double sx, double sy, double sz) {
    std::string s = "project = controls(";
    for (int z = 0; z < 3; ++z)
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 3; ++x)
                s += fmt::format("{}({}, {}, {})", s.back() == '(' ? "" : ", ", sx * x, sy * y, sz * z);
    return s + ");";
}

// Faces and blocks cut in n (2: halves, 3: thirds).
std::string cells(int n) {
    const std::string piece = n == 2 ? "half" : "third";
    std::string s = "cell v in bary(1); cell e in bary(3); cell f in bary(9); cell b in bary(27);\n";
    s += "subdivide e {";
    for (int i = 0; i < n; ++i) s += fmt::format(" T{} = {}{};", i, piece, i);
    s += " }\nsubdivide f {";
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
            s += fmt::format(" T{} = kron({}{}, {}{});", i + n * j, piece, j, piece, i);
    s += " }\nsubdivide b {";
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x)
                s += fmt::format(" T{} = kron({}{}, kron({}{}, {}{}));", x + n * y + n * n * z, piece, z,
                                 piece, y, piece, x);
    s +=
        fmt::format(" }}\ntopology e = edge(v) split {0}; topology f = quad(e) split {0} x {0}; topology b = "
                    "cube(f) split {0} x {0} x {0};\n",
                    n);
    return s;
}

ir::Automaton lowered(const std::string& text, const std::string& name) {
    auto c = driver::compile_source("t.frac", text);
    if (!c->ok()) FAIL(c->diags.render(c->sources));
    const front::AutomatonInfo* info = c->module.find_automaton(name);
    REQUIRE(info);
    return info->automaton;
}

ir::Automaton block(double sx, double sy, double sz) {
    return lowered(std::string(edges) + "bcifs block {\n" + cells(2) + box_controls(sx, sy, sz) + "\n}",
                   "block");
}

ir::Automaton arborescent(double sx, double sy, double sz) {
    return lowered(std::string(edges) + "bcifs tree {\n" + cells(3) + R"(
cell a in bary(27);
subdivide a {
    Tb -> b = kron(half1, kron(whole, whole));
    T0 = kron(half0, kron(third0, third0)); T1 = kron(half0, kron(third0, third2));
    T2 = kron(half0, kron(third2, third0)); T3 = kron(half0, kron(third2, third2));
}
a.T0 * a.Tb * b.B1 == a.Tb * b.B0 * f.T0;
a.T1 * a.Tb * b.B1 == a.Tb * b.B0 * f.T2;
a.T2 * a.Tb * b.B1 == a.Tb * b.B0 * f.T6;
a.T3 * a.Tb * b.B1 == a.Tb * b.B0 * f.T8;
initial a;
)" + box_controls(sx, sy, sz) +
                       "\n}",
                   "tree");
}

} // namespace

TEST_CASE("a cube topology's cell is recorded with its six faces", "[solid]") {
    const ir::Automaton a = block(1, 1, 1);
    REQUIRE(a.volume_cells.size() == 1);
    const ir::VolumeCell& v = a.volume_cells[0];
    CHECK(a.states[v.state].name == "b");
    for (std::size_t face = 0; face < 6; ++face) {
        CHECK(a.embeddings[v.faces[face]].label == fmt::format("B{}", face));
        CHECK(a.states[a.embeddings[v.faces[face]].to].name == "f");
    }
    CHECK(rt::reaches_volume(a));
}

TEST_CASE("a Bezier block over an affine grid is meshed as its box, closed at every depth", "[solid]") {
    const ir::Automaton a = block(1, 1.5, 2.5); // the box [0, 2] x [0, 3] x [0, 5]
    for (int p = 0; p <= 4; ++p) {
        INFO("depth " << p);
        const rt::SolidMesh s = rt::tessellate_solid(a, p);
        const rt::MeshCheck check = rt::check_mesh(s.mesh);
        CHECK(check.ok());
        CHECK(check.euler == 2);
        CHECK(check.boundary_edges == 0);
        const double n = std::pow(2.0, p);
        CHECK(s.mesh.vertices.size() == static_cast<std::size_t>(6 * n * n + 2));
        CHECK(s.mesh.triangles.size() == static_cast<std::size_t>(12 * n * n));
        CHECK(check.volume == Approx(30.0).epsilon(1e-12));
        CHECK(s.blocks == 1);
        CHECK(s.faces == 6);
        CHECK(s.inner == 0);
        // Every vertex lies on the box's surface.
        for (const auto& v : s.mesh.vertices) {
            const double extent[3] = {2, 3, 5};
            bool on_side = false;
            for (int r = 0; r < 3; ++r) {
                CHECK(v[r] >= -1e-12);
                CHECK(v[r] <= extent[r] + 1e-12);
                on_side = on_side || std::abs(v[r]) < 1e-12 || std::abs(v[r] - extent[r]) < 1e-12;
            }
            CHECK(on_side);
        }
    }
}

TEST_CASE("a mirrored projection still gives outward normals", "[solid]") {
    const rt::SolidMesh s = rt::tessellate_solid(block(-1, 1, 1), 2); // x reversed: faces turn inwards
    const rt::MeshCheck check = rt::check_mesh(s.mesh);
    CHECK(check.ok());
    CHECK(check.volume == Approx(8.0).epsilon(1e-12));
}

TEST_CASE("the arborescent condensation: layers of blocks, feet on the blocks below, closed", "[solid]") {
    // Over the box [0, 3] x [0, 3] x [0, 4]: the block is its upper half, each copy a third by a third
    // by a half of it, so layer L holds 4^L blocks of volume 18 (2/9)^L.
    const ir::Automaton a = arborescent(1.5, 1.5, 2);
    double volume = 0, inner = 0, blocks = 0;
    for (int p = 0; p <= 3; ++p) {
        INFO("depth " << p);
        volume += 18 * std::pow(2.0 / 9.0, p);
        blocks += std::pow(4.0, p);
        // Copies of layer L + 1 stand on the layer-L blocks (drawn at depth p - L): 4 feet of 9^(p-L-1).
        inner = 0;
        for (int l = 0; l < p; ++l) inner += std::pow(4.0, l) * 4 * std::pow(9.0, p - l - 1);
        const rt::SolidMesh s = rt::tessellate_solid(a, p);
        const rt::MeshCheck check = rt::check_mesh(s.mesh);
        CHECK(check.ok());
        CHECK(check.euler == 2);
        CHECK(check.components == 1);
        CHECK(check.volume == Approx(volume).epsilon(1e-12));
        CHECK(s.blocks == static_cast<std::size_t>(blocks));
        CHECK(s.layers == p + 1);
        CHECK(s.inner == static_cast<std::size_t>(inner));
    }
}

TEST_CASE("a solid mesh needs a volume cell, and says so", "[solid]") {
    ir::Automaton a = block(1, 1, 1);
    a.volume_cells.clear();
    CHECK_FALSE(rt::reaches_volume(a));
    CHECK_THROWS_WITH(rt::tessellate_solid(a, 1), Catch::Contains("no volume cell"));
    CHECK_THROWS_WITH(rt::tessellate_solid(block(1, 1, 1), 25), Catch::Contains("outside [0, 24]"));
    CHECK_THROWS_WITH(rt::tessellate_solid(arborescent(1, 1, 1), 14), Catch::Contains("2^26 vertices"));
}
