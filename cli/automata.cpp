// frac tree, frac chaos, and render / mesh / dimension of automata (ifs, cifs).
#include "cli/commands.hpp"

#include "driver/queries.hpp"
#include "frontend/lower.hpp"
#include "runtime/automata/attractor_cover.hpp"
#include "runtime/automata/chaos.hpp"
#include "runtime/automata/dimension.hpp"
#include "runtime/automata/solid.hpp"
#include "runtime/automata/surface.hpp"
#include "runtime/automata/tree.hpp"
#include "runtime/dimension.hpp"
#include "runtime/legend.hpp"
#include "runtime/limits.hpp"
#include "runtime/picture.hpp"
#include "runtime/relief.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <functional>
#include <iostream>
#include <stdexcept>
#include <string_view>

namespace frac::cli {

namespace {

// Runs a runtime job, turning its refusals (std::invalid_argument) into run-time errors.
template <class F>
auto runtime_job(F&& job) {
    try {
        return job();
    } catch (const rt::RangeError&) {
        throw; // reported at the automaton (on_automaton)
    } catch (const std::invalid_argument& e) {
        throw RunError(e.what());
    }
}

void check_picture_output(const std::string& path, bool svg_allowed) {
    if (path.empty()) throw UsageError("give the picture file: -o FILE.png");
    if (!ends_with(path, ".png") && !(svg_allowed && ends_with(path, ".svg")))
        throw UsageError(fmt::format("cannot tell the picture format of '{}': use .png{}", path,
                                     svg_allowed ? " or .svg" : ""));
    check_output_writable(path);
}

// Refuses, before any walk, a tree of more nodes than the limit (--max-cells, FRAC_MAX_CELLS, else
// rt::default_max_tree_nodes) and an SVG drawing of it over the output size limit (unless forced).
void check_tree_size(const ir::Automaton& a, int depth, const std::string& output, const WorkLimits& limits,
                     bool force) {
    const rt::TreeSize size = runtime_job([&] { return rt::tree_size(a, depth); });
    const std::uint64_t limit = limit_of(limits.cells, "FRAC_MAX_CELLS", rt::default_max_tree_nodes);
    if (size.nodes > static_cast<double>(limit))
        throw cell_limit_error(rt::LimitError(
            fmt::format("depth {}: the evaluation tree of {} has about {:.3g} nodes, more than the limit of "
                        "{} nodes",
                        depth, a.name, size.nodes, limit),
            size.nodes, limit));
    if (ends_with(output, ".svg")) check_output_size(output, size.svg_bytes, force);
}

// The primitives of the evaluation tree's leaves, one colour per state (.svg: curves as polylines).
void draw_tree(const ir::Automaton& a, int depth, const std::string& output, int size,
               const WorkLimits& limits, bool force) {
    check_tree_size(a, depth, output, limits, force);
    runtime_job([&] {
        if (ends_with(output, ".svg"))
            rt::write_tree_svg(a, depth, output);
        else
            rt::write_tree_png(a, depth, output, size);
        return 0;
    });
    std::cout << fmt::format("wrote {} (evaluation tree of {} to depth {})\n", output, a.name, depth);
}

// The options of an attractor cover to --depth (grid level depth - 3, then 3 refinements of the kept
// cells) within --max-cells (else FRAC_MAX_CELLS, else the cover's own budget) cells a level, and 32 arcs
// a cell.
rt::AttractorCoverOptions cover_options(const RenderOptions& o) {
    if (o.depth < 3 || o.depth > 14) throw UsageError("--depth of an attractor cover is 3 to 14");
    rt::AttractorCoverOptions co;
    co.refinements = 3;
    co.initial_level = o.depth - co.refinements;
    co.max_cells = limit_of(o.limits.cells, "FRAC_MAX_CELLS", co.max_cells);
    co.max_arcs = co.max_cells > UINT64_MAX / 32 ? UINT64_MAX : 32 * co.max_cells;
    return co;
}

// Runs a cover: its refusals by the cell limit (rt::LimitError) as RunErrors saying how to raise it.
template <class F>
rt::AttractorCoverResult cover_job(F&& job) {
    try {
        return runtime_job(job);
    } catch (const rt::LimitError& e) {
        throw cell_limit_error(e);
    }
}

// The cover's picture, and how each graph of the refinement went. A 3D cover is drawn as its section by
// the plane of --slice, or as a shaded relief seen from +z (.png).
void write_cover(const rt::AttractorCoverResult& cover, const RenderOptions& o, const std::string& name) {
    const rt::PictureKind kind = o.kind == "process" ? rt::PictureKind::process
                                 : o.kind == "cover" ? rt::PictureKind::cover
                                                     : rt::PictureKind::both;
    const SliceRequest plane = parse_slice(o.slice);
    std::string what = "cell-graph cover";
    if (cover.dimension() == 3 && plane.axis < 0) {
        rt::write_png(rt::relief_image(cover, o.size), o.output);
        what = "relief of the cell-graph cover, seen from +z,";
    } else {
        const rt::Cover section = plane.axis >= 0 ? section_of(cover, plane, o.slice) : rt::Cover{};
        const rt::Cover& picture = plane.axis >= 0 ? section : cover;
        if (ends_with(o.output, ".png"))
            rt::write_png(rt::with_legend(rt::render(picture, kind, o.size), kind), o.output);
        else
            write_cover_svg(picture, o.output, kind, o.force);
        if (plane.axis >= 0) what = fmt::format("section {} of the cell-graph cover", o.slice);
    }
    for (const rt::CoverStep& s : cover.steps)
        std::cout << fmt::format("level {:2}: {} cells, {} arcs, {} kept, {} {:.6g}\n", s.level, s.cells,
                                 s.arcs, s.kept, cover.dimension() == 3 ? "volume" : "area", s.area);
    std::cout << fmt::format("wrote {} ({} of {})\n", o.output, what, name);
}

// Refuses, before any work, a --slice or an output a cover of `dimension` axes cannot be drawn to.
void check_cover_picture(const RenderOptions& o, int dimension, const std::string& name) {
    if (!o.slice.empty() && dimension != 3)
        throw UsageError(fmt::format("--slice is for 3D shapes and covers; '{}' is {}D", name, dimension));
    parse_slice(o.slice);
    if (dimension == 3 && o.slice.empty() && !ends_with(o.output, ".png"))
        throw UsageError(fmt::format("'{}' is 3D: draw a section of its cover with --slice z=VALUE, or a "
                                     "relief (shaded depth image) as .png",
                                     name));
}

// --layout NxM or N, --cells A,B,...
rt::LayoutRequest layout_request(const MeshOptions& o) {
    rt::LayoutRequest r;
    if (!o.layout.empty()) {
        // N or NxM, digits only.
        const auto number = [](std::string_view text) -> std::size_t {
            std::size_t v = 0;
            const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
            return ec == std::errc() && end == text.data() + text.size() && v >= 2 && v <= 64 ? v : 0;
        };
        const std::string_view text = o.layout;
        const std::size_t x = text.find('x');
        r.dimension = x == std::string_view::npos ? 1 : 2;
        r.n_s = number(text.substr(0, x));
        r.n_t = x == std::string_view::npos ? 1 : number(text.substr(x + 1));
        if (r.n_s == 0 || r.n_t == 0)
            throw UsageError(fmt::format(
                "--layout needs NxM (a quad patch) or N (a curve), each 2 to 64, not '{}'", o.layout));
    }
    for (std::size_t start = 0; !o.cells.empty() && start <= o.cells.size();) {
        const std::size_t comma = std::min(o.cells.find(',', start), o.cells.size());
        r.cells.push_back(o.cells.substr(start, comma - start));
        start = comma + 1;
    }
    return r;
}

// Several patches joined along the sides they share (rt::tessellate_patches).
int mesh_patches(const front::AutomatonInfo& info, const MeshOptions& o) {
    const rt::PatchSurface s = runtime_job([&] { return rt::tessellate_patches(info.automaton, o.depth); });
    if (ends_with(o.output, ".svg"))
        throw UsageError(fmt::format("{} is a surface: write it as .stl, .obj or .ply", info.name));
    const rt::MeshCheck check = rt::check_mesh(s.mesh);
    const bool ok = check.manifold && check.oriented && check.edges > 0;
    std::cerr << fmt::format(
        "{}: {} patches, {} joined sides; depth {}: {} vertices, {} triangles, {} rim edges; "
        "{}, Euler characteristic {}, {} components\n",
        info.name, s.patches, s.joins, o.depth, s.mesh.vertices.size(), s.mesh.triangles.size(),
        check.boundary_edges, ok ? "manifold and oriented" : "NOT manifold: " + check.problem, check.euler,
        check.components);
    write_mesh_file(s.mesh, o.output, o.force);
    return ok ? 0 : 1;
}

} // namespace

int on_automaton(const front::Compilation& c, const front::AutomatonInfo& info,
                 const std::function<int()>& job) {
    try {
        return job();
    } catch (const rt::RangeError& e) {
        front::Diagnostics diags;
        diags.error(info.loc, e.what());
        std::cerr << diags.render(c.sources);
        return front::exit_runtime_error;
    }
}

const front::AutomatonInfo& find_automaton(const front::Compilation& c, const std::string& name) {
    if (const front::AutomatonInfo* a = c.module.find_automaton(name)) return *a;
    std::vector<std::string> known;
    for (const auto& a : c.module.automata) known.push_back(a.name);
    no_such_name("ifs or cifs", name, known, "automata");
}

int run_tree(const std::string& file, const TreeOptions& o) {
    if (o.depth < 0 || o.depth > 24) throw UsageError("--depth must be between 0 and 24");
    if (!o.output.empty()) check_picture_output(o.output, true);
    auto c = compile_or_report(file);
    if (!c) return front::exit_compile_error;
    const front::AutomatonInfo& info = find_automaton(*c, o.name);
    const ir::Automaton& a = info.automaton;
    if (o.output.empty()) { // the text dump (--emit=tree): each node's state and composite operator
        check_tree_size(a, o.depth, o.output, o.limits, o.force);
        runtime_job([&] {
            rt::write_tree_text(a, o.depth, std::cout, o.matrices);
            return 0;
        });
        return 0;
    }
    return on_automaton(*c, info, [&] {
        draw_tree(a, o.depth, o.output, o.size, o.limits, o.force);
        return 0;
    });
}

int run_solve(const std::string& file, const std::string& name) {
    auto c = compile_or_report(file);
    if (!c) return front::exit_compile_error;
    bool any = false;
    for (const front::AutomatonInfo& a : c->module.automata) {
        if (a.solution.empty() || (!name.empty() && a.name != name)) continue;
        std::cout << a.solution;
        any = true;
    }
    if (!any && !name.empty()) {
        const front::AutomatonInfo& a = find_automaton(*c, name);
        throw UsageError(
            fmt::format("'{}' is an ifs or cifs, not a bcifs: it has no constraints to solve", a.name));
    }
    if (!any) throw UsageError(fmt::format("{} has no bcifs", file));
    return 0;
}

int run_chaos(const std::string& file, const ChaosCommandOptions& o) {
    check_picture_output(o.output, false);
    if (o.points < 1 || o.points > 4'000'000'000ULL) throw UsageError("-n must be between 1 and 4e9 points");
    if (o.size < 16 || o.size > 8192) throw UsageError("--size must be between 16 and 8192 pixels");
    auto c = compile_or_report(file);
    if (!c) return front::exit_compile_error;
    const front::AutomatonInfo& info = find_automaton(*c, o.name);
    rt::ChaosOptions co;
    co.points = o.points;
    co.seed = o.seed;
    co.threads = o.threads;
    co.width = o.size;
    return on_automaton(*c, info, [&] {
        const rt::Density d = runtime_job([&] { return rt::chaos_game(info.automaton, co); });
        rt::write_density_png(d, o.output);
        std::cout << fmt::format("wrote {} ({} points of {}, seed {}, over [{}, {}] × [{}, {}])\n", o.output,
                                 d.recorded, info.name, o.seed, d.x0, d.x1, d.y0, d.y1);
        return 0;
    });
}

int render_automaton(const front::AutomatonInfo& info, const RenderOptions& o) {
    const ir::Automaton& a = info.automaton;
    if (o.output.empty())
        throw UsageError("render of an automaton needs -o FILE.png (or .svg for --method tree)");
    std::string method = o.method;
    if (method.empty()) {
        method = "chaos";
        for (const ir::State& s : a.states)
            if (s.primitive.kind != ir::Primitive::Kind::none) method = "tree";
    }
    if (!o.slice.empty() && method != "cover")
        throw UsageError("--slice draws a section of a cover: give --method cover");
    if (!o.box.empty())
        throw UsageError(fmt::format("--box sets the view of a shape's cover; '{}' is an automaton, drawn "
                                     "over the bounds of its attractor",
                                     info.name));
    if (method == "chaos" && ends_with(o.output, ".svg"))
        throw UsageError("--method chaos draws a .png; .svg is for --method tree or cover");
    if (method == "tree") {
        if (o.depth > 24) throw UsageError("--depth of an evaluation tree is at most 24");
        draw_tree(a, o.depth, o.output, o.size, o.limits, o.force);
        return 0;
    }
    if (method == "chaos") {
        rt::ChaosOptions co;
        co.width = o.size;
        co.points = static_cast<std::uint64_t>(o.size) * static_cast<std::uint64_t>(o.size) * 8;
        const rt::Density d = runtime_job([&] { return rt::chaos_game(a, co); });
        rt::write_density_png(d, o.output);
        std::cout << fmt::format("wrote {} (chaos game of {}: {} points, seed {})\n", o.output, info.name,
                                 d.recorded, co.seed);
        return 0;
    }
    // A cover by cell graphs (seed 000 sec. 2.4) in the box of the attractor's proven bounding ball.
    const rt::AttractorCoverOptions co = cover_options(o);
    check_cover_picture(o, a.output_dimension(), info.name);
    write_cover(cover_job([&] { return rt::automaton_attractor_cover(a, {}, co); }), o, info.name);
    return 0;
}

int render_map(front::Compilation& c, const front::Item& map, const RenderOptions& o,
               const EngineOptions& engine) {
    if (o.output.empty()) throw UsageError("render of a map needs -o FILE.png or FILE.svg");
    if (o.box.empty())
        throw UsageError(fmt::format(
            "the attractor of the map '{}' is covered inside a box: give --box x0:x1,y0:y1", map.name));
    const rt::AttractorCoverOptions co = cover_options(o);
    check_cover_picture(o, 2, map.name);
    const std::vector<ir::Interval> box = parse_box(o.box, 2);
    std::vector<ir::NodeId> components;
    try {
        components = front::lower_point_map(c.program, c.typed, c.sources, {}, c.module, map, 2);
    } catch (const front::CompileError& e) {
        c.diags.error(e.loc, e.what());
        std::cerr << c.diags.render(c.sources);
        return front::exit_compile_error;
    }
    std::vector<std::unique_ptr<ir::Evaluator>> evaluators;
    std::vector<ir::Evaluator*> parts;
    for (ir::NodeId n : components) {
        evaluators.push_back(make_evaluator(c.module, n, 2, engine));
        parts.push_back(evaluators.back().get());
    }
    write_cover(cover_job([&] { return rt::map_attractor_cover(parts, box, co); }), o, map.name);
    return 0;
}

namespace {

// Checks a surface's mesh, says what it is on stderr (`how`, when not empty, first), and writes it.
int report_surface_mesh(const front::AutomatonInfo& info, const rt::Mesh& mesh, const std::string& how,
                        const MeshOptions& o) {
    const rt::MeshCheck check = rt::check_mesh(mesh);
    const bool ok = check.manifold && check.oriented && check.edges > 0;
    if (!how.empty())
        std::cerr << fmt::format("{}: {}; depth {}: {} vertices\n", info.name, how, o.depth,
                                 mesh.vertices.size());
    std::cerr << fmt::format("{}: {} triangles, {} rim edges; {}, Euler characteristic {}, {} components\n",
                             info.name, mesh.triangles.size(), check.boundary_edges,
                             ok ? "manifold and oriented" : "NOT manifold: " + check.problem, check.euler,
                             check.components);
    write_mesh_file(mesh, o.output, o.force);
    return ok ? 0 : 1;
}

} // namespace

int mesh_automaton(const front::AutomatonInfo& info, const MeshOptions& o) {
    if (o.depth > 24) throw UsageError("--depth of a tessellation is at most 24");
    const ir::Automaton& a = info.automaton;
    // A triangle patch (a bcifs's triangle topology) has its own grid.
    for (const ir::TrianglePatch& patch : a.triangle_patches)
        if (patch.state == a.initial && o.layout.empty() && o.cells.empty()) {
            if (ends_with(o.output, ".svg"))
                throw UsageError(fmt::format("{} is a surface: write it as .stl, .obj or .ply", info.name));
            const rt::Mesh mesh =
                runtime_job([&] { return rt::tessellate_triangle_patch(a, patch, o.depth); });
            return report_surface_mesh(info, mesh,
                                       fmt::format("a triangle patch split {} (topology)", patch.n), o);
        }
    // A solid: volume cells (a bcifs's cube topology) and what places them.
    if (rt::reaches_volume(a) && o.layout.empty() && o.cells.empty()) {
        if (ends_with(o.output, ".svg"))
            throw UsageError(fmt::format("{} is a solid: write it as .stl, .obj or .ply", info.name));
        const rt::SolidMesh s = runtime_job([&] { return rt::tessellate_solid(a, o.depth); });
        return report_surface_mesh(
            info, s.mesh,
            fmt::format("a solid of {} blocks in {} layers, {} faces, {} inner squares "
                        "removed",
                        s.blocks, s.layers, s.faces, s.inner),
            o);
    }
    const rt::LayoutRequest request = layout_request(o);
    // An initial state that is never reached again and is no grid itself: a set of patches.
    bool set_of_patches = request.n_s == 0 && request.cells.empty();
    for (const ir::Arc& arc : a.arcs) set_of_patches = set_of_patches && arc.to != a.initial;
    rt::SurfaceLayout layout;
    try {
        layout = rt::infer_layout(a, request);
    } catch (const std::invalid_argument& e) {
        if (!set_of_patches) throw RunError(e.what());
        try {
            return mesh_patches(info, o);
        } catch (const RunError& patches) {
            throw RunError(fmt::format("{}; nor is it a set of patches: {}", e.what(), patches.what()));
        }
    }
    const rt::Tessellation t = runtime_job([&] { return rt::tessellate(a, layout, o.depth); });
    std::cerr << fmt::format("{}: {}; depth {}: {} vertices\n", info.name, layout.how, o.depth,
                             t.vertices.size());
    if (t.dimension == 1) {
        if (!ends_with(o.output, ".svg") && !ends_with(o.output, ".obj"))
            throw UsageError(
                fmt::format("{} is a curve: write it as a polyline, -o FILE.svg or FILE.obj", info.name));
        check_output_size(o.output, 40.0 * static_cast<double>(t.vertices.size()), o.force);
        runtime_job([&] {
            if (ends_with(o.output, ".svg"))
                rt::write_polyline_svg(t, o.output);
            else
                rt::write_polyline_obj(t, o.output);
            return 0;
        });
        std::cerr << fmt::format("wrote {}\n", o.output);
        return 0;
    }
    if (ends_with(o.output, ".svg"))
        throw UsageError(fmt::format("{} is a surface: write it as .stl, .obj or .ply", info.name));
    return report_surface_mesh(info, rt::surface_mesh(t), "", o);
}

int automaton_dimension(const front::AutomatonInfo& info, int from, int to) {
    const rt::SimilarityDimension d = runtime_job([&] { return rt::similarity_dimension(info.automaton); });
    if (d.defined) {
        std::cout << fmt::format("similarity dimension of {}: {:.12f} in [{:.15f}, {:.15f}] ({})\n",
                                 info.name, d.value, d.bracket.lo, d.bracket.hi, d.method);
        return 0;
    }
    // Maps that are not similitudes: box counting of the chaos-game cover.
    std::cout << fmt::format("{} has no similarity dimension: {}\n", info.name, d.reason);
    if (to > 12) throw UsageError("the chaos-game cover of an automaton goes to --to 12 at most");
    rt::ChaosOptions co;
    co.points = std::uint64_t{1} << std::min(2 * to + 4, 30);
    const rt::Cover cover = runtime_job([&] { return rt::chaos_cover(info.automaton, to, co, false); });
    const rt::DimensionEstimate e = runtime_job([&] { return rt::box_counting(cover, from, to); });
    for (const auto& [level, count] : e.counts)
        std::cout << fmt::format("level {:2}: {} boxes\n", level, count);
    std::cout << fmt::format(
        "box-counting dimension of {} (chaos game, {} points): {:.4f} (r^2 = {:.5f}, levels "
        "{}..{})\n",
        info.name, co.points, e.dimension, e.r_squared, from, to);
    return 0;
}

} // namespace frac::cli
