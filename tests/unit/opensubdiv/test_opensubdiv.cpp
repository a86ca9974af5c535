// The library's bicubic B-spline patch tessellated by Frac against OpenSubdiv's uniform refinement of
// the same control grid (limit positions): the same surface within 1e-12 at every vertex.
#include "bench/osd_reference.hpp"
#include "driver/pipeline.hpp"
#include "runtime/automata/surface.hpp"

#include <catch2/catch.hpp>

using namespace frac;

TEST_CASE("the bicubic patch agrees with OpenSubdiv's limit surface", "[opensubdiv]") {
    const auto c = driver::compile_source("patch.frac", "import \"ifs\";");
    REQUIRE(c->ok());
    const front::AutomatonInfo* info = c->module.find_automaton("bicubic_bspline_patch");
    REQUIRE(info);
    const ir::Automaton& a = info->automaton;
    const rt::SurfaceLayout layout = rt::infer_layout(a);
    for (const int depth : {1, 4, 8}) {
        const rt::Tessellation t = rt::tessellate(a, layout, depth);
        const osd::RefinedPatch reference = osd::refine_bicubic_patch(osd::patch_controls(a), depth);
        REQUIRE(reference.grid.size() == t.vertices.size());
        INFO("depth " << depth);
        CHECK(osd::max_difference(reference, t.vertices) < 1e-12);
        // OpenSubdiv refines the 9 faces of the control grid; the patch is the central one.
        const std::size_t side = (std::size_t{3} << depth) + 1;
        CHECK(reference.refined_vertices == side * side);
    }
}

TEST_CASE("the comparison fails for another surface", "[opensubdiv]") {
    const auto c = driver::compile_source("patch.frac", "import \"ifs\";");
    REQUIRE(c->ok());
    const ir::Automaton& a = c->module.find_automaton("bicubic_bspline_patch")->automaton;
    rt::Tessellation t = rt::tessellate(a, rt::infer_layout(a), 4);
    auto controls = osd::patch_controls(a);
    controls[5][2] += 1e-9; // an inner control point moved up: the surface moves by about 1e-9 / 2
    CHECK(osd::max_difference(osd::refine_bicubic_patch(controls, 4), t.vertices) > 1e-10);
}
