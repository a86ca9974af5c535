// Distance to attractors and attractor covers (seed 000 secs. 2.3 and 2.4).
//  1. Branch and bound against the brute force of eq. (2) (every level-k image, k the least level whose
//     balls have radius <= epsilon) at epsilon = 1e-4, on the same points, in the same run.
//  2. The cell-graph cover of the Hénon attractor: cells, arcs and time per refinement.
// Usage: bench_distance [points] [refinements] [json]
#include "backend/interp/interpreter.hpp"
#include "bench_common.hpp"
#include "driver/pipeline.hpp"
#include "ir/tape.hpp"
#include "numeric/matrix.hpp"
#include "runtime/automata/attractor_cover.hpp"
#include "runtime/automata/distance.hpp"

#include <fmt/format.h>
#include <fstream>
#include <iostream>
#include <random>

using namespace frac;

namespace {

using num::Rational;

ir::Operator affine(Rational a, Rational b, Rational c, Rational d, Rational e, Rational f) {
    return ir::Operator::from_exact(num::Matrix<Rational>{{a, b, e}, {c, d, f}, {0, 0, 1}});
}

ir::Automaton ifs(const std::string& name, const std::vector<ir::Operator>& maps) {
    ir::Automaton a;
    a.name = name;
    a.states.push_back({name, ir::Space::euclidean(2), {}});
    for (const ir::Operator& m : maps) a.arcs.push_back({0, 0, m, std::nullopt, ""});
    return a;
}

ir::Automaton koch() {
    num::UpwardRounding up;
    const num::Interval t = num::div(1.0, 3.0), h = num::div(1.0, 6.0), s = num::div(num::sqrt(3.0), 6.0),
                        z(0.0);
    auto op = [](num::Interval a, num::Interval b, num::Interval c, num::Interval d, num::Interval e,
                 num::Interval f) {
        return ir::Operator::from_enclosure(
            num::Matrix<num::Interval>{{a, b, e}, {c, d, f}, {0.0, 0.0, 1.0}});
    };
    return ifs("koch", {op(t, z, z, t, z, z), op(h, num::neg(s), s, h, t, z),
                        op(h, s, num::neg(s), h, 0.5, s), op(t, z, z, t, num::div(2.0, 3.0), z)});
}

struct Row {
    std::string system;
    int level;
    std::uint64_t leaves, nodes;
    double brute_s, bb_s, max_width;
    bool agree;
};

Row compare(const ir::Automaton& a, int points, double lo, double hi) {
    constexpr double eps = 1e-4;
    rt::DistanceOptions o;
    o.epsilon = eps;
    const rt::AttractorDistance dist(a, o);
    const int level = dist.brute_force_level(eps);
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> u(lo, hi);
    std::vector<std::array<double, 2>> ps(static_cast<std::size_t>(points));
    for (auto& p : ps) p = {u(rng), u(rng)};
    Row r{a.name, level, 0, 0, 0, 0, 0, true};
    // Best of three runs of each, interleaved: the machine is shared.
    std::vector<rt::BruteForceResult> bf;
    std::vector<rt::DistanceResult> bb;
    r.brute_s = r.bb_s = 1e300;
    for (int rep = 0; rep < 3; ++rep) {
        bf.clear(), bb.clear();
        auto t0 = bench::Clock::now();
        for (const auto& p : ps) bf.push_back(dist.brute_force(p.data(), level));
        r.brute_s = std::min(r.brute_s, bench::seconds_since(t0));
        t0 = bench::Clock::now();
        for (const auto& p : ps) bb.push_back(dist.query(std::vector<num::Interval>{p[0], p[1]}.data()));
        r.bb_s = std::min(r.bb_s, bench::seconds_since(t0));
    }
    for (std::size_t i = 0; i < ps.size(); ++i) {
        r.leaves += bf[i].leaves, r.nodes += bb[i].nodes;
        r.max_width = std::max(r.max_width, bb[i].distance.hi - bb[i].distance.lo);
        // The two answers overlap (brute force: within its error of its estimate).
        r.agree = r.agree && bf[i].estimate - bf[i].error <= bb[i].distance.hi &&
                  bb[i].distance.lo <= bf[i].estimate + bf[i].error;
    }
    return r;
}

} // namespace

int main(int argc, char** argv) {
    const int points = argc > 1 ? std::atoi(argv[1]) : 20;
    const int refinements = argc > 2 ? std::atoi(argv[2]) : 5;
    const std::string json_path = argc > 3 ? argv[3] : "bench_distance.json";
    const Rational h(1, 2);
    const ir::Automaton sierpinski =
        ifs("sierpinski", {affine(h, 0, 0, h, 0, 0), affine(h, 0, 0, h, h, 0), affine(h, 0, 0, h, 0, h)});

    fmt::print("Distance at epsilon 1e-4, {} points: branch and bound against eq. (2) brute force\n", points);
    fmt::print("{:<12} {:>6} {:>14} {:>12} {:>10} {:>12} {:>10} {:>10} {:>6}\n", "system", "level",
               "leaves/point", "brute s", "nodes/pt", "b&b s", "speedup", "width", "agree");
    std::vector<Row> rows{compare(sierpinski, points, -0.5, 1.5), compare(koch(), points, -0.3, 1.3)};
    for (const Row& r : rows)
        fmt::print("{:<12} {:>6} {:>14} {:>12.4f} {:>10} {:>12.6f} {:>9.0f}x {:>10.2e} {:>6}\n", r.system,
                   r.level, r.leaves / static_cast<std::uint64_t>(points), r.brute_s,
                   r.nodes / static_cast<std::uint64_t>(points), r.bb_s, r.brute_s / r.bb_s, r.max_width,
                   r.agree ? "yes" : "NO");

    auto c = driver::compile_source("henon.frac",
                                    "shape hx(x, y) = 1 + y - 1.4 * x^2;\nshape hy(x, y) = 0.3 * x;");
    if (!c->ok()) {
        std::cerr << c->diags.render(c->sources);
        return 1;
    }
    std::vector<std::unique_ptr<ir::Evaluator>> evals;
    std::vector<ir::Evaluator*> components;
    for (const char* name : {"hx", "hy"}) {
        const front::ShapeInfo* s = c->module.find_shape(name);
        evals.push_back(interp::make_interpreter(ir::build_tape(c->module.graph, s->root, s->dimension)));
        components.push_back(evals.back().get());
    }
    rt::AttractorCoverOptions o;
    o.initial_level = 6;
    o.refinements = refinements;
    const rt::AttractorCoverResult cover = rt::map_attractor_cover(components, {{-1.5, 1.5}, {-0.5, 0.5}}, o);
    fmt::print("\nHenon attractor cover (a = 1.4, b = 0.3) over [-1.5, 1.5] x [-0.5, 0.5], interpreter\n");
    fmt::print("{:>6} {:>10} {:>12} {:>10} {:>12} {:>10}\n", "level", "cells", "arcs", "kept", "area",
               "seconds");
    for (const rt::CoverStep& s : cover.steps)
        fmt::print("{:>6} {:>10} {:>12} {:>10} {:>12.6f} {:>10.3f}\n", s.level, s.cells, s.arcs, s.kept,
                   s.area, s.seconds);

    std::ofstream json(json_path);
    json << "{\"distance\": [";
    for (std::size_t i = 0; i < rows.size(); ++i)
        json << (i ? ", " : "")
             << fmt::format(
                    "{{\"system\": \"{}\", \"level\": {}, \"brute_s\": {}, \"bb_s\": {}, \"speedup\": {}}}",
                    rows[i].system, rows[i].level, rows[i].brute_s, rows[i].bb_s,
                    rows[i].brute_s / rows[i].bb_s);
    json << "], \"henon\": [";
    for (std::size_t i = 0; i < cover.steps.size(); ++i)
        json << (i ? ", " : "")
             << fmt::format("{{\"level\": {}, \"cells\": {}, \"arcs\": {}, \"kept\": {}, \"seconds\": {}}}",
                            cover.steps[i].level, cover.steps[i].cells, cover.steps[i].arcs,
                            cover.steps[i].kept, cover.steps[i].seconds);
    json << "]}\n";
    bool ok = true;
    for (const Row& r : rows) ok = ok && r.agree;
    return ok ? 0 : 1;
}
