// RSS covers of the standard library's shapes: boxes per second, and the effect of adaptive series
// truncation, each variant measured in the same run. Prints a table of ratios and writes JSON.
#include "backend/interp/interpreter.hpp"
#include "driver/pipeline.hpp"
#include "ir/tape.hpp"
#include "runtime/rss.hpp"

#include <chrono>
#include <fmt/format.h>
#include <fstream>
#include <iostream>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

using namespace frac;

namespace {

struct Row {
    std::string shape, variant;
    int depth;
    std::uint64_t boxes, terms;
    double seconds;
};

Row measure(const front::Module& m, const front::ShapeInfo& s, int depth, const ir::EvalOptions& options,
            const std::string& variant) {
    auto eval = interp::make_interpreter(ir::build_tape(m.graph, s.root, s.dimension), options);
    rt::RssOptions ro;
    ro.depth = depth;
    ro.keep_cells = false;
    // Best of three runs: the machine is shared.
    double best = 1e300;
    rt::RssResult r;
    for (int rep = 0; rep < 3; ++rep) {
        eval->stats = {};
        r = rt::subdivide(*eval, s.box, ro);
        best = std::min(best, r.seconds);
    }
    return {s.name, variant, depth, r.evaluated, eval->stats.series_terms, best};
}

} // namespace

int main(int argc, char** argv) {
    const int depth = argc > 1 ? std::atoi(argv[1]) : 10;
    const std::string json_path = argc > 2 ? argv[2] : "bench_rss.json";
    auto c = driver::compile_source("bench.frac", "import \"fractals\";");
    if (!c->ok()) {
        std::cerr << c->diags.render(c->sources);
        return 1;
    }
    std::vector<Row> rows;
    fmt::print("{:<18} {:>6} {:>10} {:>12} {:>12} {:>10} {:>14}\n", "shape", "depth", "boxes", "boxes/s",
               "terms/box", "seconds", "fixed/adaptive");
    for (const front::ShapeInfo& s : c->module.shapes) {
        ir::EvalOptions adaptive, fixed;
        fixed.adaptive_terms = false;
        const Row a = measure(c->module, s, depth, adaptive, "adaptive");
        const Row f = measure(c->module, s, depth, fixed, "fixed");
        rows.push_back(a);
        rows.push_back(f);
        fmt::print("{:<18} {:>6} {:>10} {:>12.0f} {:>12.1f} {:>10.3f} {:>13.2f}x\n", s.name, depth, a.boxes,
                   a.boxes / a.seconds, double(a.terms) / double(a.boxes), a.seconds, f.seconds / a.seconds);
    }
    // Parallel subdivision: the same cover with 1 and 2 threads, and the memory peak of deep covers,
    // each measured in a child process so that peaks do not mix.
    auto c3 = driver::compile_source("bench3.frac", "import \"solids\";");
    struct Deep {
        const front::Module* module;
        const char* shape;
        int depth;
    };
    const Deep deep[] = {{&c->module, "carpet", 12}, {&c3->module, "menger_holes", 8}};
    fmt::print("\n{:<14} {:>6} {:>12} {:>12} {:>10} {:>14}\n", "shape", "depth", "1 thread s", "2 threads s",
               "speed-up", "peak RSS MiB");
    for (const Deep& dp : deep) {
        const front::ShapeInfo& s = *dp.module->find_shape(dp.shape);
        double secs[2] = {0, 0};
        long peak_kib = 0;
        for (int t = 1; t <= 2; ++t) {
            int pipe_fd[2];
            if (pipe(pipe_fd) != 0) return 1;
            const pid_t pid = fork();
            if (pid == 0) {
                auto eval = interp::make_interpreter(ir::build_tape(dp.module->graph, s.root, s.dimension));
                rt::RssOptions ro;
                ro.depth = dp.depth;
                ro.keep_cells = false;
                ro.threads = t;
                const double sec = rt::subdivide(*eval, s.box, ro).seconds;
                if (write(pipe_fd[1], &sec, sizeof sec) != sizeof sec) _exit(1);
                _exit(0);
            }
            double sec = 0;
            if (read(pipe_fd[0], &sec, sizeof sec) != sizeof sec) return 1;
            close(pipe_fd[0]);
            close(pipe_fd[1]);
            int status = 0;
            rusage usage{};
            wait4(pid, &status, 0, &usage);
            secs[t - 1] = sec;
            if (t == 1) peak_kib = usage.ru_maxrss;
        }
        fmt::print("{:<14} {:>6} {:>12.3f} {:>12.3f} {:>9.2f}x {:>14.1f}\n", dp.shape, dp.depth, secs[0],
                   secs[1], secs[0] / secs[1], peak_kib / 1024.0);
        rows.push_back({std::string(dp.shape) + " (1 thread)", "parallel", dp.depth, 0, 0, secs[0]});
        rows.push_back({std::string(dp.shape) + " (2 threads)", "parallel", dp.depth, 0, 0, secs[1]});
    }

    std::ofstream json(json_path);
    json << "[\n";
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const Row& r = rows[i];
        json << fmt::format(
            "  {{\"shape\": \"{}\", \"variant\": \"{}\", \"engine\": \"interp\", \"depth\": {}, "
            "\"boxes\": {}, \"series_terms\": {}, \"seconds\": {}, \"boxes_per_second\": {}}}{}\n",
            r.shape, r.variant, r.depth, r.boxes, r.terms, r.seconds, r.boxes / r.seconds,
            i + 1 < rows.size() ? "," : "");
    }
    json << "]\n";
    fmt::print("wrote {}\n", json_path);
    return 0;
}
