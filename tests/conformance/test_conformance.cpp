// One conformance suite for every evaluator: each test runs for the interpreter, the JIT and a model
// compiled ahead of time (the shared library `frac compile` makes, loaded with dlopen). Where the C ABI
// of compiled models lacks what a check reads (series counters), the check says so and skips that
// engine; everything else holds for all three.
#include "tests/unit/llvm/engines.hpp"

#include "runtime/rss.hpp"

#include <cfenv>
#include <cstdlib>
#include <thread>

using namespace frac;
using namespace frac::test;

namespace {

template <class E>
std::unique_ptr<ir::Evaluator> shape_eval(const Model& m, const std::string& name, ir::EvalOptions o = {}) {
    for (std::size_t i = 0; i < m.tapes.size(); ++i)
        if (m.shape(i).name == name) return E::make(m.tapes[i], o);
    FAIL("no shape " << name);
    return nullptr;
}

Interval box2(ir::Evaluator& e, Interval x, Interval y) {
    const Interval b[2] = {x, y};
    return e.eval_box(b);
}

double point2(ir::Evaluator& e, double x, double y) {
    const double p[2] = {x, y};
    return e.eval_point(p);
}

double takagi_reference(double x) {
    double s = 0, p = 1;
    for (int i = 0; i < 60; ++i, p *= 2) s += std::fabs(p * x - std::nearbyint(p * x)) / p;
    return s;
}

} // namespace

TEMPLATE_TEST_CASE("plain expressions on points and boxes", "[conformance]", InterpEngine, JitEngine,
                   TieredEngine, AotEngine) {
    const Model m = compile("shape s(x, y) = x * x + y * y - 1;");
    auto e = TestType::make(m.tapes[0]);
    CHECK(e->engine() == TestType::name);
    CHECK(e->dimension() == 2);
    CHECK(point2(*e, 0.5, 0.5) == -0.5);
    const Interval r = box2(*e, {0, 1}, {0, 1});
    CHECK(r.lo <= -1.0);
    CHECK(r.hi >= 1.0);
    // Outward rounding: 0.1 + 0.2 is not a double, so the enclosure of the thin box is not thin.
    const Model m2 = compile("shape s(x, y) = x + y;");
    auto e2 = TestType::make(m2.tapes[0]);
    const Interval s = box2(*e2, Interval(0.1), Interval(0.2));
    CHECK(s.lo < s.hi);
    CHECK(s.lo == std::nextafter(s.hi, 0.0));
    CHECK(s.contains(0.30000000000000004));
}

TEMPLATE_TEST_CASE("rounding is set by the evaluator and restored", "[conformance]", InterpEngine, JitEngine,
                   TieredEngine, AotEngine) {
    const Model m = compile("shape s(x, y) = x / 3 + y * 0.1;");
    auto e = TestType::make(m.tapes[0]);
    REQUIRE(std::fegetround() == FE_TONEAREST);
    const Interval r = box2(*e, Interval(1.0), Interval(1.0));
    CHECK(std::fegetround() == FE_TONEAREST);
    CHECK(r.lo < r.hi); // both 1/3 and 0.1 are enclosed
    // Called with the mode already upward (nested batches): the same result.
    std::fesetround(FE_UPWARD);
    const Interval r2 = box2(*e, Interval(1.0), Interval(1.0));
    CHECK(std::fegetround() == FE_UPWARD);
    std::fesetround(FE_TONEAREST);
    CHECK(same(r, r2));
}

TEMPLATE_TEST_CASE("Takagi series: point value and proven enclosure", "[conformance][series]", InterpEngine,
                   JitEngine, TieredEngine, AotEngine) {
    const Model m = compile("shape s(x, y) = y - sum(i in 0.., dz(2^i * x) / 2^i);");
    auto e = TestType::make(m.tapes[0]);
    for (double x : {0.1, 0.3, 1.0 / 3.0, 0.77}) {
        const double t = takagi_reference(x);
        CHECK(-point2(*e, x, 0.0) == Approx(t).epsilon(1e-14));
        const Interval b = box2(*e, Interval(x), Interval(0.0));
        CHECK(b.contains(-t));
        CHECK(num::width(b) < 1e-12);
    }
}

TEMPLATE_TEST_CASE("wide boxes are not charged for terms they cannot resolve", "[conformance][series]",
                   InterpEngine, JitEngine, TieredEngine, AotEngine) {
    const Model m = compile("import \"fractals\";");
    auto e = shape_eval<TestType>(m, "carpet");
    auto reference = shape_eval<InterpEngine>(m, "carpet");
    e->stats = {};
    const Interval wide = box2(*e, {0.1, 0.1 + 1.0 / 64}, {0.2, 0.2 + 1.0 / 64});
    [[maybe_unused]] const auto wide_terms = e->stats.series_terms;
    e->stats = {};
    const Interval narrow = box2(*e, {0.1, 0.1 + 1e-9}, {0.2, 0.2 + 1e-9});
    [[maybe_unused]] const auto narrow_terms = e->stats.series_terms;
    if constexpr (TestType::counts_series) { // compiled models count calls only
        CHECK(wide_terms <= 6);
        CHECK(narrow_terms > wide_terms);
        CHECK(e->stats.series_capped == 0);
    }
    // The same terms as the interpreter's: the same bits.
    CHECK(same(wide, box2(*reference, {0.1, 0.1 + 1.0 / 64}, {0.2, 0.2 + 1.0 / 64})));
    CHECK(same(narrow, box2(*reference, {0.1, 0.1 + 1e-9}, {0.2, 0.2 + 1e-9})));
    CHECK(e->stats.calls == 1);
    // Holes are proven inside, the carpet itself never.
    CHECK(box2(*e, {0.4, 0.6}, {0.4, 0.6}).hi < 0);
    CHECK(box2(*e, {0.13, 0.2}, {0.13, 0.2}).hi < 0);
    CHECK(box2(*e, {0.0, 1e-6}, {0.0, 1e-6}).hi >= 0);
}

TEMPLATE_TEST_CASE("the term limit caps a series and is counted", "[conformance][series]", InterpEngine,
                   JitEngine, TieredEngine, AotEngine) {
    const Model m = compile("shape s(x, y) = y - sum(i in 0.., dz(2^i * x) / 2^i);");
    ir::EvalOptions o;
    o.max_terms = 5;
    o.adaptive_terms = false;
    auto e = TestType::make(m.tapes[0], o);
    const Interval r = box2(*e, Interval(0.3), Interval(0.0));
    if constexpr (TestType::counts_series) { // compiled models count calls only
        CHECK(e->stats.series_terms == 5);
        CHECK(e->stats.series_capped == 1);
    }
    CHECK(r.contains(-takagi_reference(0.3)));
    // Five terms and no more: the enclosure is the one the interpreter computes with this cap, wider
    // than the uncapped one.
    auto reference = interp::make_interpreter(m.tapes[0], o);
    CHECK(same(r, box2(*reference, Interval(0.3), Interval(0.0))));
    CHECK(num::width(r) > num::width(box2(*TestType::make(m.tapes[0]), Interval(0.3), Interval(0.0))));
    CHECK_THROWS_AS(TestType::make(m.tapes[0], ir::EvalOptions{0, true}), std::invalid_argument);
}

TEMPLATE_TEST_CASE("orbit series update the point simultaneously", "[conformance][series]", InterpEngine,
                   JitEngine, TieredEngine, AotEngine) {
    // p0 = (x, y), p1 = swap(p0) = (y, x): the sum of p.y over both is y + x.
    const Model m =
        compile("fn swap(p) = (p.y, p.x); shape s(x, y) = sum(k in 0..1, p in orbit((x, y), swap), p.y);");
    auto e = TestType::make(m.tapes[0]);
    CHECK(point2(*e, 0.25, 0.5) == 0.75);
    CHECK(same(box2(*e, Interval(0.25), Interval(0.5)), Interval(0.75)));
}

TEMPLATE_TEST_CASE("empty coordinates give empty enclosures", "[conformance]", InterpEngine, JitEngine,
                   TieredEngine, AotEngine) {
    const Model m = compile("import \"fractals\"; shape d(x, y) = sqrt(x) + y;");
    auto carpet = shape_eval<TestType>(m, "carpet");
    CHECK(box2(*carpet, Interval::empty(), {0, 1}).is_empty());
    auto d = shape_eval<TestType>(m, "d");
    CHECK(box2(*d, {-2, -1}, {0, 1}).is_empty()); // sqrt outside its domain
    CHECK(box2(*d, {0, 4}, Interval::empty()).is_empty());
    const Interval r = box2(*d, {-1, 4}, {0, 1});
    CHECK(r.lo <= 0);
    CHECK(r.hi >= 3);
}

TEMPLATE_TEST_CASE("batches equal single evaluations, clones are independent", "[conformance]", InterpEngine,
                   JitEngine, TieredEngine, AotEngine) {
    const Model m = compile("import \"fractals\";");
    auto e = shape_eval<TestType>(m, "triangle_stripes");
    BoxMaker mk(3);
    std::vector<Interval> boxes;
    std::vector<double> points;
    for (int n = 0; n < 500; ++n) {
        for (const Interval& c : mk.box({{0, 1}, {0, 1}})) boxes.push_back(c);
        for (double p : mk.point({{0, 1}, {0, 1}})) points.push_back(p);
    }
    boxes[2 * 17] = Interval::empty();
    std::vector<Interval> batch(500);
    std::vector<double> pbatch(500);
    e->stats = {};
    e->eval_boxes(boxes.data(), 500, batch.data());
    CHECK(e->stats.calls == 500);
    const auto terms = e->stats.series_terms;
    auto c = e->clone();
    CHECK(c->engine() == TestType::name);
    CHECK(c->stats.calls == 0);
    c->eval_points(points.data(), 500, pbatch.data());
    std::uint64_t single_terms = 0;
    for (int n = 0; n < 500; ++n) {
        c->stats = {};
        CHECK(same(c->eval_box(&boxes[2 * static_cast<std::size_t>(n)]), batch[static_cast<std::size_t>(n)]));
        single_terms += c->stats.series_terms;
        CHECK(same(c->eval_point(&points[2 * static_cast<std::size_t>(n)]),
                   pbatch[static_cast<std::size_t>(n)]));
    }
    CHECK(single_terms == terms);
    e.reset(); // the clone keeps working without its original
    CHECK(same(c->eval_box(&boxes[0]), batch[0]));
}

TEMPLATE_TEST_CASE("clones evaluate on several threads", "[conformance]", InterpEngine, JitEngine,
                   TieredEngine, AotEngine) {
    const Model m = compile("import \"fractals\";");
    auto e = shape_eval<TestType>(m, "carpet");
    const std::vector<Interval> root{{0, 1}, {0, 1}};
    rt::RssOptions o;
    o.depth = 6;
    o.keep_cells = false;
    const rt::RssResult expected = rt::subdivide(*e, root, o);
    std::vector<std::uint64_t> boundary(2);
    std::vector<std::thread> threads;
    for (int t = 0; t < 2; ++t)
        threads.emplace_back([&, t] {
            auto c = e->clone();
            boundary[static_cast<std::size_t>(t)] = rt::subdivide(*c, root, o).boundary;
        });
    for (auto& t : threads) t.join();
    CHECK(boundary[0] == expected.boundary);
    CHECK(boundary[1] == expected.boundary);
}

namespace {

// Engines e[1 .. engines) against e[0] on the same random boxes and points, one by one and in batches:
// returns a description of the first difference in bits, empty when there is none. Boxes with an empty
// coordinate are left out: compiled models give them the empty image (docs/c-abi.md), the others evaluate on
// them.
std::string differ_from_first(const std::unique_ptr<ir::Evaluator>* e, int engines, const ir::Tape& t,
                              const std::vector<Interval>& range, std::uint64_t seed, std::size_t count) {
    const auto d = static_cast<std::size_t>(t.inputs);
    BoxMaker mk(seed);
    std::vector<Interval> boxes;
    std::vector<double> points;
    for (std::size_t n = 0; n < count; ++n) {
        for (const Interval& c : mk.box(range)) boxes.push_back(c);
        for (double p : mk.point(range)) points.push_back(p);
    }
    std::vector<Interval> batch[3];
    std::vector<double> pbatch[3];
    for (int k = 0; k < engines; ++k) {
        batch[k].resize(count);
        pbatch[k].resize(count);
        e[k]->eval_boxes(boxes.data(), count, batch[k].data());
        e[k]->eval_points(points.data(), count, pbatch[k].data());
    }
    for (std::size_t n = 0; n < count; ++n) {
        const Interval* b = boxes.data() + d * n;
        const double* p = points.data() + d * n;
        const Interval ri = e[0]->eval_box(b);
        const double pi = e[0]->eval_point(p);
        for (int k = 1; k < engines; ++k) {
            const std::string who = e[k]->engine() + " (" + e[0]->engine() + " ";
            if (!same(e[k]->eval_box(b), ri))
                return "box " + hex_box(b, t.inputs) + ": " + who + hex(ri) + ") " + hex(e[k]->eval_box(b));
            if (!same(batch[k][n], ri)) return "batch box " + std::to_string(n) + ": " + who + hex(ri) + ")";
            if (!same(e[k]->eval_point(p), pi))
                return "point " + std::to_string(n) + ": " + who + hex(pi) + ")";
            if (!same(pbatch[k][n], pi))
                return "batch point " + std::to_string(n) + ": " + who + hex(pi) + ")";
        }
    }
    return "";
}

// The interpreter against the JIT and a compiled model built with the numeric core's calls in place of
// the inline sin, cos, exp, tan, log, pow and atan2 kernels (FRAC_JIT_EXACT_CALLS=1: the interpreter's bits);
// then the JIT against a compiled model with the inline kernels (the same generated code).
std::string engines_differ(const ir::Tape& t, const std::vector<Interval>& range, std::uint64_t seed,
                           std::size_t count, const ir::EvalOptions& o = {}) {
    setenv("FRAC_JIT_EXACT_CALLS", "1", 1);
    std::unique_ptr<ir::Evaluator> exact[3] = {InterpEngine::make(t, o), JitEngine::make(t, o),
                                               AotEngine::make(t, o)};
    unsetenv("FRAC_JIT_EXACT_CALLS");
    const std::string differ = differ_from_first(exact, 3, t, range, seed, count);
    if (!differ.empty()) return differ;
    std::unique_ptr<ir::Evaluator> inline_kernels[2] = {JitEngine::make(t, o), AotEngine::make(t, o)};
    return differ_from_first(inline_kernels, 2, t, range, seed, count);
}

} // namespace

TEST_CASE("the three engines agree bit for bit: every operation and series of every kind", "[conformance]") {
    // Together the operations call every helper of the run-time support that compiled models link.
    const char* exprs[] = {
        "x * y - x / y + 1 / x - y^2 + x^3 + x^-1 - y^-2 + x^y + abs(x)^0.5 + abs(x - y)",
        "sqrt(x) + log(y) + pow(abs(x), 1/3)",
        "min(x, y) + max(x, 1, y) + floor(x * 3) - ceil(y / 3) + mod(3 * x, 1) + dz(5 * x + y)",
        "sin(x) + cos(3 * y) - tan(x) + exp(x) - log(abs(x) + y) + atan2(y, x)",
        "if x < y and not (x >= 0.5) or y == 1 then x * x else if x != y then -y else log(y)",
        "[0.1, 0.2] * x + [-1, 1] / y + 1e300 * x * x - exp(x * 800) + dz(x * 1e17)",
    };
    std::uint64_t seed = 40;
    for (const char* e : exprs) {
        const Model m = compile(std::string("shape s(x, y) = ") + e + ";");
        INFO(e);
        CHECK(engines_differ(m.tapes[0], {{-1, 1}, {-1, 1}}, ++seed, 150) == "");
    }
    for (const std::string& e : series_kinds()) {
        // compile() fails the test when the expression does not compile: none is skipped.
        const Model m = compile(series_maps + "shape s(x, y) = " + e + ";");
        INFO(e);
        CHECK(engines_differ(m.tapes[0], {{-1, 1}, {-1, 1}}, ++seed, 150) == "");
    }
    // Options are baked into compiled code: a small term limit, and fixed term counts.
    const Model m = compile("import \"fractals\";");
    ir::EvalOptions capped;
    capped.max_terms = 3;
    ir::EvalOptions fixed;
    fixed.adaptive_terms = false;
    for (const char* name : {"carpet", "triangle_stripes"})
        for (const ir::EvalOptions& o : {capped, fixed})
            for (std::size_t i = 0; i < m.tapes.size(); ++i)
                if (m.shape(i).name == name) {
                    INFO(name << ", max_terms " << o.max_terms << ", adaptive " << o.adaptive_terms);
                    CHECK(engines_differ(m.tapes[i], m.shape(i).box, ++seed, 150, o) == "");
                }
}

TEST_CASE("closed expressions (no coordinates) agree on every engine", "[conformance]") {
    ir::Graph g;
    const ir::NodeId root = g.op(ir::Op::Add, g.constant(1.0), g.constant(Interval{0.1, 0.2}, 0.15));
    const ir::Tape t = ir::build_tape(g, root, 0);
    auto a = AotEngine::make(t);
    CHECK(a->dimension() == 0);
    CHECK(engines_differ(t, {}, 1, 4) == "");
}

TEST_CASE("dist(p, A) agrees on every engine, compiled models included", "[conformance][dist]") {
    // A euclidean IFS composed by CSG, and a projected B-spline CIFS (a bary(3) state).
    const Model m = compile("import \"ifs\";\nimport \"fractals\";\n"
                            "shape fused(x, y) = dist((x, y), sierpinski) - 0.01 | carpet(x, y);\n"
                            "shape curve(x, y) = dist((x, y), quadratic_bspline) - 0.05;\n");
    std::uint64_t seed = 40;
    for (std::size_t i = 0; i < m.tapes.size(); ++i) {
        if (m.shape(i).name != "fused" && m.shape(i).name != "curve") continue;
        INFO(m.shape(i).name);
        REQUIRE(!m.tapes[i].externals.empty());
        CHECK(engines_differ(m.tapes[i], {{-0.5, 3.5}, {-0.5, 2.5}}, ++seed, 60) == "");
    }
}
