// frac: the command-line tool. Thin: it wires the frontend, the engines and the runtime together.
#include "cli/allocator.hpp"
#include "cli/commands.hpp"
#include "cli/fit_curve.hpp"
#include "frontend/suggest.hpp"
#include "runtime/automata/attractor_cover.hpp"
#include "runtime/automata/tree.hpp"
#include "runtime/rss.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <iostream>
#include <limits>
#include <map>
#include <oneapi/tbb/global_control.h>
#include <optional>
#include <pthread.h>

namespace {

int run(int argc, char** argv);

// The passes over syntax trees and graphs recurse along the nesting of expressions, and a model may nest
// deeply (a chain of thousands of `+` or `min` is a left-deep tree): the work runs on a thread whose stack
// is large enough for the parser's limits (address space only; pages are touched as used). AddressSanitizer
// surrounds every frame's locals with red zones, several times the frame: its builds get 8 times the stack
// (a chain of 199,999 `+` overflowed 1 GiB there).
#if defined(__SANITIZE_ADDRESS__)
constexpr std::size_t work_stack_bytes = std::size_t{8} << 30;
#else
constexpr std::size_t work_stack_bytes = std::size_t{1} << 30;
#endif

struct Work {
    int argc;
    char** argv;
    int status = 0;
};

// The work is done and its outputs written. A background compile of the "auto" engine may still be
// running (the interpreter finished first): leave without waiting for it, and without tearing LLVM
// down under it. Objects kept for the exit (cli::FreedAtExit) are freed by leaving the same way.
int finish(int status) {
    // What was printed must have reached the standard output (a full disk, a closed pipe): a run whose
    // output is lost does not succeed.
    errno = 0;
    std::cout.flush();
    if (std::fflush(stdout) != 0 || std::ferror(stdout) || !std::cout) {
        std::fprintf(stderr, "frac: error: cannot write the standard output: %s\n",
                     errno != 0 ? std::strerror(errno) : "write error");
        if (status == 0) status = 1;
    }
    if (!frac::driver::background_compile_pending() && !frac::cli::objects_kept_for_exit()) return status;
    std::cerr.flush();
    std::fflush(nullptr);
    std::_Exit(status);
}

} // namespace

int main(int argc, char** argv) {
    frac::cli::tune_allocator();            // before the work thread and its heap
    frac::driver::leave_compiles_at_exit(); // finish() below
    // Worker threads get a large stack too, whatever parallel work starts them first
    // (rt::worker_stack_bytes).
    tbb::global_control worker_stack(tbb::global_control::thread_stack_size, frac::rt::worker_stack_bytes);
    Work work{argc, argv};
    pthread_attr_t attr;
    pthread_t thread;
    const auto body = [](void* w) -> void* {
        auto* job = static_cast<Work*>(w);
        job->status = run(job->argc, job->argv);
        return nullptr;
    };
    if (pthread_attr_init(&attr) != 0 || pthread_attr_setstacksize(&attr, work_stack_bytes) != 0 ||
        pthread_create(&thread, &attr, body, &work) != 0)
        return finish(run(argc, argv)); // no large stack to be had: run on the main thread
    pthread_join(thread, nullptr);
    pthread_attr_destroy(&attr);
    return finish(work.status);
}

namespace {

// A whole number written in decimal digits that fits in 64 bits (no sign: "-1" would wrap around), of at
// least `least`; CLI11's own checks print ranges such as "0.000000 to 1.797693e+308".
CLI::Validator whole_number(std::uint64_t least) {
    return CLI::Validator(
        [least](std::string& text) -> std::string {
            const bool digits = !text.empty() && text.find_first_not_of("0123456789") == std::string::npos;
            errno = 0;
            const unsigned long long v = digits ? std::strtoull(text.c_str(), nullptr, 10) : 0;
            if (!digits || errno == ERANGE || v < least)
                return fmt::format("'{}' is not a whole number from {} to {}", text, least,
                                   std::numeric_limits<std::uint64_t>::max());
            return "";
        },
        least > 0 ? "POSITIVE" : "");
}

int run(int argc, char** argv) {
    using namespace frac;
    CLI::App app{"frac: fractal geometric modeling with guaranteed interval evaluation", "frac"};
    app.require_subcommand(1);
    app.set_version_flag("--version", fmt::format("frac {} (LLVM {})", FRAC_VERSION, FRAC_LLVM_VERSION),
                         "print the version of frac and of the LLVM it uses, then exit");
    cli::EngineOptions engine;
    engine.engine = "auto";
    // Constant overrides, NAME=VALUE, applied to the model before it is compiled.
    std::vector<std::string> sets;
    // The seed of the values of free bcifs entries: --free-seed everywhere, --seed where the command has
    // no other seed (chaos seeds its points with --seed).
    std::optional<std::uint64_t> free_entry_seed;
    auto add_set = [&](CLI::App* sub, bool seed_alias = true) {
        sub->add_option("--set", sets, "override a constant of the model: NAME=VALUE (repeatable)")
            ->type_name("NAME=VALUE")
            ->allow_extra_args(false);
        sub->add_option_function<std::uint64_t>(
               seed_alias ? "--seed,--free-seed" : "--free-seed",
               [&](const std::uint64_t& seed) { free_entry_seed = seed; },
               "give the free entries of every bcifs values drawn from this seed (reproducible) instead "
               "of the most uniform ones")
            ->check(whole_number(0))
            ->type_name("N");
    };
    auto add_engine = [&](CLI::App* sub) {
        sub->add_option("--engine", engine.engine,
                        "evaluation engine: auto (the interpreter while the JIT compiles, then the JIT), "
                        "jit (compiled first), interp, or aot (compiled as by frac compile, then loaded)")
            ->check(CLI::IsMember({"auto", "jit", "interp", "aot"}))
            ->capture_default_str();
        sub->add_option("--max-terms", engine.eval.max_terms,
                        "most terms of an infinite series before its tail bound")
            ->check(CLI::Range(1, ir::max_terms_limit))
            ->capture_default_str();
        sub->add_option("--threads", engine.threads, "subdivision threads (0: all cores)")
            ->check(CLI::Range(0, 1024))
            ->capture_default_str();
        sub->add_option("--prune", engine.eval.prune,
                        "min/max pruning per region during subdivision: on or off")
            ->transform(CLI::CheckedTransformer(std::map<std::string, bool>{{"on", true}, {"off", false}}))
            ->default_str("on");
        add_set(sub);
    };

    // The work limits of the subdividing commands (runtime/limits.hpp).
    auto add_cell_limit = [](CLI::App* sub, cli::WorkLimits& limits, const std::string& automata = "") {
        sub->add_option(
               "--max-cells", limits.cells,
               fmt::format("most cells the subdivision evaluates and keeps (default: FRAC_MAX_CELLS, "
                           "else {}){}; a run foreseen to pass it is refused",
                           rt::default_max_cells, automata))
            ->check(whole_number(1));
    };

    std::string file, shape, emit, at, box;
    auto* check = app.add_subcommand("check", "parse, check and lower a model; --emit shows a stage");
    check->add_option("file", file, "model file")->required();
    check->add_option("--emit", emit, "print what a stage produced: " + driver::stage_names());
    check->add_option("--shape", shape, "only this shape");
    bool time_passes = false;
    check->add_flag("--time-passes", time_passes, "run every stage and print the time of each on stderr");
    add_set(check);

    auto* eval = app.add_subcommand("eval", "evaluate a shape at a point or over a box");
    eval->add_option("file", file, "model file")->required();
    eval->add_option("shape", shape, "shape name")->required();
    eval->add_option("--at", at, "point x,y[,z]");
    eval->add_option("--box", box, "box x0:x1,y0:y1[,z0:z1]");
    add_engine(eval);

    cli::RenderOptions render_options;
    auto* render = app.add_subcommand(
        "render", "cover a shape by recursive subdivision and draw it (3D: a section or a shaded relief)");
    render->add_option("file", file, "model file")->required();
    render->add_option("shape", render_options.shape,
                       "shape, ifs or cifs name (default: the last shape of the file)");
    render
        ->add_option("--method", render_options.method,
                     "automata: tree (the primitives of the evaluation tree to --depth), chaos (the chaos "
                     "game's density) or cover (a cover of the attractor by cells); default: tree when a "
                     "state has a primitive, else chaos")
        ->check(CLI::IsMember({"tree", "chaos", "cover"}));
    render->add_option("--depth", render_options.depth, "subdivision depth")
        ->check(CLI::Range(0, 64))
        ->capture_default_str();
    render->add_option("--split", render_options.split, "parts per axis and level")
        ->check(CLI::Range(2, 4))
        ->capture_default_str();
    render->add_option("--box", render_options.box, "view box x0:x1,y0:y1 (default: the shape's)");
    render->add_option("-o,--output", render_options.output, "picture file, .png or .svg");
    render->add_option("--kind", render_options.kind, "process, cover or both (side by side)")
        ->check(CLI::IsMember({"process", "cover", "both"}))
        ->capture_default_str();
    render->add_option("--size", render_options.size, "pixels per panel (PNG)")
        ->check(CLI::Range(16, 8192))
        ->capture_default_str();
    render->add_option("--ascii", render_options.ascii, "also print a COLSxROWS character picture");
    render->add_flag("--force", render_options.force, "write an SVG estimated above 100 MB");
    render->add_option(
        "--slice", render_options.slice,
        "3D shapes and covers of automata in R3: draw the section by the plane AXIS=VALUE (x, y or z), "
        "e.g. z=0.5; without it a 3D shape or cover is drawn as a shaded relief seen from +z (.png)");
    add_cell_limit(render, render_options.limits,
                   fmt::format("; automata: the nodes of the tree (else {}), the cells of a level of the "
                               "cover (else {})",
                               rt::default_max_tree_nodes, rt::AttractorCoverOptions{}.max_cells));
    add_engine(render);

    cli::MeshOptions mesh_options;
    auto* mesh =
        app.add_subcommand("mesh", "cover a 3D shape by an octree and write a watertight mesh of it, or "
                                   "tessellate the patch or curve of an ifs or cifs");
    mesh->add_option("file", file, "model file")->required();
    mesh->add_option("shape", mesh_options.shape, "shape name (default: the last shape of the file)");
    mesh->add_option("--depth", mesh_options.depth, "subdivision depth")
        ->check(CLI::Range(0, 64))
        ->capture_default_str();
    mesh->add_option("--split", mesh_options.split, "parts per axis and level")
        ->check(CLI::Range(2, 4))
        ->capture_default_str();
    mesh->add_option("--box", mesh_options.box, "box x0:x1,y0:y1,z0:z1 (default: the shape's)");
    mesh->add_option("--select", mesh_options.select,
                     "inside: the proven-inside cells; cover: inside and boundary cells; boundary: the "
                     "boundary cells (a thin solid around the surface)")
        ->check(CLI::IsMember({"inside", "cover", "boundary"}))
        ->capture_default_str();
    mesh->add_option("--layout", mesh_options.layout,
                     "automata: how the initial state is cut, NxM (a quad patch) or N (a curve); default: "
                     "inferred from the operators");
    mesh->add_option("--cells", mesh_options.cells,
                     "automata: the initial state's arc labels in cell order (i * M + j), comma-separated");
    mesh->add_option("-o,--output", mesh_options.output,
                     "mesh file: .stl (binary), .obj or .ply; a curve of an automaton: .svg or .obj");
    mesh->add_flag("--force", mesh_options.force, "write a mesh estimated above 100 MB");
    add_cell_limit(mesh, mesh_options.limits);
    mesh->add_option("--max-triangles", mesh_options.limits.triangles,
                     fmt::format("most triangles of the mesh (default: FRAC_MAX_TRIANGLES, else {})",
                                 cli::default_max_triangles))
        ->check(whole_number(1));
    add_engine(mesh);

    int from = 4, to = 9, split = 2;
    auto* dimension =
        app.add_subcommand("dimension", "box-counting dimension of a shape's boundary from its cover");
    dimension->add_option("file", file, "model file")->required();
    dimension->add_option("shape", shape, "shape name (default: the last shape of the file)");
    dimension->add_option("--from", from, "first level of the fit")
        ->check(CLI::Range(0, 64))
        ->capture_default_str();
    dimension->add_option("--to", to, "last level (the subdivision depth)")
        ->check(CLI::Range(1, 64))
        ->capture_default_str();
    dimension->add_option("--split", split, "parts per axis and level")
        ->check(CLI::Range(2, 4))
        ->capture_default_str();
    cli::WorkLimits dimension_limits;
    add_cell_limit(dimension, dimension_limits);
    add_engine(dimension);

    cli::TreeOptions tree_options;
    auto* tree = app.add_subcommand("tree", "the evaluation tree of an ifs or cifs: a text dump, or drawn");
    tree->add_option("file", file, "model file")->required();
    tree->add_option("name", tree_options.name, "ifs or cifs name")->required();
    tree->add_option("--depth", tree_options.depth, "levels of the tree (0 to 24)")->capture_default_str();
    add_set(tree);
    tree->add_option("-o,--output", tree_options.output,
                     "picture file: .png or .svg (curves as polylines); without it the tree is printed");
    tree->add_option("--size", tree_options.size, "picture width and height in pixels")
        ->check(CLI::Range(16, 16384))
        ->capture_default_str();
    tree->add_flag("--force", tree_options.force, "write an SVG estimated above 100 MB");
    tree->add_option("--max-cells", tree_options.limits.cells,
                     fmt::format("most nodes of the tree (default: FRAC_MAX_CELLS, else {}); a deeper tree "
                                 "is refused before it is walked",
                                 rt::default_max_tree_nodes))
        ->check(CLI::PositiveNumber);
    bool tree_no_matrices = false;
    tree->add_flag("--no-matrices", tree_no_matrices, "print the nodes' states and addresses only");
    std::string tree_emit;
    tree->add_option("--emit", tree_emit, "tree: print the text dump (the default without -o)")
        ->check(CLI::IsMember({"tree"}));

    std::string solve_name;
    auto* solve = app.add_subcommand(
        "solve", "solve the constraints of a bcifs: its operators with exact entries and free parameters");
    solve->add_option("file", file, "model file")->required();
    solve->add_option("name", solve_name, "bcifs name (default: every bcifs of the file)");
    add_set(solve);

    cli::ChaosCommandOptions chaos_options;
    auto* chaos = app.add_subcommand("chaos", "the chaos game of an ifs or cifs, as a density picture");
    chaos->add_option("file", file, "model file")->required();
    chaos->add_option("name", chaos_options.name, "ifs or cifs name")->required();
    chaos->add_option("-n,--points", chaos_options.points, "points recorded")->capture_default_str();
    chaos->add_option("-o,--output", chaos_options.output, "picture file (.png)")->required();
    chaos->add_option("--seed", chaos_options.seed, "random seed: the same seed gives the same picture")
        ->check(whole_number(0))
        ->capture_default_str();
    chaos->add_option("--threads", chaos_options.threads, "threads (the picture depends on their number)")
        ->check(CLI::Range(1, 256))
        ->capture_default_str();
    chaos->add_option("--size", chaos_options.size, "picture width in pixels")->capture_default_str();
    add_set(chaos, false);

    std::string analyze_name;
    auto* analyze = app.add_subcommand(
        "analyze", "verified eigenvalues of the subdivision operators of a cifs: tangents, spirals, "
                   "oscillations at its vertices and junctions");
    analyze->add_option("file", file, "model file")->required();
    analyze->add_option("name", analyze_name, "ifs or cifs name")->required();
    add_set(analyze);

    std::vector<std::string> files;
    auto* test = app.add_subcommand("test", "run the test blocks of model files");
    test->add_option("files", files, "model files")->required();
    add_engine(test);
    auto* run = app.add_subcommand("run", "run a model's print statements, then its tests");
    run->add_option("file", file, "model file")->required();
    add_engine(run);

    cli::CompileOptions compile_options;
    auto* compile = app.add_subcommand(
        "compile", "compile shapes to an object file or shared library with a C ABI (docs/c-abi.md)");
    compile->add_option("file", file, "model file")->required();
    compile->add_option("shapes", compile_options.shapes, "shapes to compile (default: every shape)");
    compile->add_option("-o,--output", compile_options.output, "model.o, model.so or model.ll (LLVM IR only)")
        ->required()
        ->check(CLI::Validator(cli::check_compile_output, "FILE.o|.so|.ll", "output"));
    compile->add_option("--header", compile_options.header,
                        "also write the C header declaring the functions");
    compile->add_flag("--emit-llvm", compile_options.emit_llvm,
                      "also write the LLVM IR next to the output (.ll)");
    compile
        ->add_option("--max-terms", compile_options.max_terms,
                     "most terms of an infinite series before its tail bound (baked into the code)")
        ->check(CLI::Range(1, ir::max_terms_limit))
        ->capture_default_str();
    compile
        ->add_option("--cpu", compile_options.cpu,
                     "generic (any CPU of this architecture), native (this host) or an LLVM CPU name such as "
                     "x86-64-v3, x86-64-v4")
        ->capture_default_str();
    compile->add_option("--prefix", compile_options.prefix, "prefix of the exported C names")
        ->capture_default_str();
    add_set(compile);

    // frac fit: curves and functions (cli/fit_curve.cpp: hough, pfif, rfif) and surfaces and images
    // (cli/fit_surface.cpp: lm) share the data file, the output, the method, the quantisation, the name.
    cli::FitCurveOptions fit_curve;
    cli::FitSurfaceOptions fit_surface;
    std::string fit_data, fit_output, fit_method, fit_name;
    int fit_quantize = 0;
    auto* fit =
        app.add_subcommand("fit", "fit a fractal model to data and write it as a .frac model: a FIF "
                                  "to a curve or function, a projected IFS to a height grid or image");
    fit->add_option("data", fit_data,
                    "data: a CSV of t,x (a function) or x,y / t,x,y (a curve) rows; a CSV grid of heights, a "
                    "grey 8-bit PNG (an image) or 16-bit PNG (heights) for --method lm");
    fit->add_option("-o,--output", fit_output, "the model written (.frac); with --generate, the CSV written");
    fit->add_option("--method", fit_method,
                    "hough: the maps of a self-affine function (seed 001 sec. 3.1); pfif or rfif: a "
                    "least-squares partitioned or recurrent FIF (sec. 3.2); lm: Levenberg-Marquardt fitting "
                    "of a projected IFS quad patch (seed 003 sec. 4). Default: lm for a PNG or a CSV grid of "
                    "more than 3 "
                    "columns, else pfif")
        ->check(CLI::IsMember({"hough", "pfif", "rfif", "lm"}));
    fit->add_option("--quantize", fit_quantize,
                    "bits per stored parameter: curves 8 (default: full precision), surfaces 2 to 32 "
                    "(default 16)");
    fit->add_option("--name", fit_name,
                    "the model's name (default: the output's stem for curves, fitted "
                    "for surfaces)");
    cli::add_fit_curve_options(fit, fit_curve);
    cli::add_fit_surface_options(fit, fit_surface);

    // `frac help [COMMAND]`: the text of `frac [COMMAND] --help`.
    std::string help_topic;
    auto* help = app.add_subcommand("help", "print the help of frac or of one command");
    help->add_option("command", help_topic, "a command");

    // A first word that is neither an option nor a command is a mistyped command: suggest the nearest.
    if (argc > 1 && argv[1][0] != '-') {
        std::vector<std::string> names;
        for (const CLI::App* sub : app.get_subcommands({})) names.push_back(sub->get_name());
        if (std::find(names.begin(), names.end(), argv[1]) == names.end()) {
            const auto near = front::closest_name(argv[1], names);
            std::cerr << fmt::format("frac: error: no command '{}'{}; the commands: {}\n", argv[1],
                                     near ? fmt::format(" (did you mean '{}'?)", *near) : "",
                                     front::list_names(names));
            return front::exit_usage_error;
        }
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);
        return code == 0 ? 0 : front::exit_usage_error;
    }
    try {
        if (*help) {
            if (help_topic.empty()) {
                // app.help() would describe the selected subcommand, `help` itself.
                std::cout << app.get_formatter()->make_help(&app, app.get_name(), CLI::AppFormatMode::Normal);
                return 0;
            }
            for (const CLI::App* sub : app.get_subcommands({}))
                if (sub->get_name() == help_topic) {
                    std::cout << sub->help(app.get_name());
                    return 0;
                }
            std::vector<std::string> names;
            for (const CLI::App* sub : app.get_subcommands({})) names.push_back(sub->get_name());
            const auto near = front::closest_name(help_topic, names);
            throw cli::UsageError(fmt::format("no command '{}'{}; the commands: {}", help_topic,
                                              near ? fmt::format(" (did you mean '{}'?)", *near) : "",
                                              front::list_names(names)));
        }
        cli::set_constant_overrides(sets);
        cli::set_free_entry_seed(free_entry_seed);
        engine.max_compile_instructions = cli::compile_instruction_limit();
        engine.jit_cache_dir = cli::jit_cache_dir();
        if (*check) return cli::run_check(file, emit, shape, time_passes);
        if (*eval) return cli::run_eval(file, shape, at, box, engine);
        if (*render) return cli::run_render(file, render_options, engine);
        if (*dimension) return cli::run_dimension(file, shape, from, to, split, dimension_limits, engine);
        if (*tree) {
            tree_options.matrices = !tree_no_matrices;
            if (!tree_emit.empty() && !tree_options.output.empty())
                throw cli::UsageError("--emit=tree prints the tree; -o draws it: give one of them");
            return cli::run_tree(file, tree_options);
        }
        if (*chaos) return cli::run_chaos(file, chaos_options);
        if (*analyze) return cli::run_analyze(file, analyze_name);
        if (*solve) return cli::run_solve(file, solve_name);

        if (*mesh) return cli::run_mesh(file, mesh_options, engine);
        if (*test) return cli::run_tests(files, false, engine);
        if (*compile) return cli::run_compile(file, compile_options);
        if (*run) return cli::run_tests({file}, true, engine);
        if (*fit) {
            if (fit_method == "lm" || (fit_method.empty() && cli::is_surface_data(fit_data))) {
                if (fit_data.empty() || fit_output.empty())
                    throw cli::UsageError(
                        "frac fit DATA -o MODEL.frac --method lm: give the data and the output");
                if (fit_quantize != 0 && (fit_quantize < 2 || fit_quantize > 32))
                    throw cli::UsageError(
                        fmt::format("--quantize {}: a surface fit stores 2 to 32 bits", fit_quantize));
                fit_surface.data = fit_data;
                fit_surface.output = fit_output;
                if (fit_quantize != 0) fit_surface.bits = fit_quantize;
                if (!fit_name.empty()) fit_surface.name = fit_name;
                return cli::run_fit_surface(fit_surface);
            }
            fit_curve.file = fit_data;
            fit_curve.output = fit_output;
            if (!fit_method.empty()) fit_curve.method = fit_method;
            fit_curve.quantize = fit_quantize;
            fit_curve.name = fit_name;
            return cli::run_fit_curve(fit_curve);
        }
    } catch (const cli::UsageError& e) {
        std::cerr << "frac: error: " << e.what() << "\n";
        return front::exit_usage_error;
    } catch (const cli::RunError& e) {
        std::cerr << "frac: error: " << e.what() << "\n";
        return front::exit_runtime_error;
    } catch (const front::InternalError& e) {
        std::cerr << "frac: internal error (a bug in frac, please report it): " << e.what() << "\n";
        return front::exit_internal_error;
    } catch (const std::bad_alloc&) {
        std::cerr << "frac: error: out of memory\n";
        return front::exit_runtime_error;
    } catch (const std::exception& e) {
        std::cerr << "frac: internal error (a bug in frac, please report it): " << e.what() << "\n";
        return front::exit_internal_error;
    }
    return 0;
}

} // namespace
