// The JIT's inline interval kernels (sqrt, sin, cos, exp, tan, log, atan2: backend/llvm/box_kernels.cpp)
// against the calls into the numeric core they replace (FRAC_JIT_EXACT_CALLS=1 at compile time) and against
// the interpreter, every variant in this one run, repetitions interleaved, medians:
//  1. octree covers (one thread) of the scenes of bench/kernel_scenes.frac: a gyroid sheet in a ball
//     (sin, cos, sqrt) and spheres and boxes in CSG (sqrt); the covers of the variants compared cell by cell;
//  2. each kernel alone on random intervals: nanoseconds per evaluation, and the width of its enclosure
//     against the correctly rounded range of the numeric core (median and worst ratio).
//
//   bench_kernels [depth=8] [reps=5]
#include "backend/interp/interpreter.hpp"
#include "backend/llvm/jit.hpp"
#include "bench/bench_common.hpp"
#include "driver/pipeline.hpp"
#include "ir/graph.hpp"
#include "ir/tape.hpp"
#include "runtime/rss.hpp"

#include <algorithm>
#include <cstdlib>
#include <fmt/format.h>
#include <iostream>
#include <memory>
#include <random>

using namespace frac;

namespace {

using bench::Clock;
using bench::seconds_since;
using bench::Shape;

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

// The JIT with the inline kernels, or with the numeric core's calls in their place.
std::unique_ptr<ir::Evaluator> make_jit(const ir::Tape& t, bool exact_calls) {
    if (exact_calls) setenv("FRAC_JIT_EXACT_CALLS", "1", 1);
    auto e = jit::make_jit(t);
    unsetenv("FRAC_JIT_EXACT_CALLS");
    return e;
}

struct Variant {
    const char* name;
    std::unique_ptr<ir::Evaluator> e;
    std::vector<double> seconds;
    rt::RssResult cover;
};

std::vector<Variant> variants(const ir::Tape& t) {
    std::vector<Variant> v;
    v.push_back({"interpreter", interp::make_interpreter(t), {}, {}});
    v.push_back({"jit, core calls", make_jit(t, true), {}, {}});
    v.push_back({"jit, inline kernels", make_jit(t, false), {}, {}});
    return v;
}

void covers(const Shape& s, int depth, int reps) {
    auto vs = variants(s.tape);
    rt::RssOptions o;
    o.depth = depth;
    o.threads = 1;
    for (Variant& v : vs) v.cover = rt::subdivide(*v.e, s.box, o); // the cells, for the comparison
    o.keep_cells = false;
    for (int r = 0; r < reps; ++r)
        for (std::size_t k = 0; k < vs.size(); ++k) {
            Variant& v = vs[(k + static_cast<std::size_t>(r)) % vs.size()]; // rotate the order
            v.seconds.push_back(rt::subdivide(*v.e, s.box, o).seconds);
        }
    fmt::print("\n{} (octree depth {}, one thread, median of {})\n", s.name, depth, reps);
    fmt::print("{:<22} {:>9} {:>11} {:>10} {:>9} {:>10} {:>10}  {}\n", "engine", "ms", "ns/eval", "evaluated",
               "boundary", "vs interp", "vs calls", "cover");
    const double interp_s = median(vs[0].seconds), calls_s = median(vs[1].seconds);
    for (const Variant& v : vs) {
        const double sec = median(v.seconds);
        const char* same = rt::same_cover(v.cover, vs[1].cover)       ? "= core calls"
                           : v.cover.boundary <= vs[1].cover.boundary ? "tighter"
                                                                      : "LOOSER";
        fmt::print("{:<22} {:>9.1f} {:>11.1f} {:>10} {:>9} {:>9.2f}x {:>9.2f}x  {}\n", v.name, 1e3 * sec,
                   1e9 * sec / double(v.cover.evaluated), v.cover.evaluated, v.cover.boundary, interp_s / sec,
                   calls_s / sec, same);
    }
}

// Random intervals with widths like an octree's cells (2^-12 .. 2^0) around points in [-8, 8] (positive:
// in (0, 16], each interval then positive).
std::vector<ir::Interval> cell_like(std::size_t n, std::uint64_t seed, bool positive) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<ir::Interval> v(n);
    for (auto& x : v) {
        const double w = std::ldexp(1.0, -static_cast<int>(rng() % 13));
        const double c = positive ? 16 * u(rng) + w : 16 * u(rng) - 8;
        x = {c - w / 2, c + w / 2};
    }
    return v;
}

// `arity` 2: boxes of two such intervals (atan2's (y, x)).
void kernel(const char* name, ir::Op op, int reps, bool positive = false, int arity = 1) {
    ir::Graph g;
    const ir::Tape t = arity == 2 ? ir::build_tape(g, g.op(op, g.var(0), g.var(1)), 2)
                                  : ir::build_tape(g, g.op(op, g.var(0)), 1);
    const std::size_t count = 1 << 20, chunk = 4096;
    const std::vector<ir::Interval> in = cell_like(count * static_cast<std::size_t>(arity), 42, positive);
    auto vs = variants(t);
    std::vector<std::vector<ir::Interval>> out(vs.size(), std::vector<ir::Interval>(count));
    for (int r = 0; r < reps; ++r)
        for (std::size_t k = 0; k < vs.size(); ++k) {
            const auto t0 = Clock::now();
            for (std::size_t i = 0; i < count; i += chunk)
                vs[k].e->eval_boxes(in.data() + i * static_cast<std::size_t>(arity),
                                    std::min(chunk, count - i), out[k].data() + i);
            vs[k].seconds.push_back(seconds_since(t0));
        }
    // Tightness: width against the numeric core's correctly rounded enclosure of the exact range.
    std::vector<double> ratio;
    bool contains = true;
    for (std::size_t i = 0; i < count; ++i) {
        const ir::Interval exact = out[0][i], fast = out[2][i];
        contains = contains && fast.contains(exact);
        const double width = exact.hi - exact.lo; // finite and positive (tan over a pole is all of R)
        if (width > 0 && std::isfinite(width)) ratio.push_back((fast.hi - fast.lo) / width);
    }
    std::sort(ratio.begin(), ratio.end());
    const double n = double(count);
    fmt::print("{:<5} {:>10.2f} {:>10.2f} {:>10.2f} {:>9.2f}x {:>9.2f}x   {:.12f} {:.12f}  {}\n", name,
               1e9 * median(vs[0].seconds) / n, 1e9 * median(vs[1].seconds) / n,
               1e9 * median(vs[2].seconds) / n, median(vs[0].seconds) / median(vs[2].seconds),
               median(vs[1].seconds) / median(vs[2].seconds), ratio[ratio.size() / 2], ratio.back(),
               contains ? "contains" : "MISSES the core's range");
}

} // namespace

int main(int argc, char** argv) {
    const int depth = argc > 1 ? std::atoi(argv[1]) : 8;
    const int reps = argc > 2 ? std::atoi(argv[2]) : 5;
    std::string why;
    if (!jit::jit_available(&why)) {
        std::cerr << "bench_kernels: the JIT is not available: " << why << "\n";
        return 1;
    }
    auto c = driver::compile_file(std::string(FRAC_SOURCE_DIR) + "/bench/kernel_scenes.frac");
    if (!c->ok()) {
        std::cerr << c->diags.render(c->sources);
        return 1;
    }
    fmt::print("Interval kernels: inline (vector) against the numeric core's calls; AVX-512: {}\n",
               jit::host_has_avx512() ? "yes" : "no");
    for (const front::ShapeInfo& s : c->module.shapes)
        covers({s.name, s.dimension, s.box, ir::build_tape(c->module.graph, s.root, s.dimension)}, depth,
               reps);

    fmt::print(
        "\nEach kernel on 2^20 random intervals of widths 2^-12 .. 1 in [-8, 8] (log: in (0, 16]; ns per "
        "evaluation, median of {}; atan2: boxes of two);\nwidth / width of the correctly rounded range: "
        "median and worst\n",
        reps);
    fmt::print("{:<5} {:>10} {:>10} {:>10} {:>10} {:>10}   {:<14} {:<14}\n", "op", "interp", "calls",
               "inline", "vs interp", "vs calls", "median ratio", "worst ratio");
    kernel("sqrt", ir::Op::Sqrt, reps);
    kernel("sin", ir::Op::Sin, reps);
    kernel("cos", ir::Op::Cos, reps);
    kernel("exp", ir::Op::Exp, reps);
    kernel("tan", ir::Op::Tan, reps);
    kernel("log", ir::Op::Log, reps, true);
    kernel("atan2", ir::Op::Atan2, reps, false, 2);
    return 0;
}
