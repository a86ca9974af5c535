// The JIT's one-thread cover of one shape of a model: nanoseconds per evaluation, best of a number of
// covers after one compile, with pruning off and on, and what the cover evaluated (cells, series
// terms), so that two builds of the tree can be compared on the same models (run their binaries in
// turn; the covers and term counts must agree). docs/performance.md, "The JIT's term loop".
//
//   bench_shape FILE SHAPE [depth=10] [covers=5]
#include "backend/llvm/jit.hpp"
#include "driver/pipeline.hpp"
#include "ir/tape.hpp"
#include "runtime/rss.hpp"

#include <algorithm>
#include <fmt/format.h>
#include <iostream>

using namespace frac;

int main(int argc, char** argv) {
    if (argc < 3) {
        std::cerr << "usage: bench_shape FILE SHAPE [depth=10] [covers=5]\n";
        return 2;
    }
    const int depth = argc > 3 ? std::atoi(argv[3]) : 10;
    const int covers = argc > 4 ? std::max(1, std::atoi(argv[4])) : 5;
    auto c = driver::compile_file(argv[1]);
    if (!c->ok()) {
        std::cerr << c->diags.render(c->sources);
        return 1;
    }
    const front::ShapeInfo* s = c->module.find_shape(argv[2]);
    if (!s) {
        std::cerr << "no shape " << argv[2] << " in " << argv[1] << "\n";
        return 1;
    }
    const ir::Tape tape = ir::build_tape(c->module.graph, s->root, s->dimension);
    fmt::print("{} depth {}, one thread, best of {} covers\n", s->name, depth, covers);
    fmt::print("prune  ns/eval   evaluations  terms/eval  requests\n");
    for (bool prune : {false, true}) {
        ir::EvalOptions eo;
        eo.prune = prune;
        auto e = jit::make_jit(tape, eo);
        rt::RssOptions o;
        o.depth = depth;
        o.threads = 1;
        o.keep_cells = false; // the cover alone
        double best = 0;
        rt::RssResult r;
        for (int k = 0; k < covers; ++k) {
            e->stats = {};
            r = rt::subdivide(*e, s->box, o);
            if (k == 0 || r.seconds < best) best = r.seconds;
        }
        std::uint64_t requests = 0;
        for (const rt::PruneLevel& l : r.prune_levels) requests += l.requests;
        fmt::print("{:<5}  {:7.1f}  {:12}  {:10.3f}  {:8}\n", prune ? "on" : "off",
                   1e9 * best / static_cast<double>(r.evaluated), r.evaluated,
                   static_cast<double>(e->stats.series_terms) / static_cast<double>(r.evaluated), requests);
    }
}
