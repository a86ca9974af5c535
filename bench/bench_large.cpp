// Large models (bench/large_models.hpp: text strokes, buildings, blends; 1k, 3k and 7k clauses),
// covered at depth 10 on one thread, every variant in this one run:
//  - the JIT without pruning (the reference cover), then the interpreter without pruning (small
//    models only: it takes minutes on the big ones), with pruning by default (every cell with
//    children asks; the engine's rule decides) and with pruning only 5 or 3 or more levels above
//    the depth (5: the old rule; without the JIT on big models its cover is the reference);
//  - the default with the flat interpreter's boxes side by side on the scalar kernels, lane by lane
//    (the vector kernels are the default where the CPU has AVX2);
//  - the tape interpreter (the reference, instruction by instruction) with pruning, which flat tapes
//    such as these ran on before the flat interpreter;
//  - the JIT with pruning (its compile time apart and in the wall time); the JIT only up to 1000
//    clauses (LLVM takes tens of seconds there already).
// Prints per variant the nanoseconds per evaluation of the cover (wall clock and this thread's CPU
// time: the machine is shared), the compile time, the wall time (compile + cover) and whether the
// cover is the reference one; per level, for the pruned
// interpreter, the cells, the prune requests, the pruned functions made and the mean instructions
// per evaluation. Writes the models (for `frac render`) and JSON. Runs on the frac command's
// allocator (cli/allocator.hpp), as the command does.
//
//   bench_large [depth=10] [json=bench_large.json] [model_dir=.] [sizes=1000,3000,7000] [jit=1]
//               [quick|pushes]
// `quick`: the default pruned interpreter alone (no reference cover, no comparison): for profiling;
// `pushes`: the push costs alone (below; printed unless `quick`).
#include "backend/interp/flat_interpreter.hpp"
#include "backend/interp/interpreter.hpp"
#include "backend/llvm/jit.hpp"
#include "bench/bench_common.hpp"
#include "bench/large_models.hpp"
#include "cli/allocator.hpp"
#include "driver/pipeline.hpp"
#include "runtime/rss.hpp"

#include <ctime>
#include <fmt/format.h>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <thread>

using namespace frac;

namespace {

using bench::Clock;
using bench::seconds_since;

struct Variant {
    std::string name;
    bool jit = false;
    bool prune = true;
    int min_remaining = rt::default_prune_min_remaining;
    bool tape_interpreter = false; // the instruction-by-instruction interpreter, not the flat one
    bool scalar_lanes = false;     // the flat interpreter's boxes side by side on the scalar kernels
};

// CPU time of this thread: the machine is shared, and a cover on one thread is this thread's work.
double thread_cpu_s() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

struct Run {
    double compile_s = 0, cover_s = 0, cover_cpu_s = 0;
    rt::RssResult result;
    ir::SpecializeStats spec;
};

Run cover(const ir::Tape& tape, const std::vector<ir::Interval>& box, int depth, const Variant& v) {
    ir::EvalOptions eo;
    eo.prune = v.prune;
    interp::use_vector_lanes(!v.scalar_lanes);
    Run run;
    const auto t0 = Clock::now();
    auto e = v.jit                ? jit::make_jit(tape, eo)
             : v.tape_interpreter ? interp::make_tape_interpreter(tape, eo)
                                  : interp::make_interpreter(tape, eo);
    run.compile_s = seconds_since(t0);
    rt::RssOptions ro;
    ro.depth = depth;
    ro.keep_cells = true;
    ro.threads = 1;
    ro.prune_min_remaining = v.min_remaining;
    const double cpu0 = thread_cpu_s();
    run.result = rt::subdivide(*e, box, ro);
    run.cover_cpu_s = thread_cpu_s() - cpu0;
    run.cover_s = run.result.seconds;
    run.spec = e->specialize_stats;
    interp::use_vector_lanes(true);
    return run;
}

// The constants of the interpreter's push rule (backend/interp/interpreter.hpp), measured on the model's
// own tapes: descents from the root through undecided cells, each level's tape pushed from its parent's
// as a cover does; per level, the best of `repeats` timings of evaluating a cell's 4 children side by
// side and of the pushes of its undecided children (per push). Prints the push in evaluations of one box with
// the parent's tape (the rule's push_build_evaluations) and the time per instruction of both.
void push_costs(const ir::Tape& tape, const std::vector<ir::Interval>& root, int depth) {
    constexpr int descents = 12, repeats = 15;
    struct Level {
        double instructions = 0, eval_ns = 0, push_ns = 0;
        int samples = 0;
    };
    std::vector<Level> levels(static_cast<std::size_t>(depth));
    std::mt19937 rng(7);
    ir::EvalOptions eo;
    for (int descent = 0; descent < descents; ++descent) {
        std::shared_ptr<ir::Evaluator> e = interp::make_interpreter(tape, eo);
        std::vector<ir::Interval> box = root;
        for (int level = 0; level < depth; ++level) {
            std::vector<ir::Interval> children;
            for (int c = 0; c < 4; ++c) {
                const ir::Interval x = box[0], y = box[1];
                const double mx = 0.5 * (x.lo + x.hi), my = 0.5 * (y.lo + y.hi);
                children.push_back(c % 2 ? ir::Interval{mx, x.hi} : ir::Interval{x.lo, mx});
                children.push_back(c / 2 ? ir::Interval{my, y.hi} : ir::Interval{y.lo, my});
            }
            ir::Interval out[4];
            double best_eval = 1e300, best_push = 1e300;
            std::vector<int> undecided;
            std::shared_ptr<ir::Evaluator> pushed;
            for (int r = 0; r < repeats; ++r) {
                auto t0 = Clock::now();
                e->eval_boxes(children.data(), 4, out);
                best_eval = std::min(best_eval, seconds_since(t0));
                if (r == 0)
                    for (int c = 0; c < 4; ++c)
                        if (out[c].lo <= 0 && out[c].hi >= 0) undecided.push_back(c);
                if (undecided.empty()) break;
                // Every undecided child pushes, as in a cover (they share the analysis of the batch).
                const int chosen = undecided[static_cast<std::size_t>(descent) % undecided.size()];
                t0 = Clock::now();
                for (int c : undecided) {
                    auto p = e->specialize_after_eval(static_cast<std::size_t>(c), &children[2 * c], 1e12);
                    if (c == chosen) pushed = std::move(p);
                }
                best_push = std::min(best_push, seconds_since(t0) / static_cast<double>(undecided.size()));
            }
            if (undecided.empty()) break;
            Level& l = levels[static_cast<std::size_t>(level)];
            l.instructions += static_cast<double>(e->instruction_count());
            l.eval_ns += 1e9 * best_eval / 4;
            l.push_ns += 1e9 * best_push;
            ++l.samples;
            const int c = undecided[static_cast<std::size_t>(descent) % undecided.size()];
            box = {children[2 * c], children[2 * c + 1]};
            if (pushed) e = pushed;
        }
    }
    fmt::print(
        "  push costs ({} descents, best of {}; means per level):\n  {:>5} {:>12} {:>12} {:>12} {:>12} "
        "{:>12} {:>14}\n",
        descents, repeats, "level", "instructions", "eval ns/box", "ns/instr/box", "push ns", "ns/instr",
        "push in evals");
    for (std::size_t k = 0; k < levels.size(); ++k) {
        const Level& l = levels[k];
        if (l.samples == 0) continue;
        const double n = l.instructions / l.samples, eval = l.eval_ns / l.samples,
                     push = l.push_ns / l.samples;
        fmt::print("  {:>5} {:>12.0f} {:>12.0f} {:>12.2f} {:>12.0f} {:>12.2f} {:>14.1f}\n", k, n, eval,
                   eval / n, push, push / n, push / eval);
    }
}

std::vector<int> parse_sizes(const std::string& s) {
    std::vector<int> sizes;
    std::stringstream in(s);
    for (std::string item; std::getline(in, item, ',');) sizes.push_back(std::stoi(item));
    return sizes;
}

int run(int argc, char** argv) {
    const int depth = argc > 1 ? std::atoi(argv[1]) : 10;
    const std::string json_path = argc > 2 ? argv[2] : "bench_large.json";
    const std::string model_dir = argc > 3 ? argv[3] : ".";
    const std::vector<int> sizes = parse_sizes(argc > 4 ? argv[4] : "1000,3000,7000");
    const bool with_jit = argc > 5 ? std::atoi(argv[5]) != 0 : true;
    const std::string mode = argc > 6 ? argv[6] : "";
    const bool quick = mode == "quick" || mode == "pushes";
    fmt::print("allocator: {}\n", cli::allocator_in_use());
    std::string why;
    if (with_jit && !jit::jit_available(&why)) {
        std::cerr << "bench_large: the JIT is not available: " << why << "\n";
        return 1;
    }
    // The first variant is the reference cover. The interpreter without pruning takes minutes on the
    // big models (about 40 ns per instruction and box): only up to `max_unpruned_interp` clauses.
    constexpr int max_unpruned_interp = 1000;
    // LLVM compiles the whole tape for tens of seconds at 1000 clauses (superlinear): the JIT variants
    // only up to that size.
    constexpr int max_jit_clauses = 1000;
    const Variant interp_plain{"interp, no pruning", false, false};
    const Variant pruned{"interp, pruning (default)", false, true};
    const Variant pruned_late{"interp, pruning (>= 5 levels left)", false, true, 5};
    const Variant pruned_3{"interp, pruning (>= 3 levels left)", false, true, 3};
    Variant pruned_tape{"tape interpreter, pruning (default)", false, true};
    pruned_tape.tape_interpreter = true;
    Variant pruned_scalar{"interp, pruning, scalar lanes", false, true};
    pruned_scalar.scalar_lanes = true;
    std::string json = "[";
    for (int clauses : sizes) {
        const bench::LargeModel model = bench::large_model(clauses);
        const std::string path = model_dir + "/" + model.name + ".frac";
        std::ofstream(path) << model.source;
        auto t0 = Clock::now();
        auto c = driver::compile_source(path, model.source);
        const double front_s = seconds_since(t0);
        if (!c->ok()) {
            std::cerr << c->diags.render(c->sources);
            return 1;
        }
        const front::ShapeInfo& s = c->module.shapes.at(0);
        t0 = Clock::now();
        const ir::Tape tape = ir::build_tape(c->module.graph, s.root, s.dimension);
        const double tape_s = seconds_since(t0);
        fmt::print(
            "\n{} ({} clauses, {} bytes of source): frontend {:.0f} ms, tape {:.0f} ms, {} instructions\n",
            model.name, model.clauses, model.source.size(), 1e3 * front_s, 1e3 * tape_s,
            tape.instruction_count());
        if (mode != "quick") push_costs(tape, s.box, depth);
        if (mode == "pushes") continue;
        fmt::print("  {:<36} {:>10} {:>10} {:>10} {:>10} {:>10} {:>9} {:>9} {:>9}  {}\n", "variant",
                   "ns/eval", "cpu ns/ev", "compile s", "cover s", "wall s", "evals", "pruned", "functions",
                   "cover");
        std::vector<Variant> variants;
        const bool jit_here = with_jit && clauses <= max_jit_clauses && !quick;
        if (jit_here) variants.push_back({"jit, no pruning", true, false});
        if (clauses <= max_unpruned_interp && !quick) variants.push_back(interp_plain);
        // Without either, the reference is the old rule's cover (tests compare it with the unpruned one).
        const bool late_is_reference = variants.empty() && !quick;
        if (late_is_reference) variants.push_back(pruned_late);
        const std::size_t first_pruned = variants.size();
        variants.push_back(pruned);
        if (!late_is_reference && !quick) variants.push_back(pruned_late);
        if (!quick) variants.push_back(pruned_3);
        if (!quick) variants.push_back(pruned_tape);
        if (!quick) variants.push_back(pruned_scalar);
        if (jit_here) variants.push_back({"jit, pruning", true, true});
        std::vector<Run> runs;
        for (const Variant& v : variants) {
            runs.push_back(cover(tape, s.box, depth, v));
            const Run& r = runs.back();
            const bool same = rt::same_cover(runs.front().result, r.result);
            const double ns = 1e9 * r.cover_s / static_cast<double>(r.result.evaluated);
            const double cpu_ns = 1e9 * r.cover_cpu_s / static_cast<double>(r.result.evaluated);
            fmt::print("  {:<36} {:>10.0f} {:>10.0f} {:>10.3f} {:>10.3f} {:>10.3f} {:>9} {:>9} {:>9}  {}\n",
                       v.name, ns, cpu_ns, r.compile_s, r.cover_s, r.compile_s + r.cover_s,
                       r.result.evaluated, r.result.pruned_evaluations, r.result.specializations,
                       quick  ? "not compared"
                       : same ? "same"
                              : "DIFFERS");
            if (v.prune)
                fmt::print("  {:<36} requests {}, unpruned {}, too little {}, declined {}, tape pushes {}, "
                           "compiled {} "
                           "({:.1f} ms), hits {}, second tier {}; record {:.1f} ms, prune {:.1f} ms (wall)\n",
                           "", r.spec.requests, r.spec.unpruned, r.spec.too_little, r.spec.declined,
                           r.spec.pushes, r.spec.compiled, r.spec.compile_ms, r.spec.hits, r.spec.fallbacks,
                           r.spec.record_ms, r.spec.prune_ms);
            json += fmt::format(
                "{}{{\"model\": \"{}\", \"clauses\": {}, \"instructions\": {}, \"variant\": \"{}\", "
                "\"depth\": {}, \"ns_per_eval\": {:.1f}, \"cpu_ns_per_eval\": {:.1f}, \"compile_s\": {:.4f}, "
                "\"cover_s\": {:.4f}, "
                "\"evaluated\": {}, \"pruned_evaluations\": {}, \"functions\": {}, \"same\": {}}}",
                json.size() > 1 ? ", " : "", model.name, model.clauses, tape.instruction_count(), v.name,
                depth, ns, cpu_ns, r.compile_s, r.cover_s, r.result.evaluated, r.result.pruned_evaluations,
                r.result.specializations, same);
        }
        const Run& now = runs[first_pruned];
        if (!quick) {
            const Run& base = runs[first_pruned - 1];
            fmt::print("  pruned interpreter (cpu time) against {}: {:.2f}x; against pruning from 5 levels: "
                       "{:.2f}x\n",
                       variants[first_pruned - 1].name, base.cover_cpu_s / now.cover_cpu_s,
                       runs[late_is_reference ? 0 : first_pruned + 1].cover_cpu_s / now.cover_cpu_s);
            for (std::size_t k = 0; k < variants.size(); ++k)
                if (variants[k].tape_interpreter)
                    fmt::print(
                        "  flat interpreter against the tape interpreter (cpu time, both pruning): {:.2f}x\n",
                        runs[k].cover_cpu_s / now.cover_cpu_s);
                else if (variants[k].scalar_lanes)
                    fmt::print(
                        "  vector kernels against the scalar kernels (cpu time, both pruning): {:.2f}x\n",
                        runs[k].cover_cpu_s / now.cover_cpu_s);
        }
        fmt::print(
            "  per level (pruned interpreter, default):\n  {:>5} {:>9} {:>9} {:>9} {:>9} {:>12} {:>12}\n",
            "level", "evals", "undecided", "requests", "pruned", "instr/eval", "no pruning");
        for (std::size_t k = 0; k < now.result.levels.size(); ++k) {
            const rt::PruneLevel& pl = now.result.prune_levels[k];
            const double n = static_cast<double>(now.result.levels[k].evaluated);
            fmt::print("  {:>5} {:>9} {:>9} {:>9} {:>9} {:>12.1f} {:>12}\n", k,
                       now.result.levels[k].evaluated, now.result.levels[k].undecided, pl.requests, pl.pruned,
                       n > 0 ? pl.instructions / n : 0.0, tape.instruction_count());
        }
    }
    json += "]\n";
    std::ofstream(json_path) << json;
    fmt::print("\nwrote {}\n", json_path);
    return 0;
}

} // namespace

// The frac command's allocator, tuned as the command tunes it, and the work on a thread of its own as
// in the command: the main thread's heap began before the tuning (a large model's cover allocates
// hundreds of megabytes of pushed tapes; on 4 KB pages their faults were a third of the cover on a VM).
int main(int argc, char** argv) {
    cli::tune_allocator();
    int status = 1;
    std::thread work([&] { status = run(argc, argv); });
    work.join();
    return status;
}
