// The builtin dist(p, A): the distance to the attractor of an automaton, an external function of the IR
// bound by the driver to the runtime's branch and bound. Both engines call the same implementation, so
// they agree bit for bit; box results enclose the distance; RSS covers of dist(p, A) - r hold every
// chaos-game point; compiled (AOT) models embed the automaton (tests/aot compares them with the JIT).
#include "engines.hpp"

#include "backend/llvm/aot.hpp"
#include "driver/external_functions.hpp"
#include "runtime/automata/chaos.hpp"
#include "runtime/rss.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <tuple>

using namespace frac;
using namespace frac::test;

namespace {

const char* const model = R"(import "ifs";
import "fractals";
shape d(x, y) over [-0.25, 1.25] × [-0.25, 1.25] = dist((x, y), sierpinski);
shape ring(x, y) over [-0.25, 1.25] × [-0.25, 1.25] = dist((x, y), sierpinski) - 0.02;
shape fused(x, y) over [0, 1] × [0, 1] = dist((x, y), sierpinski) - 0.01 | carpet(x, y);
)";

bool same_bits(double a, double b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
}
bool same_bits(Interval a, Interval b) {
    return same_bits(a.lo, b.lo) && same_bits(a.hi, b.hi);
}

const driver::AttractorDistanceFunction& bound_distance(const Model& m) {
    REQUIRE(m.c->module.graph.externals.size() == 1);
    const auto* f =
        dynamic_cast<const driver::AttractorDistanceFunction*>(m.c->module.graph.externals[0].get());
    REQUIRE(f);
    return *f;
}

std::size_t shape_index(const Model& m, const std::string& name) {
    for (std::size_t i = 0; i < m.c->module.shapes.size(); ++i)
        if (m.shape(i).name == name) return i;
    FAIL("no shape " << name);
    return 0;
}

} // namespace

TEST_CASE("dist is one external function per automaton, bound after lowering", "[llvm][dist]") {
    const Model m = compile(model);
    const auto& f = bound_distance(m);
    CHECK(f.arity() == 2);
    CHECK(f.name() == "dist sierpinski");
    for (const ir::Tape& t : m.tapes) REQUIRE(t.externals.size() == 1);
    const std::string text = ir::print_tape(m.tapes[shape_index(m, "d")]);
    CHECK(text.find("= external") != std::string::npos);
    CHECK(text.find("#0 dist sierpinski") != std::string::npos);
}

TEST_CASE("dist: the engines agree bit for bit on points, boxes and batches", "[llvm][dist]") {
    const Model m = compile(model);
    BoxMaker make(20261202);
    for (std::size_t i = 0; i < m.tapes.size(); ++i) {
        INFO("shape " << m.shape(i).name);
        auto in = InterpEngine::make(m.tapes[i]);
        auto jt = JitEngine::make(m.tapes[i]);
        std::vector<Interval> boxes;
        std::vector<double> points;
        for (int k = 0; k < 64; ++k) {
            const double w = std::ldexp(1.0, -make.pick(12));
            for (int a = 0; a < 2; ++a) {
                const double lo = make.uniform(-0.3, 1.3);
                boxes.push_back({lo, lo + w});
                points.push_back(make.uniform(-0.3, 1.3));
            }
        }
        for (std::size_t k = 0; k < 64; ++k) {
            const Interval bi = in->eval_box(&boxes[2 * k]), bj = jt->eval_box(&boxes[2 * k]);
            CHECK(same_bits(bi, bj));
            const double pi = in->eval_point(&points[2 * k]), pj = jt->eval_point(&points[2 * k]);
            CHECK(same_bits(pi, pj));
        }
        std::vector<Interval> oi(64), oj(64);
        in->eval_boxes(boxes.data(), 64, oi.data());
        jt->eval_boxes(boxes.data(), 64, oj.data());
        std::vector<double> pi(64), pj(64);
        in->eval_points(points.data(), 64, pi.data());
        jt->eval_points(points.data(), 64, pj.data());
        for (std::size_t k = 0; k < 64; ++k) {
            CHECK(same_bits(oi[k], oj[k]));
            CHECK(same_bits(oi[k], in->eval_box(&boxes[2 * k])));
            CHECK(same_bits(pi[k], pj[k]));
        }
    }
}

TEST_CASE("dist: enclosures contain the brute-force distance of eq. (2)", "[llvm][dist]") {
    const Model m = compile(model);
    const rt::AttractorDistance& exact = bound_distance(m).distance();
    const int level = exact.brute_force_level(1e-3);
    REQUIRE(level > 0);
    const std::size_t d = shape_index(m, "d");
    BoxMaker make(7);
    for (auto engine : {0, 1}) {
        auto f = engine == 0 ? InterpEngine::make(m.tapes[d]) : JitEngine::make(m.tapes[d]);
        for (int k = 0; k < 40; ++k) {
            const double w = std::ldexp(1.0, -make.pick(10));
            const double x0 = make.uniform(-0.2, 1.2), y0 = make.uniform(-0.2, 1.2);
            const Interval box[2] = {{x0, x0 + w}, {y0, y0 + w}};
            const Interval enc = f->eval_box(box);
            for (int s = 0; s < 3; ++s) {
                const double p[2] = {make.uniform(x0, x0 + w), make.uniform(y0, y0 + w)};
                const rt::BruteForceResult b = exact.brute_force(p, level);
                INFO(engine << ": box [" << x0 << ", " << x0 + w << "] x [" << y0 << ", " << y0 + w
                            << "], p (" << p[0] << ", " << p[1] << "), brute force " << b.estimate << " +- "
                            << b.error << ", enclosure [" << enc.lo << ", " << enc.hi << "]");
                const double slack = b.error + 1e-9;
                CHECK(enc.lo <= b.estimate + slack);
                CHECK(enc.hi >= b.estimate - slack);
                // The point value is the midpoint of an enclosure of width <= 1e-6.
                CHECK(std::fabs(f->eval_point(p) - b.estimate) <= slack + 1e-6);
            }
        }
    }
}

TEST_CASE("dist: an RSS cover of dist(p, A) - r holds every chaos-game point", "[llvm][dist]") {
    const Model m = compile(model);
    const std::size_t ring = shape_index(m, "ring");
    const ir::Automaton& a = m.c->module.find_automaton("sierpinski")->automaton;
    std::vector<std::array<double, 2>> points;
    rt::chaos_points(a, 20000, 100, 42, [&](const std::vector<double>& p) {
        points.push_back({p[0], p[1]});
    });
    REQUIRE(points.size() == 20000);
    rt::RssOptions o;
    o.depth = 7;
    std::vector<rt::RssResult> covers;
    for (auto engine : {0, 1}) {
        auto f = engine == 0 ? InterpEngine::make(m.tapes[ring]) : JitEngine::make(m.tapes[ring]);
        covers.push_back(rt::subdivide(*f, m.shape(ring).box, o));
    }
    CHECK(rt::same_cover(covers[0], covers[1]));
    for (const rt::RssResult& cover : covers) {
        REQUIRE(cover.boundary > 0);
        REQUIRE(cover.outside > 0);
        // Outside cells by position; a point must lie in none (cells overlap where they touch: look at
        // the neighbours too).
        std::map<std::tuple<int, std::uint32_t, std::uint32_t>, const rt::Cell*> outside;
        for (const rt::Cell& c : cover.cells)
            if (c.cls == rt::CellClass::outside) outside[{c.level, c.ix, c.iy}] = &c;
        std::size_t misses = 0;
        for (const auto& p : points) {
            for (int level = 0; level <= cover.depth; ++level) {
                const double n = static_cast<double>(cover.cells_per_axis(level));
                const auto cell_of = [&](int axis) {
                    const Interval r = cover.root[static_cast<std::size_t>(axis)];
                    return static_cast<long>(
                        std::floor((p[static_cast<std::size_t>(axis)] - r.lo) / (r.hi - r.lo) * n));
                };
                const long cx = cell_of(0), cy = cell_of(1);
                for (long ix = cx - 1; ix <= cx + 1; ++ix)
                    for (long iy = cy - 1; iy <= cy + 1; ++iy) {
                        if (ix < 0 || iy < 0) continue;
                        auto it = outside.find(
                            {level, static_cast<std::uint32_t>(ix), static_cast<std::uint32_t>(iy)});
                        if (it == outside.end()) continue;
                        const Interval bx = cover.cell_interval(*it->second, 0),
                                       by = cover.cell_interval(*it->second, 1);
                        if (bx.lo <= p[0] && p[0] <= bx.hi && by.lo <= p[1] && p[1] <= by.hi) ++misses;
                    }
            }
        }
        CHECK(misses == 0);
    }
}

TEST_CASE("dist: compiled models embed the automaton and resolve it at the first call", "[llvm][dist]") {
    const Model m = compile(model);
    const std::size_t ring = shape_index(m, "ring");
    const auto& f = bound_distance(m);
    const std::optional<ir::ExternalFunction::Compiled> c = f.compiled();
    REQUIRE(c);
    CHECK(c->archive == "libfrac_aot_automata.a");
    jit::AotShape s{"ring", m.tapes[ring], m.shape(ring).box};
    CHECK(jit::external_archives({s}) == std::vector<std::string>{"libfrac_aot_automata.a"});
    const std::string ll = "/tmp/frac_test_dist_embedded.ll";
    jit::compile_aot({s}, jit::AotConfig{}, "", ll);
    std::ifstream in(ll);
    const std::string ir_text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    CHECK(ir_text.find("@frac_aot_attractor_distance(ptr") != std::string::npos);
    CHECK(ir_text.find("@frac_aot_attractor_distance_release(ptr") != std::string::npos);
    CHECK(ir_text.find("@llvm.global_dtors") != std::string::npos);
    std::remove(ll.c_str());

    // The C entry points on the embedded data: the same function, built once, then freed.
    ir::ExternalData record{nullptr, c->data.size(), c->data.data()};
    const ir::ExternalFunction* rebuilt = frac_aot_attractor_distance(&record);
    REQUIRE(rebuilt);
    CHECK(frac_aot_attractor_distance(&record) == rebuilt);
    CHECK(rebuilt->name() == "dist sierpinski");
    const Interval box[2] = {{0.3, 0.4}, {0.6, 0.65}};
    CHECK(same_bits(rebuilt->eval_box(box), f.eval_box(box)));
    const double p[2] = {0.5, 0.5};
    CHECK(same_bits(rebuilt->eval_point(p), f.eval_point(p)));
    frac_aot_attractor_distance_release(&record);
    CHECK(record.function == nullptr);

    // Malformed data (truncated, or a byte changed in the format tag) rebuilds nothing.
    for (std::size_t size : {std::size_t(0), std::size_t(7), c->data.size() - 1}) {
        ir::ExternalData cut{nullptr, size, c->data.data()};
        CHECK(frac_aot_attractor_distance(&cut) == nullptr);
    }
    std::vector<std::uint8_t> bad = c->data;
    bad[8 + std::string("sierpinski").size()] ^= 1;
    ir::ExternalData wrong{nullptr, bad.size(), bad.data()};
    CHECK(frac_aot_attractor_distance(&wrong) == nullptr);
}

TEST_CASE("dist: an external function without a compiled form is refused by frac compile", "[llvm][dist]") {
    class Opaque final : public ir::ExternalFunction {
    public:
        int arity() const override { return 2; }
        num::Interval eval_box(const num::Interval*) const override { return {0, 1}; }
        double eval_point(const double*) const override { return 0.5; }
        std::string name() const override { return "opaque"; }
    };
    Model m = compile(model);
    const std::size_t ring = shape_index(m, "ring");
    jit::AotShape s{"ring", m.tapes[ring], m.shape(ring).box};
    s.tape.externals[0] = std::make_shared<Opaque>();
    REQUIRE_THROWS_WITH(jit::compile_aot({s}, jit::AotConfig{}, "", ""),
                        Catch::Contains("shape 'ring' calls opaque, which compiled models cannot carry"));
}
