// Min/max pruning per region and adaptive series truncation, every variant measured in this one run:
//  1. the constants of the pruning rule (ir/specialize.hpp): evaluation time per unit of tape cost,
//     and the JIT's compile time of pruned tapes against their size (least squares); the fixed part
//     of an evaluation in a cover (the JIT's without pruning, the interpreter's with it);
//  2. RSS covers of CSG shapes with pruning off and on, with both engines: time, cells evaluated
//     with a pruned function, cache hits, compiles and the time they took, and whether the covers
//     are identical (they must be);
//  3. adaptive series truncation on and off with both engines.
// Prints tables of ratios and writes JSON.
//
//   bench_prune [depth=10] [json=bench_prune.json] [depth_3d=7]
#include "backend/interp/flat_interpreter.hpp"
#include "backend/interp/interpreter.hpp"
#include "backend/llvm/jit.hpp"
#include "bench/bench_common.hpp"
#include "bench/large_models.hpp"
#include "driver/pipeline.hpp"
#include "ir/specialize.hpp"
#include "ir/tape.hpp"
#include "runtime/rss.hpp"

#include <algorithm>
#include <chrono>
#include <fmt/format.h>
#include <fstream>
#include <iostream>
#include <random>
#include <set>

using namespace frac;

namespace {

using bench::Clock;
using bench::seconds_since;
using bench::Shape;

// The named shape of a model file (relative to the source tree) or of a stdlib module.
// A shape of a file of the tree (is_file), of a library module, or of the model text `source`.
enum class From { file, module, text };
Shape load(const std::string& source, const std::string& name, From from) {
    auto c = from == From::file     ? driver::compile_file(std::string(FRAC_SOURCE_DIR) + "/" + source)
             : from == From::module ? driver::compile_source("bench.frac", "import \"" + source + "\";")
                                    : driver::compile_source("bench.frac", source);
    if (!c->ok()) {
        std::cerr << c->diags.render(c->sources);
        std::exit(1);
    }
    for (const front::ShapeInfo& s : c->module.shapes)
        if (s.name == name)
            return {s.name, s.dimension, s.box, ir::build_tape(c->module.graph, s.root, s.dimension)};
    std::cerr << "bench_prune: no shape " << name << " in " << source << "\n";
    std::exit(1);
}

using Make = std::unique_ptr<ir::Evaluator> (*)(const ir::Tape&, const ir::EvalOptions&);
std::unique_ptr<ir::Evaluator> make_interp(const ir::Tape& t, const ir::EvalOptions& o) {
    return interp::make_interpreter(t, o);
}
std::unique_ptr<ir::Evaluator> make_jit(const ir::Tape& t, const ir::EvalOptions& o) {
    return jit::make_jit(t, o);
}

struct Run {
    rt::RssResult result;
    ir::EvalStats stats;
    ir::SpecializeStats spec;
    double seconds = 1e300; // best of the repetitions (each with a fresh evaluator: compiles count)
    double compile_s = 0;   // compiling the shape itself (JIT), not counted in `seconds`
};

void cover_once(Make make, const Shape& s, int depth, const ir::EvalOptions& o, Run& run) {
    const auto t0 = Clock::now();
    auto e = make(s.tape, o);
    run.compile_s = seconds_since(t0);
    rt::RssOptions ro;
    ro.depth = depth;
    rt::RssResult res = rt::subdivide(*e, s.box, ro);
    if (res.seconds < run.seconds) {
        run.seconds = res.seconds;
        run.stats = e->stats;
        run.spec = e->specialize_stats;
        run.result = std::move(res);
    }
}

// Two variants, repetitions interleaved (the machine is shared: a disturbance then hits both alike
// instead of one of them); the best of each.
std::pair<Run, Run> cover_pair(Make make, const Shape& s, int depth, const ir::EvalOptions& a,
                               const ir::EvalOptions& b, int reps) {
    std::pair<Run, Run> runs;
    Run warm_up; // the first cover of a process pays for growing the heap
    cover_once(make, s, std::max(0, depth - 2), a, warm_up);
    for (int r = 0; r < reps; ++r) {
        // Alternate which goes first, so that neither always follows the other.
        if (r % 2 == 0) cover_once(make, s, depth, a, runs.first);
        cover_once(make, s, depth, b, runs.second);
        if (r % 2 == 1) cover_once(make, s, depth, a, runs.first);
    }
    return runs;
}

// Boxes of the cells of a cover (every level), for timing evaluations.
std::vector<ir::Interval> cell_boxes(const rt::RssResult& r) {
    std::vector<ir::Interval> boxes;
    for (const rt::Cell& c : r.cells)
        for (int a = 0; a < r.dimension(); ++a) boxes.push_back(r.cell_interval(c, a));
    return boxes;
}

// Nanoseconds per box to evaluate `boxes` (batches of 4096), best of `reps`.
double ns_per_box(ir::Evaluator& e, const std::vector<ir::Interval>& boxes, int reps) {
    const auto d = static_cast<std::size_t>(e.dimension());
    const std::size_t n = boxes.size() / d;
    std::vector<ir::Interval> out(n);
    double best = 1e300;
    for (int r = 0; r < reps; ++r) {
        const auto t0 = Clock::now();
        for (std::size_t i = 0; i < n; i += 4096)
            e.eval_boxes(boxes.data() + d * i, std::min<std::size_t>(4096, n - i), out.data() + i);
        best = std::min(best, seconds_since(t0));
    }
    return 1e9 * best / double(n);
}

// Least squares y = a + b x.
std::pair<double, double> fit(const std::vector<double>& x, const std::vector<double>& y) {
    const double n = double(x.size());
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        sx += x[i];
        sy += y[i];
        sxx += x[i] * x[i];
        sxy += x[i] * y[i];
    }
    const double b = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    return {(sy - b * sx) / n, b};
}

// Distinct pruned tapes of a shape (at most `count`), from the choices recorded over sub-boxes of its
// cover's cells at `depth`, and those cells' boxes.
struct PrunedSet {
    std::vector<ir::Tape> tapes;
    std::vector<ir::Interval> boxes;
};
PrunedSet pruned_tapes(const Shape& shape, int depth, std::size_t count) {
    PrunedSet set;
    auto e = interp::make_interpreter(shape.tape);
    rt::RssOptions ro;
    ro.depth = depth;
    const rt::RssResult r = rt::subdivide(*e, shape.box, ro);
    set.boxes = cell_boxes(r);
    const auto d = static_cast<std::size_t>(shape.dimension);
    interp::ChoiceRecorder rec(shape.tape, {});
    std::set<std::string> seen;
    for (std::size_t i = 0; d * (i + 1) <= set.boxes.size() && set.tapes.size() < count; i += 37) {
        const auto choices = rec.record(&set.boxes[d * i]);
        if (!ir::any_decided(choices)) continue;
        ir::Tape t = ir::specialize(shape.tape, choices);
        if (seen.insert(ir::tape_key(t)).second) set.tapes.push_back(std::move(t));
    }
    return set;
}

} // namespace

int main(int argc, char** argv) {
    const int depth = argc > 1 ? std::atoi(argv[1]) : 10;
    const std::string json_path = argc > 2 ? argv[2] : "bench_prune.json";
    const int depth_3d = argc > 3 ? std::atoi(argv[3]) : 7;
    std::string why;
    if (!jit::jit_available(&why)) {
        std::cerr << "bench_prune: the JIT is not available: " << why << "\n";
        return 1;
    }
    std::vector<Shape> shapes = {
        load("bench/csg_scene.frac", "csg_scene", From::file),
        load("koch", "double_koch", From::module),
        load("examples/menger_frame.frac", "sponge_in_frame", From::file),
        load("fractals", "carpet", From::module), // no min/max outside its series: nothing to prune
        // a short tape: the JIT's evaluation is mostly its fixed part, its pruning cannot pay
        load("bench/kernel_scenes.frac", "sphere_box_csg", From::file),
    };
    const Shape& scene = shapes[0];
    std::string json = "{\n";

    // ---- 1. The rule's constants ----
    // Pruned tapes of the scene (its carpet's series run on the tape interpreter) and of a generated
    // 300-clause model (flat: the flat interpreter runs them), from choices recorded over sub-boxes
    // of their covers' cells.
    const PrunedSet scene_set = pruned_tapes(scene, 6, 24);
    const Shape flat_model = load(bench::large_model(300).source, bench::large_model(300).name, From::text);
    const PrunedSet flat_set = pruned_tapes(flat_model, 6, 24);
    const std::vector<ir::Tape>& pruned = scene_set.tapes;
    const std::vector<ir::Interval>& scene_boxes = scene_set.boxes;
    // Compile time of the JIT against the pruned tape's size (best of 3 per tape).
    std::vector<double> sizes, compile_ms, costs, jit_ns, interp_ns, tape_interp_ns;
    for (const ir::Tape& t : pruned) {
        double best = 1e300;
        for (int r = 0; r < 3; ++r) best = std::min(best, jit::compile_info(*jit::make_jit(t))->total_ms);
        sizes.push_back(double(t.instruction_count()));
        compile_ms.push_back(best);
    }
    const auto [compile_fixed, compile_per_instr] = fit(sizes, compile_ms);
    // The interpreter's "compile" of the same tapes: a copy and a register file.
    double interp_make_us = 0;
    for (const ir::Tape& t : pruned) {
        double best = 1e300;
        for (int r = 0; r < 3; ++r) {
            const auto t0 = Clock::now();
            auto e = interp::make_interpreter(t);
            best = std::min(best, 1e6 * seconds_since(t0));
        }
        interp_make_us += best / double(pruned.size());
    }
    // Evaluation time per unit of tape cost: the full and the pruned tapes over the same boxes, by the
    // JIT and the tape interpreter (the scene's), and by the flat interpreter (the flat model's).
    std::vector<ir::Tape> timed = pruned;
    timed.push_back(scene.tape);
    for (const ir::Tape& t : timed) {
        costs.push_back(ir::tape_cost(t));
        jit_ns.push_back(ns_per_box(*jit::make_jit(t), scene_boxes, 3));
        interp_ns.push_back(ns_per_box(*interp::make_interpreter(t), scene_boxes, 1));
        tape_interp_ns.push_back(ns_per_box(*interp::make_tape_interpreter(t), scene_boxes, 1));
    }
    std::vector<ir::Tape> flat_timed = flat_set.tapes;
    flat_timed.push_back(flat_model.tape);
    std::vector<double> flat_costs, flat_ns, flat_tape_ns;
    for (const ir::Tape& t : flat_timed) {
        if (!interp::runs_flat(t)) continue;
        flat_costs.push_back(ir::tape_cost(t));
        flat_ns.push_back(ns_per_box(*interp::make_interpreter(t), flat_set.boxes, 3));
        flat_tape_ns.push_back(ns_per_box(*interp::make_tape_interpreter(t), flat_set.boxes, 1));
    }
    const auto [jit_ns0, jit_ns_per_cost] = fit(costs, jit_ns);
    const auto [tape_interp_ns0, tape_interp_ns_per_cost] = fit(costs, tape_interp_ns);
    const auto [flat_ns0, flat_ns_per_cost] = fit(flat_costs, flat_ns);
    const auto [flat_tape_ns0, flat_tape_ns_per_cost] = fit(flat_costs, flat_tape_ns);
    fmt::print(
        "Pruning rule constants ({} pruned tapes of csg_scene, {} instructions unpruned, cost {:.0f};\n"
        "{} flat tapes of {}: pruned, and unpruned with {} instructions, cost {:.0f})\n",
        pruned.size(), scene.tape.instruction_count(), ir::tape_cost(scene.tape), flat_costs.size(),
        flat_model.name, flat_model.tape.instruction_count(), ir::tape_cost(flat_model.tape));
    fmt::print(
        "  JIT compile:      {:.2f} ms + {:.4f} ms per instruction   (in use: {:.2f} ms + {:.4f} ms)\n",
        compile_fixed, compile_per_instr, jit::jit_prune_costs.compile_ns_fixed * 1e-6,
        jit::jit_prune_costs.compile_ns_per_instruction * 1e-6);
    fmt::print("  interpreter make: {:.1f} us on average   (in use: {:.1f} us)\n", interp_make_us,
               interp::interp_prune_costs.compile_ns_fixed * 1e-3);
    fmt::print("  JIT eval:         {:.1f} ns + {:.3f} ns per cost unit, per box   (in use: {:.3f})\n",
               jit_ns0, jit_ns_per_cost, jit::jit_prune_costs.eval_ns_per_cost);
    fmt::print("  tape interpreter: {:.1f} ns + {:.3f} ns per cost unit, per box   (in use: {:.3f})\n",
               tape_interp_ns0, tape_interp_ns_per_cost, interp::tape_eval_ns_per_cost);
    fmt::print("  flat interpreter: {:.1f} ns + {:.3f} ns per cost unit, per box   (in use: {:.3f}; the tape "
               "interpreter on the same tapes: {:.1f} ns + {:.3f})\n",
               flat_ns0, flat_ns_per_cost, interp::flat_eval_ns_per_cost, flat_tape_ns0,
               flat_tape_ns_per_cost);
    fmt::print("  {:>8} {:>8} {:>11} {:>10} {:>12} {:>12}\n", "instrs", "cost", "compile ms", "jit ns/box",
               "interp ns/box", "tape ns/box");
    for (std::size_t i = 0; i < timed.size(); ++i)
        fmt::print("  {:>8} {:>8.0f} {:>11} {:>10.1f} {:>12.1f} {:>12.1f}{}\n", timed[i].instruction_count(),
                   costs[i], i < compile_ms.size() ? fmt::format("{:.2f}", compile_ms[i]) : "-", jit_ns[i],
                   interp_ns[i], tape_interp_ns[i], i + 1 == timed.size() ? "  (unpruned)" : "");
    fmt::print("  {:>8} {:>12} {:>12}   ({})\n", "cost", "flat ns/box", "tape ns/box", flat_model.name);
    for (std::size_t i = 0; i < flat_costs.size(); ++i)
        fmt::print("  {:>8.0f} {:>12.1f} {:>12.1f}\n", flat_costs[i], flat_ns[i], flat_tape_ns[i]);
    json +=
        fmt::format("  \"rule\": {{\"pruned_tapes\": {}, \"jit_compile_ms_fixed\": {:.4f}, "
                    "\"jit_compile_ms_per_instruction\": {:.6f}, \"interp_make_us\": {:.3f}, "
                    "\"jit_eval_ns_fixed\": {:.3f}, \"jit_eval_ns_per_cost\": {:.5f}, "
                    "\"tape_interp_eval_ns_fixed\": {:.3f}, \"tape_interp_eval_ns_per_cost\": {:.5f}, "
                    "\"flat_interp_eval_ns_fixed\": {:.3f}, \"flat_interp_eval_ns_per_cost\": {:.5f}}},\n",
                    pruned.size(), compile_fixed, compile_per_instr, interp_make_us, jit_ns0, jit_ns_per_cost,
                    tape_interp_ns0, tape_interp_ns_per_cost, flat_ns0, flat_ns_per_cost);

    // ---- 1b. The fixed part of an evaluation in a cover ----
    // What a cover pays per evaluation apart from the tape's instructions: the JIT's on its whole tape
    // (no pruning; the generated code builds and classifies the cells), the interpreter's with
    // pruning (a parent's few children per call, boxes built by the cover, tape pushes below): the
    // cover's time per evaluation less the per-cost time of part 1 times its mean cost (flat tapes:
    // cost = instructions). In the constants' unit they are jit_prune_costs.eval_ns_fixed and
    // interp::cover_eval_ns_fixed, which decide whether a short pruned tape is worth running on the
    // interpreter, and whether the JIT records choices at all.
    const double unit = jit::jit_prune_costs.eval_ns_per_cost / jit_ns_per_cost; // ns -> constants' unit
    fmt::print("\nFixed part of an evaluation in a cover (one thread; constants' unit: ns x {:.2f})\n", unit);
    fmt::print("  {:<16} {:>5} {:>6} {:>9} {:>10} {:>10} {:>12} {:>10} {:>10} {:>12}\n", "shape", "depth",
               "cost", "boxes", "jit ns/ev", "jit fixed", "(in unit)", "interp ns", "mean cost",
               "interp fixed");
    const Shape kernel_csg = load("bench/kernel_scenes.frac", "sphere_box_csg", From::file);
    const Shape flat_100 = load(bench::large_model(100).source, bench::large_model(100).name, From::text);
    std::vector<double> jit_fixed_units, interp_fixed_units;
    json += "  \"cover_fixed\": [\n";
    for (const Shape* s : {&kernel_csg, &flat_100, &flat_model}) {
        const int d = s->dimension == 2 ? 9 : depth_3d;
        ir::EvalOptions off, on;
        off.prune = false;
        Run jit_run, interp_run;
        for (int r = 0; r < 3; ++r) {
            cover_once(make_jit, *s, d, off, jit_run);
            cover_once(make_interp, *s, d, on, interp_run);
        }
        const double n = double(jit_run.result.evaluated);
        double instructions = 0;
        for (const rt::PruneLevel& pl : interp_run.result.prune_levels) instructions += pl.instructions;
        const double mean_cost = instructions / double(interp_run.result.evaluated);
        const double jit_ns = 1e9 * jit_run.seconds / n;
        const double interp_ns = 1e9 * interp_run.seconds / double(interp_run.result.evaluated);
        const double jit_fixed = jit_ns - jit_ns_per_cost * ir::tape_cost(s->tape);
        const double interp_fixed = interp_ns - flat_ns_per_cost * mean_cost;
        jit_fixed_units.push_back(unit * jit_fixed);
        interp_fixed_units.push_back(unit * interp_fixed);
        fmt::print("  {:<16} {:>5} {:>6.0f} {:>9} {:>10.1f} {:>10.1f} {:>12.0f} {:>10.1f} {:>10.1f} {:>6.1f} "
                   "({:.0f})\n",
                   s->name, d, ir::tape_cost(s->tape), jit_run.result.evaluated, jit_ns, jit_fixed,
                   unit * jit_fixed, interp_ns, mean_cost, interp_fixed, unit * interp_fixed);
        json += fmt::format("{}    {{\"shape\": \"{}\", \"depth\": {}, \"cost\": {:.1f}, \"jit_ns\": {:.3f}, "
                            "\"jit_fixed_ns\": {:.3f}, \"interp_pruned_ns\": {:.3f}, \"mean_cost\": {:.3f}, "
                            "\"interp_fixed_ns\": {:.3f}, \"unit\": {:.4f}}}",
                            s == &kernel_csg ? "" : ",\n", s->name, d, ir::tape_cost(s->tape), jit_ns,
                            jit_fixed, interp_ns, mean_cost, interp_fixed, unit);
    }
    json += "\n  ],\n";
    // The JIT's fixed part shows on the short tape (on long ones it is lost in the error of the slope);
    // the interpreter's is the least over the shapes.
    fmt::print(
        "  fixed part, constants' unit: JIT on the short tape {:.0f} (in use {:.0f}), interpreter at least "
        "{:.0f} (in use {:.0f})\n",
        jit_fixed_units.front(), jit::jit_prune_costs.eval_ns_fixed,
        *std::min_element(interp_fixed_units.begin(), interp_fixed_units.end()), interp::cover_eval_ns_fixed);

    // ---- 2. Covers with pruning off and on ----
    fmt::print(
        "\nRSS covers with pruning off and on (one thread; best of runs, each with a fresh evaluator)\n");
    fmt::print("{:<16} {:<6} {:>5} {:>9} {:>8} {:>8} {:>7} {:>8} {:>6} {:>5} {:>5} {:>5} {:>8} {:>8} {:>5}\n",
               "shape", "engine", "depth", "boxes", "off s", "on s", "off/on", "pruned%", "funcs", "hits",
               "comp", "tier2", "comp ms", "rec ms", "same");
    json += "  \"covers\": [\n";
    bool first_row = true;
    // Every shape with both engines, and the scene two levels deeper with the JIT, whose compiles
    // pay only for many boxes.
    struct Job {
        const Shape* shape;
        const char* name;
        Make make;
        int depth;
    };
    std::vector<Job> jobs;
    for (const Shape& s : shapes)
        for (auto [name, make] : {std::pair<const char*, Make>{"jit", make_jit}, {"interp", make_interp}})
            jobs.push_back({&s, name, make, s.dimension == 2 ? depth : depth_3d});
    jobs.insert(jobs.begin() + 2, Job{&scene, "jit", make_jit, depth + 2});
    for (const Job& job : jobs) {
        const Shape& s = *job.shape;
        const int d = job.depth;
        const char* name = job.name;
        const Make make = job.make;
        {
            ir::EvalOptions off, on;
            off.prune = false;
            const int reps = std::string(name) == "jit" ? 3 : 2;
            const auto [a, b] = cover_pair(make, s, d, off, on, reps);
            const bool same = rt::same_cover(a.result, b.result);
            const double pruned_share =
                100.0 * double(b.result.pruned_evaluations) / double(b.result.evaluated);
            fmt::print("{:<16} {:<6} {:>5} {:>9} {:>8.3f} {:>8.3f} {:>6.2f}x {:>7.1f}% {:>6} {:>5} {:>5} "
                       "{:>5} {:>8.1f} "
                       "{:>8.1f} {:>5}\n",
                       s.name, name, d, b.result.evaluated, a.seconds, b.seconds, a.seconds / b.seconds,
                       pruned_share, b.result.specializations, b.spec.hits, b.spec.compiled, b.spec.fallbacks,
                       b.spec.compile_ms, b.spec.record_ms, same ? "yes" : "DIFFERS");
            json += fmt::format(
                "{}    {{\"shape\": \"{}\", \"engine\": \"{}\", \"depth\": {}, \"boxes\": {}, "
                "\"off_seconds\": {:.6f}, \"on_seconds\": {:.6f}, \"speedup\": {:.4f}, "
                "\"pruned_evaluations\": {}, \"functions\": {}, \"requests\": {}, \"unpruned\": {}, "
                "\"too_little\": {}, \"declined\": {}, \"hits\": {}, \"compiled\": {}, \"fallbacks\": {}, "
                "\"compile_ms\": {:.3f}, \"record_ms\": {:.3f}, \"series_terms_off\": {}, "
                "\"series_terms_on\": {}, \"same_cover\": {}}}",
                first_row ? "" : ",\n", s.name, name, d, b.result.evaluated, a.seconds, b.seconds,
                a.seconds / b.seconds, b.result.pruned_evaluations, b.result.specializations, b.spec.requests,
                b.spec.unpruned, b.spec.too_little, b.spec.declined, b.spec.hits, b.spec.compiled,
                b.spec.fallbacks, b.spec.compile_ms, b.spec.record_ms, a.stats.series_terms,
                b.stats.series_terms, same ? "true" : "false");
            first_row = false;
        }
    }
    json += "\n  ],\n";

    // ---- 3. Adaptive series truncation ----
    fmt::print("\nAdaptive series truncation off and on (pruning off; one thread)\n");
    fmt::print("{:<16} {:<6} {:>5} {:>10} {:>10} {:>9} {:>9} {:>10} {:>10} {:>12}\n", "shape", "engine",
               "depth", "fixed s", "adapt s", "fixed/ad", "terms/box", "terms/box", "boundary", "boundary");
    fmt::print("{:<16} {:<6} {:>5} {:>10} {:>10} {:>9} {:>9} {:>10} {:>10} {:>12}\n", "", "", "", "", "", "",
               "fixed", "adaptive", "fixed", "adaptive");
    json += "  \"adaptive_terms\": [\n";
    first_row = true;
    for (const Shape* s : {&shapes[3], &shapes[0]}) {
        for (auto [name, make] : {std::pair<const char*, Make>{"jit", make_jit}, {"interp", make_interp}}) {
            ir::EvalOptions fixed, adaptive;
            fixed.adaptive_terms = adaptive.prune = fixed.prune = false;
            const int reps = std::string(name) == "jit" ? 3 : 1;
            const auto [f, a] = cover_pair(make, *s, depth, fixed, adaptive, reps);
            const double tf = double(f.stats.series_terms) / double(f.result.evaluated);
            const double ta = double(a.stats.series_terms) / double(a.result.evaluated);
            fmt::print("{:<16} {:<6} {:>5} {:>10.3f} {:>10.3f} {:>8.2f}x {:>9.2f} {:>10.2f} {:>10} {:>12}\n",
                       s->name, name, depth, f.seconds, a.seconds, f.seconds / a.seconds, tf, ta,
                       f.result.boundary, a.result.boundary);
            json += fmt::format(
                "{}    {{\"shape\": \"{}\", \"engine\": \"{}\", \"depth\": {}, \"fixed_seconds\": {:.6f}, "
                "\"adaptive_seconds\": {:.6f}, \"speedup\": {:.4f}, \"terms_per_box_fixed\": {:.3f}, "
                "\"terms_per_box_adaptive\": {:.3f}, \"boundary_fixed\": {}, \"boundary_adaptive\": {}}}",
                first_row ? "" : ",\n", s->name, name, depth, f.seconds, a.seconds, f.seconds / a.seconds, tf,
                ta, f.result.boundary, a.result.boundary);
            first_row = false;
        }
    }
    json += "\n  ]\n}\n";
    std::ofstream(json_path) << json;
    fmt::print("wrote {}\n", json_path);
    return 0;
}
