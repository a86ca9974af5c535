// Slices of 3D covers: the cells meeting a plane, their placement and classes, the plane on a grid
// boundary (both sides), the three axes, PNG output and argument errors.
#include "runtime/rss.hpp"
#include "runtime/slice.hpp"
#include "test_mesh_shapes.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <stdexcept>

using namespace frac;
using namespace frac::rt;
using frac::rt::test::Ball;
using frac::rt::test::Menger;

namespace {

RssOptions opts(int depth, int split) {
    RssOptions o;
    o.depth = depth;
    o.split = split;
    return o;
}

std::vector<Interval> cube(double lo, double hi) {
    return {{lo, hi}, {lo, hi}, {lo, hi}};
}

// The expected ASCII character of unit cube (x, y, z) of the level-2 sponge (kept cubes inside):
// its class as the evaluator decides it on the exact cube.
char expected_class(Menger& s, int x, int y, int z) {
    const Interval b[3] = {
        {double(x), double(x + 1)}, {double(y), double(y + 1)}, {double(z), double(z + 1)}};
    const Interval f = s.eval_box(b);
    return f.hi < 0 ? '#' : f.lo > 0 ? '.' : '+';
}

} // namespace

TEST_CASE("slice: a layer of the level-2 sponge, one character per cell", "[slice]") {
    Menger s(2, true);
    const RssResult r = subdivide(s, cube(0, 9), opts(2, 3));

    // z = 4.5 cuts the unit layer z in [4, 5] only.
    const Cover v = slice(r, 4.5);
    CHECK(v.dimension() == 2);
    CHECK(v.root[0] == Interval(0, 9));
    CHECK(v.levels[0].evaluated == 1);
    CHECK(v.levels[1].evaluated == 9);
    CHECK(v.levels[2].evaluated == 81); // nothing of layer 4 is decided at level 1
    CHECK(v.evaluated == v.cells.size());
    CHECK(v.evaluated == v.inside + v.outside + v.boundary + v.subdivided);
    std::string want;
    for (int y = 8; y >= 0; --y) {
        for (int x = 0; x < 9; ++x) want += expected_class(s, x, y, 4);
        want += '\n';
    }
    CHECK(ascii_picture(v, 9, 9) == want);
    CHECK(v.inside == 16); // x, y in {0, 2, 6, 8}: no digit 1 anywhere

    // z = 3 lies between the layers 2 and 3: the cells of both meet it. A character is '#' only when
    // both cubes are inside.
    const Cover w = slice(r, 3.0);
    want.clear();
    for (int y = 8; y >= 0; --y) {
        for (int x = 0; x < 9; ++x) {
            const char a = expected_class(s, x, y, 2), b = expected_class(s, x, y, 3);
            want += a == '+' || b == '+'   ? '+'
                    : a == '#' && b == '#' ? '#'
                    : a == '.' && b == '.' ? '.'
                                           : ':';
        }
        want += '\n';
    }
    CHECK(ascii_picture(w, 9, 9) == want);
}

TEST_CASE("slice: the three axes of a ball give the same picture", "[slice]") {
    Ball ball(0.7);
    const RssResult r = subdivide(ball, cube(-1, 1), opts(5, 2));
    const std::string z = ascii_picture(slice(r, 0.3, 2), 32, 32);
    CHECK(ascii_picture(slice(r, 0.3, 0), 32, 32) == z);
    CHECK(ascii_picture(slice(r, 0.3, 1), 32, 32) == z);
    // Through the centre: a disk of inside cells ringed by boundary cells.
    const std::string c = ascii_picture(slice(r, 0.0), 32, 32);
    CHECK(c[16 * 33 + 16] == '#');
    CHECK(c[0] == '.');
    CHECK(c.find('+') != std::string::npos);
    // At the top of the box the ball is far: all outside.
    const Cover top = slice(r, 1.0);
    CHECK(top.inside == 0);
    CHECK(top.boundary == 0);
}

TEST_CASE("slice: PNG output", "[slice]") {
    Menger s(2, true);
    const RssResult r = subdivide(s, cube(0, 9), opts(2, 3));
    const auto dir = std::filesystem::temp_directory_path() / "frac_test_slice";
    std::filesystem::create_directories(dir);
    const std::string path = (dir / "layer.png").string();
    write_slice_png(r, 4.5, path, PictureKind::both, 90);
    std::ifstream in(path, std::ios::binary);
    unsigned char head[24] = {};
    in.read(reinterpret_cast<char*>(head), 24);
    REQUIRE(in);
    CHECK(head[1] == 'P');
    CHECK(head[2] == 'N');
    CHECK(head[3] == 'G');
    const auto be32 = [&](int at) {
        return (std::uint32_t{head[at]} << 24) | (std::uint32_t{head[at + 1]} << 16) |
               (std::uint32_t{head[at + 2]} << 8) | head[at + 3];
    };
    CHECK(be32(16) == 2 * 90 + 2); // both panels and the gap
    CHECK(be32(20) == 90);
    std::filesystem::remove_all(dir);
    CHECK_THROWS_AS(write_slice_png(r, 4.5, "/nonexistent-dir/x/layer.png"), std::runtime_error);
}

TEST_CASE("slice: argument errors", "[slice]") {
    test::Disk disk(0, 0, 0.5);
    const RssResult flat = subdivide(disk, {{-1.0, 1.0}, {-1.0, 1.0}}, opts(2, 2));
    CHECK_THROWS_AS(slice(flat, 0.0), std::invalid_argument);

    Ball ball(0.5);
    RssOptions o = opts(2, 2);
    o.keep_cells = false;
    CHECK_THROWS_AS(slice(subdivide(ball, cube(-1, 1), o), 0.0), std::invalid_argument);

    const RssResult r = subdivide(ball, cube(-1, 1), opts(2, 2));
    CHECK_THROWS_AS(slice(r, 0.0, 3), std::invalid_argument);
    CHECK_THROWS_AS(slice(r, 1.5), std::invalid_argument);
    CHECK_THROWS_WITH(slice(r, -2.0, 0), Catch::Contains("x = -2"));
    CHECK_NOTHROW(slice(r, -1.0));
    CHECK_NOTHROW(slice(r, 1.0, 1));
}
