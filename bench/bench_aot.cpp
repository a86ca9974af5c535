// Compiled models (frac compile, docs/c-abi.md) against the JIT, measured in this one run: the cost
// per evaluated box of the carpet's cells for the JIT (host code), a model compiled with --cpu=native
// and one compiled with --cpu=generic (portable), with every result checked bit for bit against the
// JIT. Prints a table of ratios and writes JSON.
//
//   bench_aot FRAC_BINARY [level=9] [json=bench_aot.json] [work_dir=.]
#include "backend/llvm/jit.hpp"
#include "driver/pipeline.hpp"
#include "ir/tape.hpp"

#include <bit>
#include <chrono>
#include <cstdlib>
#include <dlfcn.h>
#include <fmt/format.h>
#include <fstream>
#include <functional>
#include <iostream>

using namespace frac;

namespace {

using Clock = std::chrono::steady_clock;
using Boxes = void (*)(const ir::Interval*, std::size_t, ir::Interval*);

bool same(ir::Interval a, ir::Interval b) {
    return std::bit_cast<std::uint64_t>(a.lo) == std::bit_cast<std::uint64_t>(b.lo) &&
           std::bit_cast<std::uint64_t>(a.hi) == std::bit_cast<std::uint64_t>(b.hi);
}

} // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::cerr << "usage: bench_aot FRAC_BINARY [level=9] [json=bench_aot.json] [work_dir=.]\n";
        return 64;
    }
    const std::string frac_binary = argv[1];
    const int level = argc > 2 ? std::atoi(argv[2]) : 9;
    const std::string json_path = argc > 3 ? argv[3] : "bench_aot.json";
    const std::string work = argc > 4 ? argv[4] : ".";
    const std::string model = work + "/bench_aot_carpet.frac";
    std::ofstream(model) << "import \"fractals\";\n";

    auto c = driver::compile_file(model);
    if (!c->ok()) {
        std::cerr << c->diags.render(c->sources);
        return 1;
    }
    const front::ShapeInfo* carpet = c->module.find_shape("carpet");
    const ir::Tape tape = ir::build_tape(c->module.graph, carpet->root, carpet->dimension);

    // Every cell of the carpet's grid at `level`.
    const std::size_t side = std::size_t{1} << level;
    std::vector<ir::Interval> boxes;
    for (std::size_t i = 0; i < side; ++i)
        for (std::size_t j = 0; j < side; ++j) {
            boxes.push_back({double(i) / side, double(i + 1) / side});
            boxes.push_back({double(j) / side, double(j + 1) / side});
        }
    const std::size_t n = side * side;
    const int reps = 9;

    // The variants: the JIT, then the same shape compiled for each CPU this host can run.
    struct Variant {
        std::string name;
        std::function<void(const ir::Interval*, std::size_t, ir::Interval*)> eval;
        double seconds = 1e300;
        std::size_t mismatches = 0;
    };
    auto jit = jit::make_jit(tape);
    std::vector<Variant> variants;
    variants.push_back(
        {"JIT (" + jit::compile_info(*jit)->rounding + ")",
         [&](const ir::Interval* b, std::size_t k, ir::Interval* o) { jit->eval_boxes(b, k, o); }});
    std::vector<std::string> cpus = {"native"};
    if (__builtin_cpu_supports("avx512f")) cpus.push_back("x86-64-v4"); // what this host can run
    if (__builtin_cpu_supports("avx2")) cpus.push_back("x86-64-v3");
    if (__builtin_cpu_supports("sse4.2")) cpus.push_back("x86-64-v2");
    cpus.push_back("generic");
    for (const std::string& cpu : cpus) {
        const std::string so = fmt::format("{}/bench_aot_carpet_{}.so", work, cpu);
        const std::string cmd =
            fmt::format("{} compile {} carpet --cpu={} -o {} 2>/dev/null", frac_binary, model, cpu, so);
        if (std::system(cmd.c_str()) != 0) {
            std::cerr << "bench_aot: failed: " << cmd << "\n";
            return 1;
        }
        void* lib = dlopen(so.c_str(), RTLD_NOW | RTLD_LOCAL);
        if (!lib) {
            std::cerr << "bench_aot: " << dlerror() << "\n";
            return 1;
        }
        variants.push_back(
            {"compiled --cpu=" + cpu, reinterpret_cast<Boxes>(dlsym(lib, "frac_carpet_eval_boxes"))});
    }

    // Round robin, best of `reps` each: every variant sees the same disturbances of the shared machine.
    std::vector<ir::Interval> reference, out(n);
    for (int r = 0; r < reps; ++r)
        for (Variant& v : variants) {
            const auto t0 = Clock::now();
            for (std::size_t i = 0; i < n; i += 4096)
                v.eval(boxes.data() + 2 * i, std::min<std::size_t>(4096, n - i), out.data() + i);
            v.seconds = std::min(v.seconds, std::chrono::duration<double>(Clock::now() - t0).count());
            if (reference.empty()) reference = out;
            for (std::size_t i = 0; i < n && r == 0; ++i) v.mismatches += !same(out[i], reference[i]);
        }
    const double jit_s = variants[0].seconds;
    struct Row {
        std::string variant;
        double seconds;
        std::size_t mismatches;
    };
    std::vector<Row> rows;
    for (const Variant& v : variants) rows.push_back({v.name, v.seconds, v.mismatches});

    std::cout << fmt::format("carpet cells at level {} ({} boxes), batches of 4096, best of {}:\n", level, n,
                             reps);
    std::cout << fmt::format("{:<28} {:>12} {:>12} {:>14}\n", "variant", "ns per box", "JIT = 1",
                             "not JIT's bits");
    std::string json = fmt::format("{{\n  \"level\": {}, \"boxes\": {},\n  \"variants\": [\n", level, n);
    for (std::size_t k = 0; k < rows.size(); ++k) {
        const Row& r = rows[k];
        std::cout << fmt::format("{:<28} {:>12.1f} {:>12.2f} {:>14}\n", r.variant, 1e9 * r.seconds / n,
                                 r.seconds / jit_s, r.mismatches);
        json += fmt::format("    {{\"variant\": \"{}\", \"ns_per_box\": {:.2f}, \"ratio_to_jit\": {:.3f}, "
                            "\"mismatches\": {}}}{}\n",
                            r.variant, 1e9 * r.seconds / n, r.seconds / jit_s, r.mismatches,
                            k + 1 < rows.size() ? "," : "");
    }
    json += "  ]\n}\n";
    std::ofstream(json_path) << json;
    std::cout << "wrote " << json_path << "\n";
    for (const Row& r : rows)
        if (r.mismatches) return 1;
    return 0;
}
