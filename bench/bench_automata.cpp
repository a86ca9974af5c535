// Automata: the chaos game against a hand-written C++ loop doing the same maps with the same random
// numbers (the physical floor for this job on one core), on 2 threads; the streamed evaluation tree
// of the cubic B-spline CIFS (time per node, memory bounded). Ratios are measured in one run.
//
// Usage: bench_automata [million points, default 20]
#include "bench_common.hpp"
#include "runtime/automata/chaos.hpp"
#include "runtime/automata/tree.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <sys/resource.h>

using namespace frac;
using bench::Clock;
using bench::seconds_since;

namespace {

num::Matrix<num::Rational> affine2(const char* a, const char* b, const char* c, const char* d, const char* e,
                                   const char* f) {
    auto q = [](const char* t) { return *num::Rational::parse_decimal(t); };
    num::Matrix<num::Rational> m(3, 3);
    m(0, 0) = q(a), m(0, 1) = q(b), m(0, 2) = q(e);
    m(1, 0) = q(c), m(1, 1) = q(d), m(1, 2) = q(f);
    m(2, 2) = 1;
    return m;
}

ir::Automaton ifs(const char* name, const std::vector<num::Matrix<num::Rational>>& maps) {
    ir::Automaton a;
    a.name = name;
    a.states.push_back({"s", ir::Space::euclidean(2), {}});
    for (std::size_t i = 0; i < maps.size(); ++i) {
        ir::Arc arc;
        arc.op = ir::Operator::from_exact(maps[i]);
        arc.label = fmt::format("f{}", i);
        a.arcs.push_back(arc);
    }
    return a;
}

ir::Automaton fern() {
    return ifs("fern", {affine2("0", "0", "0", "0.16", "0", "0"),
                        affine2("0.85", "0.04", "-0.04", "0.85", "0", "1.6"),
                        affine2("0.2", "-0.26", "0.23", "0.22", "0", "1.6"),
                        affine2("-0.15", "0.28", "0.26", "0.24", "0", "0.44")});
}

ir::Automaton sierpinski() {
    return ifs("sierpinski",
               {affine2("0.5", "0", "0", "0.5", "0", "0"), affine2("0.5", "0", "0", "0.5", "0.5", "0"),
                affine2("0.5", "0", "0", "0.5", "0.25", "0.5")});
}

// The cubic B-spline with 5 control points as a projected CIFS: a in R2, b in bary(4).
ir::Automaton cubic() {
    auto q = [](long n, long d) { return num::Rational(n, d); };
    ir::Automaton a;
    a.name = "cubic";
    a.states.push_back({"a", ir::Space::euclidean(2), {}});
    ir::Primitive polygon;
    polygon.kind = ir::Primitive::Kind::polyline;
    polygon.points = num::Matrix<double>::identity(4);
    a.states.push_back({"b", ir::Space::barycentric(4), polygon});
    const long px[] = {0, 1, 4, 5, 8}, py[] = {0, 3, 3, -1, 2};
    for (std::size_t seg = 0; seg < 2; ++seg) {
        num::Matrix<num::Rational> p(3, 4);
        for (std::size_t j = 0; j < 4; ++j) p(0, j) = px[seg + j], p(1, j) = py[seg + j], p(2, j) = 1;
        ir::Arc arc;
        arc.from = 0, arc.to = 1;
        arc.op = ir::Operator::from_exact(p);
        arc.label = fmt::format("T{}a", seg);
        a.arcs.push_back(arc);
    }
    const num::Matrix<num::Rational> t0{{q(1, 2), q(1, 8), 0, 0},
                                        {q(1, 2), q(6, 8), q(1, 2), q(1, 8)},
                                        {0, q(1, 8), q(1, 2), q(6, 8)},
                                        {0, 0, 0, q(1, 8)}};
    const num::Matrix<num::Rational> t1{{q(1, 8), 0, 0, 0},
                                        {q(6, 8), q(1, 2), q(1, 8), 0},
                                        {q(1, 8), q(1, 2), q(6, 8), q(1, 2)},
                                        {0, 0, q(1, 8), q(1, 2)}};
    for (const auto& [m, label] : {std::pair{t0, "T0b"}, std::pair{t1, "T1b"}}) {
        ir::Arc arc;
        arc.from = arc.to = 1;
        arc.op = ir::Operator::from_exact(m);
        arc.label = label;
        a.arcs.push_back(arc);
    }
    return a;
}

// The same job written by hand for a one-state affine IFS of the plane: the same random stream, the
// same thresholds, the same start (the first map's fixed point) and the same grid.
rt::Density handwritten(const ir::Automaton& a, const rt::ChaosOptions& o, const rt::Density& like) {
    struct Map {
        double a, b, c, d, e, f;
    };
    std::vector<Map> maps;
    for (const ir::Arc& arc : a.arcs) {
        const auto& m = arc.op.nearest;
        maps.push_back({m(0, 0), m(0, 1), m(1, 0), m(1, 1), m(0, 2), m(1, 2)});
    }
    const std::vector<std::uint64_t> t = rt::draw_thresholds(rt::chaos_probabilities(a));
    rt::Density d = like;
    std::fill(d.counts.begin(), d.counts.end(), 0);
    d.outside = 0;
    const double sx = d.width / (d.x1 - d.x0), sy = d.height / (d.y1 - d.y0), w = d.width, h = d.height;
    // Fixed point of the first map.
    const Map& m0 = maps[0];
    const double det = (m0.a - 1) * (m0.d - 1) - m0.b * m0.c;
    double x = (-m0.e * (m0.d - 1) + m0.b * m0.f) / det, y = (-(m0.a - 1) * m0.f + m0.c * m0.e) / det;
    rt::Xoshiro256 rng(o.seed, 0);
    auto step = [&] {
        const std::uint64_t u = rng();
        std::size_t i = 0;
        while (u > t[i]) ++i;
        const Map& m = maps[i];
        const double nx = m.a * x + m.b * y + m.e;
        y = m.c * x + m.d * y + m.f;
        x = nx;
    };
    for (std::uint64_t k = 0; k < o.transient; ++k) step();
    for (std::uint64_t k = 0; k < o.points; ++k) {
        step();
        const double fx = (x - d.x0) * sx, fy = (y - d.y0) * sy;
        if (fx >= 0 && fx < w && fy >= 0 && fy < h)
            ++d.counts[static_cast<std::size_t>(fy) * static_cast<std::size_t>(d.width) +
                       static_cast<std::size_t>(fx)];
        else
            ++d.outside;
    }
    d.recorded = o.points - d.outside;
    return d;
}

double cpu_seconds() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
           static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-6;
}

long peak_rss_kib() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return u.ru_maxrss;
}

} // namespace

int main(int argc, char** argv) {
    const std::uint64_t points = static_cast<std::uint64_t>((argc > 1 ? std::atof(argv[1]) : 20.0) * 1e6);
    fmt::print("chaos game, {} M points, 512 px wide density, best of 3\n", points / 1000000.0);
    // cpu: points per CPU second (1 thread, then 2 threads together), so a busy machine that cannot give
    // the run two cores still shows whether the threads themselves lose anything.
    fmt::print("{:<11} {:>10} {:>10} {:>6} {:>9} {:>6} {:>9} {:>12} {:>5}\n", "ifs", "hand Mpt/s",
               "frac Mpt/s", "ratio", "2T Mpt/s", "2T/1T", "cpu Mpt/s", "2T cpu Mpt/s", "same");
    for (const ir::Automaton& a : {fern(), sierpinski()}) {
        rt::ChaosOptions o;
        o.points = points;
        o.seed = 5;
        o.width = 512;
        // One box for both, from the library's pilot run, so the timed runs do the same work.
        const rt::Density shape = rt::chaos_game(a, [&] {
            rt::ChaosOptions pilot = o;
            pilot.points = 1000;
            return pilot;
        }());
        o.box = std::array<double, 4>{shape.x0, shape.x1, shape.y0, shape.y1};
        o.height = shape.height;
        double hand = 1e300, lib = 1e300, lib_cpu = 1e300, two = 1e300, two_cpu = 1e300;
        rt::Density dh, dl;
        for (int rep = 0; rep < 3; ++rep) {
            auto t0 = Clock::now();
            dh = handwritten(a, o, shape);
            hand = std::min(hand, seconds_since(t0));
            t0 = Clock::now();
            const double l0 = cpu_seconds();
            dl = rt::chaos_game(a, o);
            lib = std::min(lib, seconds_since(t0));
            lib_cpu = std::min(lib_cpu, cpu_seconds() - l0);
            rt::ChaosOptions o2 = o;
            o2.threads = 2;
            t0 = Clock::now();
            const double c0 = cpu_seconds();
            (void)rt::chaos_game(a, o2);
            two = std::min(two, seconds_since(t0));
            two_cpu = std::min(two_cpu, cpu_seconds() - c0);
        }
        const double mp = static_cast<double>(points) / 1e6;
        fmt::print("{:<11} {:>10.1f} {:>10.1f} {:>6.2f} {:>9.1f} {:>6.2f} {:>9.1f} {:>12.1f} {:>5}\n", a.name,
                   mp / hand, mp / lib, hand / lib, mp / two, lib / two, mp / lib_cpu, mp / two_cpu,
                   dh.counts == dl.counts ? "yes" : "no");
    }

    fmt::print("\nevaluation tree of the cubic B-spline CIFS (2 segments, streamed DFS)\n");
    fmt::print("{:>6} {:>12} {:>10} {:>12} {:>14} {:>14}\n", "depth", "nodes", "ns/node", "stack bytes",
               "peak RSS KiB", "RSS growth KiB");
    const ir::Automaton c = cubic();
    for (int depth : {12, 16, 20}) {
        const long before = peak_rss_kib();
        double best = 1e300;
        rt::TreeStats stats;
        double sink = 0;
        const int reps = depth == 12 ? 200 : depth == 16 ? 10 : 1;
        for (int rep = 0; rep < 3; ++rep) {
            const auto t0 = Clock::now();
            for (int r = 0; r < reps; ++r)
                stats =
                    rt::walk_tree(c, {depth, false}, [&](const rt::TreeNode& n) { sink += (*n.op)(0, 0); });
            best = std::min(best, seconds_since(t0) / reps);
        }
        const long after = peak_rss_kib();
        fmt::print("{:>6} {:>12} {:>10.1f} {:>12} {:>14} {:>14}{}\n", depth, stats.nodes,
                   best / static_cast<double>(stats.nodes) * 1e9, stats.stack_bytes, after, after - before,
                   sink == 0 ? " (sink 0)" : "");
    }
    return 0;
}
