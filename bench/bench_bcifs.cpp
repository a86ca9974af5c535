// Solving BCIFS constraints: the systems the topology declarations generate, from an edge to a volume
// cell, each compiled (parse, topology, solve, values of the free entries, contraction proof) the way
// every frac command compiles a model. Two variants of each in one run: exact (all entries rational:
// Gauss-Jordan over Q) and in floating point (one fixed entry inexact: the same elimination on doubles
// with the tolerance, plus the QR rank check), with the ratio. Median of R runs each, interleaved.
//
// Usage: bench_bcifs [runs, default 3]
#include "bench_common.hpp"
#include "driver/pipeline.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

using namespace frac;
using bench::Clock;
using bench::seconds_since;

namespace {

struct Model {
    std::string name, cells, topology, fix; // `fix`: one entry, exact; the inexact variant uses sqrt
};

// The model text; `inexact`: the fixed entry written as sqrt(2)^2 / 8 (1/4, but not exact for the compiler).
std::string text(const Model& m, bool inexact) {
    return fmt::format("bcifs {} {{\n{}\n{}\nfix {} = {};\n}}\n", m.name, m.cells, m.topology, m.fix,
                       inexact ? "sqrt(2)^2 / 8" : "1/4");
}

struct Run {
    double seconds = 0;
    std::string sizes; // the solver's first line: unknowns, equations, rank, free
};

Run compile(const std::string& source, const std::string& name) {
    const auto t0 = Clock::now();
    const auto c = driver::compile_source("bench.frac", source);
    Run r;
    r.seconds = seconds_since(t0);
    if (!c->ok()) {
        std::cerr << c->diags.render(c->sources);
        std::exit(1);
    }
    const std::string& solution = c->module.find_automaton(name)->solution;
    r.sizes = solution.substr(0, solution.find('\n'));
    return r;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

} // namespace

int main(int argc, char** argv) {
    const int runs = argc > 1 ? std::max(1, std::atoi(argv[1])) : 3;
    const std::string points3 = "project = controls((0, 0, 0), (1, 0, 1), (2, 0, 0), (0, 1, 1), (1, 1, 2), "
                                "(2, 1, 1), (0, 2, 0), (1, 2, 1), (2, 2, 0));";
    const std::vector<Model> models = {
        {"edge", "cell v in bary(1); cell e in bary(3); project = controls((0, 0), (1, 1), (2, 0));",
         "topology e = edge(v) split 2;", "e.T0[1][1]"},
        {"quad", "cell v in bary(1); cell e in bary(3); cell f in bary(9); " + points3,
         "topology e = edge(v) split 2; topology f = quad(e) split 2 x 2;", "f.T0[4][4]"},
        {"triangle3",
         "cell v in bary(1); cell e in bary(3); cell t in bary(6); project = controls((0, 0, 0), (1, 0, 1), "
         "(2, 0, 0), (0, 1, 1), (1, 1, 1), (0, 2, 0));",
         "topology e = edge(v) split 3; topology t = triangle(e) split 3;", "t.T0[4][4]"},
        {"quad4",
         "cell v in bary(1); cell e in bary(4); cell f in bary(16); project = controls(" +
             [] {
                 std::string p;
                 for (int r = 0; r < 4; ++r)
                     for (int c = 0; c < 4; ++c)
                         p += fmt::format("{}({}, {}, {})", p.empty() ? "" : ", ", c, r, (r * c) % 3);
                 return p;
             }() +
             ");",
         "topology e = edge(v) split 3; topology f = quad(e) split 3 x 3;", "f.T0[5][5]"},
        {"cube",
         "cell v in bary(1); cell e in bary(3); cell f in bary(9); cell c in bary(27); initial f; " + points3,
         "topology e = edge(v) split 2; topology f = quad(e) split 2 x 2; topology c = cube(f) split 2 x 2 x "
         "2;",
         "c.T0[13][13]"},
    };
    std::cout << fmt::format(
        "BCIFS solve (compile of the model: topology, solve, values, contraction proof), "
        "median of {} runs\n",
        runs);
    std::cout << fmt::format("{:<10} {:>10} {:>10} {:>8}  {}\n", "system", "exact s", "float s", "float/ex",
                             "size (exact)");
    for (const Model& m : models) {
        std::vector<double> exact, floating;
        std::string sizes;
        for (int r = 0; r < runs; ++r) {
            // Alternate the order so that neither variant always runs on a warmer machine.
            for (int v = 0; v < 2; ++v) {
                const bool inexact = (v + r) % 2 == 1;
                const Run run = compile(text(m, inexact), m.name);
                (inexact ? floating : exact).push_back(run.seconds);
                if (!inexact) sizes = run.sizes;
            }
        }
        const double e = median(exact), f = median(floating);
        std::cout << fmt::format("{:<10} {:>10.4f} {:>10.4f} {:>7.2f}x  {}\n", m.name, e, f, f / e, sizes);
    }
    return 0;
}
