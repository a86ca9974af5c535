// The streamed evaluation tree: nodes, composites, the text dump and drawings.
#include "runtime/automata/points.hpp"
#include "runtime/automata/tree.hpp"
#include "tests/unit/automata_examples.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

using namespace frac;
using namespace frac::test;

namespace {

ir::Automaton quadratic_with_polygon() {
    ir::Automaton a = bspline(2, {{0, 0}, {1, 2}, {3, 2}, {4, 0}});
    a.states[1].primitive.kind = ir::Primitive::Kind::polyline; // the control polygon e0 e1 e2
    a.states[1].primitive.points = num::Matrix<double>::identity(3);
    return a;
}

} // namespace

TEST_CASE("the tree visits every path once, with its composite operator", "[automata][tree]") {
    const ir::Automaton s = sierpinski();
    std::uint64_t checked = 0;
    const rt::TreeStats stats = rt::walk_tree(s, {3, true}, [&](const rt::TreeNode& node) {
        REQUIRE(node.address->size() == static_cast<std::size_t>(node.depth));
        CHECK(node.leaf == (node.depth == 3));
        // The composite is the product of the arcs along the address, left to right.
        num::Matrix<num::Rational> product = num::Matrix<num::Rational>::identity(3);
        for (std::size_t i : *node.address) product = product * *s.arcs[i].op.exact;
        for (std::size_t r = 0; r < 3; ++r)
            for (std::size_t c = 0; c < 3; ++c) {
                CHECK((*node.op)(r, c) == product(r, c).to_double()); // dyadic: exact in doubles
                CHECK(node.enclosure->operator()(r, c).contains(product(r, c).to_double()));
            }
        ++checked;
    });
    CHECK(stats.nodes == 1 + 3 + 9 + 27);
    CHECK(stats.leaves == 27);
    CHECK(checked == stats.nodes);
}

TEST_CASE("the walk's memory grows with the depth, not the number of nodes", "[automata][tree]") {
    const ir::Automaton cubic = bspline(3, {{0, 0}, {1, 2}, {3, 2}, {4, 0}, {6, 1}});
    std::uint64_t leaves = 0;
    const auto s10 = rt::walk_tree(cubic, {10, false}, [&](const rt::TreeNode& n) { leaves += n.leaf; });
    const auto s20 = rt::walk_tree(cubic, {20, false}, [](const rt::TreeNode&) {});
    CHECK(leaves == 1024); // 2 segments, then 2^9 paths in b
    CHECK(s20.nodes == (std::uint64_t{1} << 21) - 1);
    CHECK(s20.stack_bytes < 2 * s10.stack_bytes + 512);
    CHECK(s20.stack_bytes < 8192);
}

TEST_CASE("the text dump follows the paper's evaluation trees", "[automata][tree]") {
    // Seed 002 Fig. 3: the Penrose tree from a; T0a leads to b, T1a back to a.
    CHECK(rt::tree_text(penrose(), 2, false) == "tree of penrose to depth 2\n"
                                                "a\n"
                                                "  T0a -> b\n"
                                                "    T0b -> b (leaf)\n"
                                                "    T1b -> a (leaf)\n"
                                                "  T1a -> a\n"
                                                "    T0a -> b (leaf)\n"
                                                "    T1a -> a (leaf)\n");
    const std::string with = rt::tree_text(cantor(), 1, true);
    CHECK(with == "tree of cantor to depth 1\n"
                  "c  [1 0; 0 1]\n"
                  "  f0 -> c (leaf)  [0.333333 0; 0 1]\n"
                  "  f1 -> c (leaf)  [0.333333 0.666667; 0 1]\n");
    CHECK_THROWS_WITH(rt::tree_text(cantor(), 65), Catch::Contains("outside [0, 64]"));
}

TEST_CASE("attractor points are fixed points of the first arcs' cycle", "[automata][tree]") {
    // Sierpinski: f0 fixes the origin. Quadratic B-spline: T0b fixes (1/2, 1/2, 0), so a's point is
    // the midpoint of P0 and P1.
    CHECK(rt::attractor_point(sierpinski(), 0) == std::vector<double>{0, 0, 1});
    const auto b = rt::attractor_point(quadratic_with_polygon(), 1);
    CHECK(b == std::vector<double>{0.5, 0.5, 0});
    const auto a = rt::attractor_point(quadratic_with_polygon(), 0);
    CHECK(a == std::vector<double>{0.5, 1, 1});
    ir::Automaton rot;
    rot.states.push_back(state("r", ir::Space::euclidean(1)));
    rot.arcs.push_back(arc(0, 0, affine({{1}}, {1}), "shift"));
    CHECK_THROWS_WITH(rt::attractor_point(rot, 0), Catch::Contains("r -shift-> r"));
}

TEST_CASE("drawings of the leaves, one colour per state", "[automata][tree]") {
    ir::Automaton s = sierpinski();
    s.states[0].primitive.kind = ir::Primitive::Kind::polygon;
    s.states[0].primitive.points = num::Matrix<double>{{0, 1, 0.5}, {0, 0, 1}, {1, 1, 1}};
    const rt::Image img = rt::draw_tree(s, 5, 256);
    CHECK(img.width == 256);
    std::size_t coloured = 0, white = 0;
    for (std::size_t i = 0; i < img.rgb.size(); i += 3) {
        const bool is_white = img.rgb[i] == 255 && img.rgb[i + 1] == 255 && img.rgb[i + 2] == 255;
        white += is_white;
        coloured += !is_white;
        if (!is_white) CHECK(img.rgb[i] == rt::state_colour(0)[0]);
    }
    // 243 triangles of area (1/32)^2 / 2 each cover about 3^5 / 4^5 of the triangle: a good part,
    // but far from all of the picture.
    CHECK(coloured > 5000);
    CHECK(white > 20000);
    // The centre of the middle hole (x = 1/2, y = 1/3) stays white.
    const double scale = 256 / 1.04;
    const auto px = static_cast<std::size_t>((0.5 + 0.02) * scale),
               py = static_cast<std::size_t>(img.height - (1.0 / 3 + 0.02) * scale);
    const std::size_t at = (py * static_cast<std::size_t>(img.width) + px) * 3;
    CHECK(img.rgb[at] == 255);

    const auto dir = std::filesystem::temp_directory_path() / "frac_tree_test";
    std::filesystem::create_directories(dir);
    const ir::Automaton q = quadratic_with_polygon();
    rt::write_tree_png(q, 6, (dir / "quadratic.png").string(), 128);
    rt::write_tree_svg(q, 6, (dir / "quadratic.svg").string());
    CHECK(std::filesystem::file_size(dir / "quadratic.png") > 100);
    std::ifstream in(dir / "quadratic.svg");
    std::stringstream text;
    text << in.rdbuf();
    CHECK(text.str().find("<polyline") != std::string::npos);
    std::size_t lines = 0;
    for (std::size_t at2 = 0; (at2 = text.str().find("<polyline", at2)) != std::string::npos; ++at2) ++lines;
    CHECK(lines == 2 * 32); // two segments, 2^5 leaves below each
    std::filesystem::remove_all(dir);
}

TEST_CASE("the tree's size is counted before the walk, without overflow", "[automata][tree]") {
    const ir::Automaton cubic = bspline(3, {{0, 0}, {1, 2}, {3, 2}, {4, 0}, {6, 1}});
    for (const ir::Automaton& a : {sierpinski(), cubic, quadratic_with_polygon()})
        for (int depth : {0, 1, 4, 9}) {
            const rt::TreeStats walked = rt::walk_tree(a, {depth, false}, [](const rt::TreeNode&) {});
            const rt::TreeSize counted = rt::tree_size(a, depth);
            CHECK(counted.nodes == static_cast<double>(walked.nodes));
            CHECK(counted.leaves == static_cast<double>(walked.leaves));
        }
    // 3^64 leaves: far beyond 64-bit counters, still a number to compare with a limit.
    const rt::TreeSize deep = rt::tree_size(sierpinski(), 64);
    CHECK(deep.leaves == Approx(std::pow(3.0, 64)));
    CHECK(deep.nodes == Approx((std::pow(3.0, 65) - 1) / 2));
    // The SVG estimate is near the file written (polylines of 3 points: 2 segments, 2^6 leaves).
    const auto path = std::filesystem::temp_directory_path() / "frac_tree_size.svg";
    rt::write_tree_svg(quadratic_with_polygon(), 6, path.string());
    const double written = static_cast<double>(std::filesystem::file_size(path));
    std::filesystem::remove(path);
    const double foreseen = rt::tree_size(quadratic_with_polygon(), 6).svg_bytes;
    CHECK(foreseen > 0.7 * written);
    CHECK(foreseen < 1.3 * written);
}
