// A point value lies in the enclosure of its own point: every standard-library shape and random
// series of every kind, both engines. Point evaluation stops a series on a bound of its tail
// (ir/point_bounds.hpp), never on the point value of an enclosure (once the cause of a triangle that
// printed 0 where the value is 0.11667, and of a sum printed as -0.15 in [-0.1333, -0.1333]).
#include "engines.hpp"

#include "ir/point_bounds.hpp"

#include <fmt/format.h>
#include <set>

using namespace frac;
using namespace frac::test;

namespace {

// The point value is inside the enclosure; NaN exactly where the enclosure is empty.
bool inside(double p, Interval e) {
    if (e.is_empty()) return std::isnan(p);
    return e.lo <= p && p <= e.hi;
}

struct Violations {
    std::size_t checked = 0, outside = 0;
    std::string first;
};

// `count` random points of `range`, evaluated as points and as thin boxes, in batches.
template <class Engine>
void check_points(const ir::Tape& tape, const std::vector<Interval>& range, std::size_t count,
                  std::uint64_t seed, Violations& v, const std::string& what) {
    auto e = Engine::make(tape);
    const auto d = static_cast<std::size_t>(tape.inputs);
    BoxMaker mk(seed);
    std::vector<double> points;
    std::vector<Interval> boxes;
    for (std::size_t n = 0; n < count; ++n) {
        for (double c : mk.point(range)) {
            points.push_back(c);
            boxes.push_back(Interval(c));
        }
    }
    std::vector<double> values(count);
    std::vector<Interval> enclosures(count);
    e->eval_points(points.data(), count, values.data());
    e->eval_boxes(boxes.data(), count, enclosures.data());
    for (std::size_t n = 0; n < count; ++n) {
        ++v.checked;
        if (inside(values[n], enclosures[n])) continue;
        ++v.outside;
        if (v.first.empty()) {
            std::string at;
            for (std::size_t k = 0; k < d; ++k) at += (k ? ", " : "") + hex(points[n * d + k]);
            v.first =
                what + " at (" + at + "): point " + hex(values[n]) + ", enclosure " + hex(enclosures[n]);
        }
    }
}

// A random series over x, y whose terms the frontend can bound: bounded kernels of b^i-scaled
// arguments, index-free factors, occasionally a factor i (a B coefficient), divided by c^i.
class SeriesMaker {
public:
    explicit SeriesMaker(std::uint64_t seed) : mk_(seed) {}

    std::string series() {
        static const char* kinds[] = {"sum", "min", "max"};
        static const char* decays[] = {"2", "3", "1.5", "4", "2.5"};
        const std::string kind = kinds[mk_.pick(3)];
        std::string term = "(" + bounded(3) + ")";
        if (mk_.pick(5) == 0) term += " * i";
        term += " / " + std::string(decays[mk_.pick(5)]) + "^i";
        const std::string start = mk_.pick(4) == 0 ? "1" : "0";
        std::string s = kind + "(i in " + start + ".., " + term + ")";
        switch (mk_.pick(3)) {
        case 0: return "y - " + s;
        case 1: return s;
        default: return s + " + " + index_free();
        }
    }

private:
    std::string argument() {
        static const char* bases[] = {"2", "3", "1.5"};
        static const char* forms[] = {"x", "y", "(x + y)", "(x - 0.3 * y)", "(0.7 * y + 0.1)"};
        return std::string(bases[mk_.pick(3)]) + "^i * " + forms[mk_.pick(5)];
    }
    std::string index_free() {
        static const char* forms[] = {"x",   "y",    "(x - y)", "sqrt(x^2 + y^2)", "sin(3 * x)",
                                      "1/3", "0.25", "x * y",   "abs(x)",          "-1/6"};
        return forms[mk_.pick(10)];
    }
    std::string bounded(int depth) {
        if (depth == 0 || mk_.pick(4) == 0) {
            switch (mk_.pick(7)) {
            case 0: return "dz(" + argument() + ")";
            case 1: return "mod(" + argument() + ", 1)";
            case 2: return "sin(" + argument() + ")";
            case 3: return "cos(" + argument() + ")";
            case 4: return "(dz(" + argument() + ") - 1/4)";
            case 5: return "(dz(" + argument() + ") - dz(" + argument() + "))";
            default: return fmt::format("{}", mk_.uniform(-1, 1));
            }
        }
        switch (mk_.pick(9)) {
        case 0: return bounded(depth - 1) + " + " + bounded(depth - 1);
        case 1: return bounded(depth - 1) + " - " + bounded(depth - 1);
        case 2: return "(" + bounded(depth - 1) + ") * (" + bounded(depth - 1) + ")";
        case 3: return "min(" + bounded(depth - 1) + ", " + bounded(depth - 1) + ")";
        case 4: return "max(" + bounded(depth - 1) + ", " + bounded(depth - 1) + ")";
        case 5: return "abs(" + bounded(depth - 1) + ")";
        case 6: return "-(" + bounded(depth - 1) + ")";
        case 7: return index_free() + " * (" + bounded(depth - 1) + ")";
        default:
            return "(if " + index_free() + " < 0.5 then " + bounded(depth - 1) + " else " +
                   bounded(depth - 1) + ")";
        }
    }

    BoxMaker mk_;
};

} // namespace

TEMPLATE_TEST_CASE("every stdlib shape: point values lie in their enclosures", "[llvm][point]", InterpEngine,
                   JitEngine) {
    // Every shape once (a file imports others), at least 10^5 points in all.
    std::vector<std::pair<const Model*, std::size_t>> shapes;
    std::vector<Model> models;
    models.reserve(stdlib_files().size());
    std::set<std::string> seen;
    for (const std::string& file : stdlib_files()) {
        models.push_back(compile("import \"" + file + "\";"));
        for (std::size_t i = 0; i < models.back().tapes.size(); ++i)
            if (seen.insert(models.back().shape(i).name).second) shapes.emplace_back(&models.back(), i);
    }
    REQUIRE(shapes.size() >= 20);
    const std::size_t per_shape = 100000 / shapes.size() + 1;
    Violations v;
    std::uint64_t seed = 500;
    for (const auto& [m, i] : shapes)
        check_points<TestType>(m->tapes[i], m->shape(i).box, per_shape, ++seed, v, m->shape(i).name);
    INFO(v.first);
    CHECK(v.checked >= 100000);
    CHECK(v.outside == 0);
}

namespace {

// `count` random series from `seed`, each its own shape, `points` points each.
template <class Engine>
void check_random_series(std::uint64_t seed, int count, std::size_t points) {
    SeriesMaker sm(seed);
    Violations v;
    int series = 0;
    for (int n = 0; n < count; ++n) {
        const std::string expr = sm.series();
        auto c = driver::compile_source("t.frac", "shape s(x, y) = " + expr + ";");
        INFO(expr << "\n" << c->diags.render(c->sources));
        REQUIRE(c->ok()); // every generated series has a provable tail
        ++series;
        const ir::Tape t = ir::build_tape(c->module.graph, c->module.shapes[0].root, 2);
        check_points<Engine>(t, {{-1.5, 1.5}, {-1.5, 1.5}}, points,
                             seed * 100000 + static_cast<std::uint64_t>(n), v, expr);
    }
    INFO(v.first);
    CHECK(series == count);
    CHECK(v.checked == static_cast<std::size_t>(count) * points);
    CHECK(v.outside == 0);
}

} // namespace

TEST_CASE("random series: point values lie in their enclosures (interpreter, 10^4 series)",
          "[llvm][point][series]") {
    check_random_series<InterpEngine>(1, 10000, 8);
}

// The JIT compiles each series (about 25 ms): 10^4 series in five parts that CTest runs in parallel.
TEST_CASE("random series: point values lie in their enclosures (JIT, part 1 of 5)", "[llvm][point][series]") {
    check_random_series<JitEngine>(1, 2000, 4); // the interpreter's first 2000 series
}
TEST_CASE("random series: point values lie in their enclosures (JIT, part 2 of 5)", "[llvm][point][series]") {
    check_random_series<JitEngine>(2, 2000, 4);
}
TEST_CASE("random series: point values lie in their enclosures (JIT, part 3 of 5)", "[llvm][point][series]") {
    check_random_series<JitEngine>(3, 2000, 4);
}
TEST_CASE("random series: point values lie in their enclosures (JIT, part 4 of 5)", "[llvm][point][series]") {
    check_random_series<JitEngine>(4, 2000, 4);
}
TEST_CASE("random series: point values lie in their enclosures (JIT, part 5 of 5)", "[llvm][point][series]") {
    check_random_series<JitEngine>(5, 2000, 4);
}

namespace {

// The graph of `root` with every interval constant replaced by a random value of its enclosure: one
// function the enclosure stands for.
ir::NodeId instantiate(const ir::Graph& from, ir::NodeId root, ir::Graph& to, BoxMaker& mk) {
    std::vector<ir::NodeId> map(root + 1, ir::no_node);
    for (ir::NodeId id = 0; id <= root; ++id) {
        const ir::Node& n = from[id];
        switch (ir::op_class(n.op)) {
        case ir::OpClass::leaf:
            if (n.op == ir::Op::Var)
                map[id] = to.var(static_cast<int>(n.imm));
            else if (n.op == ir::Op::Const) {
                // A finite value of the enclosure (an infinite end stands for large values).
                const double lo = std::fmax(n.value.lo, std::fmin(n.value.hi, 0.0) - 1e6);
                const double hi = std::fmin(n.value.hi, std::fmax(n.value.lo, 0.0) + 1e6);
                map[id] = n.value.is_empty()  ? to.constant(std::nan("")) // no value: undefined
                          : n.value.is_thin() ? to.constant(n.value, n.point)
                                              : to.constant(mk.uniform(lo, hi));
            }
            break;
        case ir::OpClass::series: break;
        default: {
            ir::NodeId a[3] = {ir::no_node, ir::no_node, ir::no_node};
            for (int k = 0; k < ir::arity(n.op); ++k) a[k] = map[n.args[static_cast<std::size_t>(k)]];
            map[id] = to.op(n.op, a[0], a[1], a[2], n.imm);
        }
        }
    }
    return map[root];
}

} // namespace

TEST_CASE("point bounds of an enclosure bound every function it stands for", "[llvm][point]") {
    // Random graphs with interval constants (each stands for any value of its enclosure): lo and hi,
    // evaluated as points, bound the value of every instance at the point (to rounding).
    BoxMaker mk(777);
    std::size_t checked = 0, bad = 0;
    std::string first;
    for (int n = 0; n < 3000; ++n) {
        ir::Graph g;
        const ir::NodeId root = random_node(g, mk, 4, true);
        const ir::PointBounds b = ir::point_bounds(g, root);
        auto el = interp::make_interpreter(ir::build_tape(g, b.lo, 2));
        auto eh = interp::make_interpreter(ir::build_tape(g, b.hi, 2));
        for (int inst = 0; inst < 5; ++inst) {
            ir::Graph gi;
            const ir::NodeId ri = instantiate(g, root, gi, mk);
            auto ev = interp::make_interpreter(ir::build_tape(gi, ri, 2));
            for (int k = 0; k < 10; ++k) {
                const std::vector<double> p = mk.point({{-2, 2}, {-2, 2}});
                const double v = ev->eval_point(p.data());
                if (std::isnan(v)) continue;
                const double l = el->eval_point(p.data()), h = eh->eval_point(p.data());
                ++checked;
                // a <= b to rounding; NaN bounds read as unbounded (ir::point_magnitude).
                const auto below = [](double x, double y) {
                    return std::isnan(x) || std::isnan(y) || x <= y ||
                           (std::isfinite(y) && x <= y + 1e-9 * std::fmax(1.0, std::fabs(y)));
                };
                if (!(below(l, v) && below(v, h)) && ++bad == 1)
                    first = ir::print_graph(g, {root}) +
                            fmt::format("at ({}, {}): bounds [{}, {}], an instance {}", p[0], p[1], l, h, v);
            }
        }
    }
    INFO(first);
    CHECK(checked > 100000);
    CHECK(bad == 0);
}
