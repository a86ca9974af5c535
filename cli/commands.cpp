// frac check, eval, render, dimension.
#include "cli/commands.hpp"

#include "backend/llvm/jit.hpp"
#include "runtime/dimension.hpp"
#include "runtime/legend.hpp"
#include "runtime/mesh.hpp"
#include "runtime/picture.hpp"
#include "runtime/relief.hpp"
#include "runtime/rss.hpp"
#include "runtime/slice.hpp"
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <optional>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fmt/format.h>
#include <iostream>
#include <unistd.h>

namespace frac::cli {

int run_check(const std::string& file, const std::string& emit, const std::string& shape, bool time_passes) {
    std::optional<driver::Stage> stage;
    if (!emit.empty()) {
        stage = driver::find_stage(emit);
        if (!stage)
            throw UsageError(
                fmt::format("--emit={}: no such stage (stages: {})", emit, driver::stage_names()));
    }
    driver::PassTimes times;
    driver::PassTimes* timing = time_passes ? &times : nullptr;
    // The frontend runs as far as the stage shown (all of it for the backend stages).
    auto c = compile_or_report(file, stage ? std::min(*stage, driver::Stage::lower) : driver::Stage::lower,
                               timing);
    if (!c) return front::exit_compile_error;
    const FreedAtExit keep_model(c);
    std::vector<std::string> shapes;
    if (!shape.empty()) shapes.push_back(find_shape(*c, shape).name);
    try {
        if (stage)
            std::cout << driver::emit(*c, *stage, shapes, timing);
        else if (time_passes) // every stage runs, so every stage is timed
            (void)driver::emit(*c, jit::jit_available() ? driver::Stage::codegen : driver::Stage::specialize,
                               shapes, timing);
    } catch (const std::runtime_error& e) {
        std::cerr << "frac: error: --emit=" << emit << ": " << e.what() << "\n";
        return 1;
    }
    if (time_passes) std::cerr << times.report();
    const front::Module& m = c->module;
    if (emit.empty()) {
        // The file's own shapes and tests: imported modules' are not its work (file 1 is the main file).
        const auto own = [](const auto& items) {
            return std::count_if(items.begin(), items.end(), [](const auto& i) { return i.loc.file == 1; });
        };
        const auto counted = [](std::ptrdiff_t n, const char* noun, const char* nouns = nullptr) {
            return n == 1  ? fmt::format("1 {}", noun)
                   : nouns ? fmt::format("{} {}", n, nouns)
                           : fmt::format("{} {}s", n, noun);
        };
        const auto automata = own(m.automata);
        std::cout << fmt::format("{}: ok ({}{}, {})\n", file, counted(own(m.shapes), "shape"),
                                 automata ? ", " + counted(automata, "automaton", "automata") : "",
                                 counted(own(m.tests), "test"));
    }
    return 0;
}

namespace {

// Engine options for an evaluator that only covers evaluate: they call its checkpoints, so "auto" may
// tier every tape (backend/llvm/tiered.hpp).
EngineOptions for_covers(EngineOptions engine) {
    engine.checkpoints = true;
    return engine;
}

} // namespace

int run_eval(const std::string& file, const std::string& shape, const std::string& at, const std::string& box,
             const EngineOptions& engine) {
    auto c = compile_or_report(file);
    if (!c) return front::exit_compile_error;
    const FreedAtExit keep_model(c);
    const front::ShapeInfo& s = find_shape(*c, shape);
    auto eval = make_evaluator(c->module, s.root, s.dimension, engine);
    if (at.empty() && box.empty()) throw UsageError("give --at x,y or --box x0:x1,y0:y1");
    int status = 0;
    if (!at.empty()) {
        std::vector<ir::Interval> enclosure;
        const std::vector<double> p = parse_point(at, s.dimension, &enclosure);
        const double value = eval->eval_point(p.data());
        const ir::Interval proven = eval->eval_box(enclosure.data());
        // NaN prints as "nan" whatever its sign bit.
        std::cout << fmt::format("{} = {}\nenclosure {}\n", s.name,
                                 std::isnan(value) ? std::string("nan") : fmt::format("{}", value),
                                 format_interval(proven));
        // NaN or an empty enclosure: the function is undefined there (sqrt or log of a negative number...),
        // which a caller testing the sign of the value must not miss.
        if (std::isnan(value) || proven.is_empty()) {
            std::cerr << fmt::format("frac: warning: '{}' is undefined at ({}): {}\n", s.name, at,
                                     proven.is_empty() ? "its enclosure is empty" : "its value is NaN");
            status = 1;
        }
    }
    if (!box.empty()) {
        const auto b = parse_box(box, s.dimension);
        const ir::Interval proven = eval->eval_box(b.data());
        std::cout << fmt::format("enclosure over the box {}\n", format_interval(proven));
        if (proven.is_empty()) {
            std::cerr << fmt::format(
                "frac: warning: '{}' is undefined over the box {}: its enclosure is empty\n", s.name, box);
            status = 1;
        }
    }
    return status;
}

std::uint64_t limit_of(std::uint64_t flag, const char* env, std::uint64_t fallback) {
    if (flag > 0) return flag;
    if (const auto v = positive_env(env, "cells or triangles"))
        return static_cast<std::uint64_t>(std::min(*v, 1e19));
    return fallback;
}

RunError cell_limit_error(const std::exception& e) {
    return RunError(fmt::format(
        "{}: lower --depth, or raise the limit with --max-cells N (or FRAC_MAX_CELLS=N)", e.what()));
}

namespace {

rt::RssProgress terminal_progress(std::shared_ptr<bool> printed) {
    if (!isatty(STDERR_FILENO)) return {};
    // Quiet for the first second: short runs print nothing but their summary.
    const auto start = std::chrono::steady_clock::now();
    return [start, printed](int level, std::uint64_t evaluated) {
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (s < 1.0) return;
        *printed = true;
        std::cerr << fmt::format("\rlevel {:2}: {} boxes evaluated, {:.3g} million a second", level,
                                 evaluated, static_cast<double>(evaluated) / s / 1e6)
                  << std::flush;
    };
}

rt::RssResult cover(const std::vector<ir::Interval>& box, int depth, int split, bool keep_cells, int threads,
                    ir::Evaluator& eval, const WorkLimits& limits, bool closed_inside = false) {
    rt::RssOptions ro;
    ro.max_cells = limit_of(limits.cells, "FRAC_MAX_CELLS", rt::default_max_cells);
    ro.closed_inside = closed_inside;
    ro.threads = threads;
    ro.depth = depth;
    if (const auto d = positive_env("FRAC_MAX_DEPTH", "levels")) {
        if (*d > 32) throw UsageError("FRAC_MAX_DEPTH must be at most 32 (cell positions are 32-bit)");
        ro.max_depth = static_cast<int>(std::ceil(*d));
    }
    ro.split = split;
    ro.keep_cells = keep_cells;
    auto printed = std::make_shared<bool>(false);
    ro.progress = terminal_progress(printed);
    try {
        rt::RssResult r = rt::subdivide(eval, box, ro);
        if (*printed) std::cerr << "\n"; // end the progress line
        return r;
    } catch (const rt::LimitError& e) {
        if (*printed) std::cerr << "\n";
        throw cell_limit_error(e);
    } catch (const std::invalid_argument& e) {
        throw RunError(e.what());
    }
}

} // namespace

namespace {

// The size limit of outputs: output_size_limit, or FRAC_OUTPUT_LIMIT_MB when set to a positive number.
double output_limit() {
    if (const auto mb = positive_env("FRAC_OUTPUT_LIMIT_MB", "megabytes")) return *mb * 1e6;
    return output_size_limit;
}

} // namespace

void check_output_size(const std::string& path, double bytes, bool force) {
    const double limit = output_limit();
    if (bytes <= limit || force) return;
    throw RunError(fmt::format("'{}' would be about {:.0f} MB (the limit is {:g} MB, FRAC_OUTPUT_LIMIT_MB): "
                               "lower --depth, or pass --force to write it anyway",
                               path, bytes / 1e6, limit / 1e6));
}

SliceRequest parse_slice(const std::string& text) {
    SliceRequest request;
    if (text.empty()) return request;
    const auto eq = text.find('=');
    const std::string axis = text.substr(0, eq);
    request.axis = axis == "x" ? 0 : axis == "y" ? 1 : axis == "z" ? 2 : -1;
    if (eq == std::string::npos || request.axis < 0)
        throw UsageError(fmt::format("--slice needs AXIS=VALUE such as z=0.5, not '{}'", text));
    // A constant expression, as in --at (z=1/3 is the plane nearest to 1/3).
    request.value = evaluate_constant(text.substr(eq + 1), "--slice: the value").point;
    return request;
}

void check_slice_within(const SliceRequest& plane, const std::vector<ir::Interval>& box,
                        const std::string& text) {
    const ir::Interval axis = box[static_cast<std::size_t>(plane.axis)];
    if (!(plane.value >= axis.lo && plane.value <= axis.hi))
        throw UsageError(
            fmt::format("--slice {}: the value lies outside the box [{}, {}]", text, axis.lo, axis.hi));
}

rt::Cover section_of(const rt::Cover& r, const SliceRequest& plane, const std::string& text) {
    check_slice_within(plane, r.root, text);
    return rt::slice(r, plane.value, plane.axis);
}

void write_cover_svg(const rt::Cover& r, const std::string& path, rt::PictureKind kind, bool force) {
    // About 48 bytes a rectangle (measured): the cover's inside and boundary leaves, the process's cells.
    const double cells = static_cast<double>(r.inside + r.boundary) +
                         (kind == rt::PictureKind::cover ? 0.0 : static_cast<double>(r.evaluated));
    check_output_size(path, 48 * cells, force);
    rt::write_svg(r, path, kind);
}

int run_render(const std::string& file, const RenderOptions& o, const EngineOptions& engine) {
    if (o.output.empty() && o.ascii.empty())
        throw UsageError("render needs -o FILE.png|FILE.svg or --ascii COLSxROWS");
    rt::PictureKind kind = rt::PictureKind::both;
    if (o.kind == "process")
        kind = rt::PictureKind::process;
    else if (o.kind == "cover")
        kind = rt::PictureKind::cover;
    else if (o.kind != "both")
        throw UsageError(fmt::format("unknown picture kind '{}' (process, cover, both)", o.kind));
    if (!o.output.empty() && !ends_with(o.output, ".png") && !ends_with(o.output, ".svg"))
        throw UsageError(fmt::format("cannot tell the picture format of '{}': use .png or .svg", o.output));
    int cols = 0, rows = 0;
    if (!o.ascii.empty() && (std::sscanf(o.ascii.c_str(), "%dx%d", &cols, &rows) != 2 || cols < 1 ||
                             rows < 1 || cols > 1000 || rows > 1000))
        throw UsageError(
            fmt::format("--ascii needs COLSxROWS such as 64x32 (1 to 1000 each), not '{}'", o.ascii));
    if (o.size < 16 || o.size > 8192) throw UsageError("--size must be between 16 and 8192 pixels");
    if (!o.output.empty()) check_output_writable(o.output, {file});
    auto c = compile_or_report(file);
    if (!c) return front::exit_compile_error;
    const FreedAtExit keep_model(c);
    if (const front::AutomatonInfo* a = c->module.find_automaton(o.shape))
        return on_automaton(*c, *a, [&] { return render_automaton(*a, o); });
    for (const front::Item& it : c->program.items)
        if (it.kind == front::ItemKind::fn && it.name == o.shape && !o.shape.empty())
            return render_map(*c, it, o, engine);
    if (!o.method.empty())
        throw UsageError("--method is for automata (ifs, cifs); shapes are drawn from their cover");
    const front::ShapeInfo& s = pick_shape(*c, o.shape);
    // A 3D shape is drawn as a plane section (--slice) or as a shaded relief of its cover from above.
    const SliceRequest plane = parse_slice(o.slice);
    const int slice_axis = plane.axis;
    if (slice_axis >= 0 && s.dimension != 3)
        throw UsageError(fmt::format("--slice is for 3D shapes; '{}' is 2D", s.name));
    if (s.dimension == 3 && slice_axis < 0 && (!o.ascii.empty() || ends_with(o.output, ".svg")))
        throw UsageError(fmt::format("shape '{}' is 3D: draw a section with --slice z=VALUE, or a relief "
                                     "(shaded depth image) as .png",
                                     s.name));
    auto eval = make_evaluator(c->module, s.root, s.dimension, for_covers(engine));
    const auto box = o.box.empty() ? s.box : parse_box(o.box, s.dimension);
    if (slice_axis >= 0) check_slice_within(plane, box, o.slice); // before the cover, which may take long
    rt::RssResult full = cover(box, o.depth, o.split, true, engine.threads, *eval, o.limits);
    const FreedAtExit keep_cover(full);
    eval.reset(); // no more evaluation: a background compile not started yet is dropped
    std::cerr << fmt::format(
        "{}: depth {}, {} boxes evaluated: {} inside, {} outside, {} boundary; {:.3f} s\n", s.name, o.depth,
        full.evaluated, full.inside, full.outside, full.boundary, full.seconds);
    if (s.dimension == 3 && slice_axis < 0) {
        try {
            rt::write_png(rt::relief_image(full, o.size), o.output);
        } catch (const std::runtime_error& e) {
            throw RunError(e.what());
        }
        std::cerr << fmt::format("wrote {} (relief seen from +z)\n", o.output);
        return 0;
    }
    rt::Cover section;
    if (slice_axis >= 0) section = section_of(full, plane, o.slice);
    const rt::Cover& r = slice_axis >= 0 ? section : static_cast<const rt::Cover&>(full);
    if (!o.ascii.empty()) std::cout << rt::ascii_picture(r, cols, rows);
    if (!o.output.empty()) {
        try {
            if (ends_with(o.output, ".png")) {
                rt::write_png(rt::with_legend(rt::render(r, kind, o.size), kind), o.output);
            } else {
                write_cover_svg(r, o.output, kind, o.force);
            }
        } catch (const std::runtime_error& e) {
            throw RunError(e.what());
        }
        std::cerr << fmt::format("wrote {}\n", o.output);
    }
    return 0;
}

int run_dimension(const std::string& file, const std::string& shape, int from, int to, int split,
                  const WorkLimits& limits, const EngineOptions& engine) {
    auto c = compile_or_report(file);
    if (!c) return front::exit_compile_error;
    const FreedAtExit keep_model(c);
    if (const front::AutomatonInfo* a = c->module.find_automaton(shape))
        return on_automaton(*c, *a, [&] { return automaton_dimension(*a, from, to); });
    const front::ShapeInfo& s = pick_shape(*c, shape);
    auto eval = make_evaluator(c->module, s.root, s.dimension, for_covers(engine));
    const rt::RssResult r = cover(s.box, to, split, false, engine.threads, *eval, limits);
    rt::DimensionEstimate d;
    try {
        d = rt::box_counting(r, from, to);
    } catch (const std::invalid_argument& e) {
        throw RunError(e.what());
    }
    for (const auto& [level, count] : d.counts)
        std::cout << fmt::format("level {:2}: {} boxes\n", level, count);
    std::cout << fmt::format("box-counting dimension of {}: {:.4f} (r^2 = {:.5f}, levels {}..{}, split {})\n",
                             s.name, d.dimension, d.r_squared, from, to, split);
    return 0;
}

int run_mesh(const std::string& file, const MeshOptions& o, const EngineOptions& engine) {
    if (o.output.empty()) throw UsageError("mesh needs -o FILE.stl|FILE.obj|FILE.ply");
    if (!ends_with(o.output, ".stl") && !ends_with(o.output, ".obj") && !ends_with(o.output, ".ply") &&
        !ends_with(o.output, ".svg"))
        throw UsageError(fmt::format(
            "cannot tell the mesh format of '{}': use .stl, .obj or .ply (.svg for curves)", o.output));
    rt::MeshSelection selection = rt::MeshSelection::inside;
    if (o.select == "cover")
        selection = rt::MeshSelection::inside_and_boundary;
    else if (o.select == "boundary")
        selection = rt::MeshSelection::boundary;
    else if (o.select != "inside")
        throw UsageError(fmt::format("unknown selection '{}': use inside, cover or boundary", o.select));
    check_output_writable(o.output, {file});
    auto c = compile_or_report(file);
    if (!c) return front::exit_compile_error;
    const FreedAtExit keep_model(c);
    if (const front::AutomatonInfo* a = c->module.find_automaton(o.shape))
        return on_automaton(*c, *a, [&] { return mesh_automaton(*a, o); });
    if (!o.layout.empty() || !o.cells.empty())
        throw UsageError("--layout and --cells cut the initial state of an automaton; a shape is meshed from "
                         "its cover");
    if (ends_with(o.output, ".svg"))
        throw UsageError("a shape is meshed as .stl, .obj or .ply; .svg is for the curves of automata");
    const front::ShapeInfo& s = pick_shape(*c, o.shape);
    if (s.dimension != 3)
        throw UsageError(fmt::format("shape '{}' is {}D; meshes are of 3D shapes (frac render draws 2D ones)",
                                     s.name, s.dimension));
    auto eval = make_evaluator(c->module, s.root, s.dimension, for_covers(engine));
    const auto box = o.box.empty() ? s.box : parse_box(o.box, s.dimension);
    // A mesh is of the closed solid {f <= 0}: cells whose faces lie on its surface are inside.
    rt::RssResult r = cover(box, o.depth, o.split, true, engine.threads, *eval, o.limits, true);
    const FreedAtExit keep_cover(r);
    rt::Mesh mesh;
    try {
        mesh = rt::mesh_cover(r, selection,
                              limit_of(o.limits.triangles, "FRAC_MAX_TRIANGLES", default_max_triangles));
    } catch (const rt::LimitError& e) {
        throw RunError(fmt::format("{}: lower --depth, or raise the limit with --max-triangles N (or "
                                   "FRAC_MAX_TRIANGLES=N)",
                                   e.what()));
    }
    if (mesh.stats.cells == 0) {
        // Nothing to print: say why rather than write an empty file.
        std::string hint;
        if (selection == rt::MeshSelection::inside && r.boundary > 0)
            hint = fmt::format(
                "no cell is proven inside, {} are on the boundary. A shape without interior (a limit set, "
                "a surface) has none: mesh its boundary cover as a thin solid with --select boundary. A "
                "solid whose faces fall between doubles (j/27 is not a double) is never proven inside: "
                "write it in lattice units, as the stdlib's menger3 on [0, 9]^3",
                r.boundary);
        else
            hint = "the shape does not meet the box (every cell is outside): check its sign and --box";
        throw RunError(
            fmt::format("{}: depth {} split {}: nothing to mesh; {}", s.name, o.depth, o.split, hint));
    }
    const rt::MeshCheck check = rt::check_mesh(mesh);
    std::cerr << fmt::format("{}: depth {} split {}: {} cells ({} inside, {} boundary), {} triangles; {}, "
                             "Euler characteristic {}, {} components\n",
                             s.name, o.depth, o.split, mesh.stats.cells, r.inside, r.boundary,
                             mesh.triangles.size(),
                             check.ok() ? "watertight and manifold" : "NOT printable: " + check.problem,
                             check.euler, check.components);
    write_mesh_file(mesh, o.output, o.force);
    return check.ok() ? 0 : 1;
}

void write_mesh_file(const rt::Mesh& mesh, const std::string& path, bool force) {
    // Binary STL takes 50 bytes a triangle; OBJ and PLY text about as much with the vertices.
    check_output_size(path,
                      50.0 * static_cast<double>(mesh.triangles.size()) +
                          40.0 * static_cast<double>(mesh.vertices.size()),
                      force);
    try {
        rt::write_mesh(mesh, path);
    } catch (const std::exception& e) {
        throw RunError(e.what());
    }
    std::cerr << fmt::format("wrote {}\n", path);
}

} // namespace frac::cli
