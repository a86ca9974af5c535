// Surfaces: the library's bicubic B-spline patch (stdlib/ifs.frac) tessellated by Frac to depth p
// against OpenSubdiv refining the same 4 x 4 control grid uniformly to level p on the CPU (Catmull-Clark
// on the grid's 3 x 3 faces, double primvars, limit positions at the last level; the patch is the
// central face). Both give the patch's (2^p + 1)^2 vertices at s, t = i / 2^p; OpenSubdiv computes
// the other 8 faces too, as uniform refinement of the grid does. Best of R runs each, one process.
//
// Usage: bench_surface [depth, default 8] [runs, default 5]
#include "bench/osd_reference.hpp"
#include "bench_common.hpp"
#include "driver/pipeline.hpp"
#include "runtime/automata/surface.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <iostream>

using namespace frac;
using bench::Clock;
using bench::seconds_since;

int main(int argc, char** argv) {
    const int depth = argc > 1 ? std::atoi(argv[1]) : 8;
    const int runs = argc > 2 ? std::max(1, std::atoi(argv[2])) : 5;
    if (depth < 1 || depth > 10) {
        std::cerr << "bench_surface: depth in [1, 10]\n";
        return 2;
    }
    const auto c = driver::compile_source("patch.frac", "import \"ifs\";");
    if (!c->ok()) {
        std::cerr << c->diags.render(c->sources);
        return 1;
    }
    const ir::Automaton& a = c->module.find_automaton("bicubic_bspline_patch")->automaton;

    // Frac: the layout inferred (exact joins), the vertex grid, the triangles: what frac mesh does.
    double frac_best = 1e300, grid_best = 1e300, layout_best = 1e300, mesh_best = 1e300;
    rt::Tessellation t;
    std::size_t triangles = 0;
    for (int r = 0; r < runs; ++r) {
        const auto t0 = Clock::now();
        const rt::SurfaceLayout layout = rt::infer_layout(a);
        const auto t1 = Clock::now();
        layout_best = std::min(layout_best, std::chrono::duration<double>(t1 - t0).count());
        t = rt::tessellate(a, layout, depth);
        grid_best = std::min(grid_best, seconds_since(t1));
        const auto t2 = Clock::now();
        triangles = rt::surface_mesh(t).triangles.size();
        mesh_best = std::min(mesh_best, seconds_since(t2));
        frac_best = std::min(frac_best, seconds_since(t0));
    }
    // OpenSubdiv: topology refinement, primvar interpolation over the levels, limit positions.
    osd::RefinedPatch best;
    double osd_best = 1e300;
    for (int r = 0; r < runs; ++r) {
        osd::RefinedPatch p = osd::refine_bicubic_patch(osd::patch_controls(a), depth);
        if (p.seconds() < osd_best) {
            osd_best = p.seconds();
            best = std::move(p);
        }
    }
    const double primvar = best.interpolate_seconds + best.limit_seconds;
    const double diff = osd::max_difference(best, t.vertices);

    fmt::print("bicubic B-spline patch, depth {}: {} patch vertices, best of {} runs\n", depth,
               t.vertices.size(), runs);
    fmt::print("  frac        {:9.3f} ms  (layout {:.3f}, grid {:.3f}, {} triangles {:.3f})\n",
               frac_best * 1e3, layout_best * 1e3, grid_best * 1e3, triangles, mesh_best * 1e3);
    fmt::print("  opensubdiv  {:9.3f} ms  (topology {:.3f}, interpolate {:.3f}, limit {:.3f}; {} vertices at "
               "the last level)\n",
               osd_best * 1e3, best.topology_seconds * 1e3, best.interpolate_seconds * 1e3,
               best.limit_seconds * 1e3, best.refined_vertices);
    fmt::print(
        "  frac / opensubdiv: {:.3f} (all), {:.3f} (against its primvar work alone, topology reused)\n",
        frac_best / osd_best, frac_best / primvar);
    fmt::print("  largest vertex difference: {:.3g} ({})\n", diff,
               diff < 1e-12 ? "agree within 1e-12" : "DIFFER");
    return diff < 1e-12 ? 0 : 1;
}
