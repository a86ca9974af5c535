// Branch-and-bound distance to attractors (seed 000 sec. 2.3) against an independent reference.
#include "attractor_systems.hpp"
#include "runtime/automata/distance.hpp"
#include "runtime/rss.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <set>
#include <thread>
#include <tuple>

using namespace frac;
using rt::test::reference_distance;

namespace {

struct System {
    const char* name;
    ir::Automaton a;
    double lo, hi; // square of test points
    // Accuracy of the reference. The fern's slow contraction (0.85) makes the reference search
    // (no witnesses at inner nodes until leaves) cost millions of nodes below 1e-5, so it is checked
    // to 1e-4 there, to 1e-9 elsewhere.
    double tol;
};

std::vector<System> systems() {
    return {{"sierpinski", rt::test::sierpinski(), -0.5, 1.5, 1e-9},
            {"fern", rt::test::fern(), -3, 3, 1e-4},
            {"koch", rt::test::koch(), -0.3, 1.3, 1e-9},
            {"two_state", rt::test::two_state(), -0.5, 1.5, 1e-9}};
}

// Epsilon no finer than the reference's accuracy.
rt::AttractorDistance distance_for(const System& s) {
    rt::DistanceOptions o;
    o.epsilon = std::max(s.tol, 1e-6);
    return rt::AttractorDistance(s.a, o);
}

} // namespace

TEST_CASE("bounding balls and witnesses are found for every state", "[distance]") {
    for (const System& s : systems()) {
        INFO(s.name);
        const std::vector<rt::StateBall> balls = rt::bounding_balls(s.a);
        REQUIRE(balls.size() == s.a.states.size());
        for (const rt::StateBall& b : balls) {
            CHECK(b.radius > 0);
            CHECK(b.witness_radius >= 0);
            CHECK(b.witness_radius <= b.radius);
        }
        // Points of the initial attractor: images of the witness; each must be in the initial ball.
        rt::AttractorDistance dist(s.a);
        const rt::BruteForceResult bf = dist.brute_force(balls[s.a.initial].centre.data(), 6);
        CHECK(bf.leaves > 0);
        // The bounding box holds points of the attractor (an orbit under the initial state's loops).
        const std::vector<num::Interval> box = dist.bounding_box();
        REQUIRE(box.size() == 2);
        double x = 0, y = 0;
        for (int i = 0; i < 5000; ++i) { // a chaos game on the initial state's self-loops
            const ir::Arc& arc = s.a.arcs[static_cast<std::size_t>(i * 7919) % s.a.arcs.size()];
            if (arc.from != s.a.initial || arc.to != s.a.initial) continue;
            const auto& m = arc.op.nearest;
            const double nx = m(0, 0) * x + m(0, 1) * y + m(0, 2), ny = m(1, 0) * x + m(1, 1) * y + m(1, 2);
            x = nx, y = ny;
            if (i > 50) CHECK((box[0].contains(x) && box[1].contains(y)));
        }
    }
}

TEST_CASE("distance enclosures contain the reference distance at random points", "[distance]") {
    std::mt19937_64 rng(7);
    for (const System& s : systems()) {
        INFO(s.name);
        const rt::AttractorDistance dist = distance_for(s);
        std::uniform_real_distribution<double> u(s.lo, s.hi);
        for (int i = 0; i < 25; ++i) {
            const double p[2] = {u(rng), u(rng)};
            INFO(p[0] << ", " << p[1]);
            const rt::DistanceResult r = dist.query(std::vector<num::Interval>{p[0], p[1]}.data());
            const double ref = reference_distance(s.a, p[0], p[1], s.tol);
            CHECK(r.converged);
            CHECK(r.distance.lo <= ref + s.tol);
            CHECK(r.distance.hi >= ref - s.tol);
            CHECK(r.distance.hi - r.distance.lo <= dist.options().epsilon * 1.001);
            CHECK(r.distance.lo >= 0);
        }
    }
}

TEST_CASE("box enclosures contain the reference distance of points of the box", "[distance]") {
    std::mt19937_64 rng(11);
    for (const System& s : systems()) {
        INFO(s.name);
        const rt::AttractorDistance dist = distance_for(s);
        std::uniform_real_distribution<double> u(s.lo, s.hi), w(0.0, 0.2), t(0.0, 1.0);
        for (int i = 0; i < 8; ++i) {
            const double x0 = u(rng), y0 = u(rng), wx = w(rng), wy = w(rng);
            const num::Interval box[2] = {{x0, x0 + wx}, {y0, y0 + wy}};
            const num::Interval e = dist.eval_box(box);
            double lo = 1e300, hi = 0;
            for (int k = 0; k < 7; ++k) {
                const double fx = k < 4    ? (k & 1)
                                  : k == 4 ? 0.5
                                           : t(rng),
                             fy = k < 4    ? (k >> 1)
                                  : k == 4 ? 0.5
                                           : t(rng);
                const double ref = reference_distance(s.a, x0 + fx * wx, y0 + fy * wy, s.tol);
                lo = std::min(lo, ref), hi = std::max(hi, ref);
            }
            INFO("box " << x0 << " " << y0 << " " << wx << " " << wy << " -> [" << e.lo << ", " << e.hi
                        << "]");
            CHECK(e.lo <= lo + s.tol);
            CHECK(e.hi >= hi - s.tol);
            // Not vacuous: within the box's diagonal of the sampled range.
            const double diag = std::hypot(wx, wy);
            CHECK(e.lo >= lo - diag - 2 * s.tol - 1e-6);
            CHECK(e.hi <= hi + diag + 2 * s.tol + 1e-6);
        }
    }
}

TEST_CASE("points on the attractor have lower bound 0", "[distance]") {
    rt::DistanceOptions o;
    o.epsilon = 1e-7;
    const rt::AttractorDistance dist(rt::test::sierpinski(), o);
    // Dyadic points of the triangle's edges and of inner edges are on the attractor.
    for (auto [x, y] :
         {std::pair{0.0, 0.0}, {1.0, 0.0}, {0.25, 0.0}, {0.5, 0.5}, {0.25, 0.25}, {0.375, 0.125}}) {
        const double p[2] = {x, y};
        const num::Interval e = dist.eval_point(p);
        INFO(x << ", " << y << " -> [" << e.lo << ", " << e.hi << "]");
        CHECK(e.lo == 0);
        CHECK(e.hi <= 1e-7);
    }
    // Points of the fern from its own maps (fixed point of f2 composed with f3), within rounding.
    const ir::Automaton fern = rt::test::fern();
    const rt::AttractorDistance fd(fern, o);
    double x = 0, y = 0;
    for (int i = 0; i < 2000; ++i) { // a chaos-game stream, deterministic order
        const auto& n =
            fern.arcs[static_cast<std::size_t>(1 + (i * 7 % 11 == 0 ? 1 : 0) + (i % 13 == 0 ? 1 : 0))]
                .op.nearest;
        const double nx = n(0, 0) * x + n(0, 1) * y + n(0, 2), ny = n(1, 0) * x + n(1, 1) * y + n(1, 2);
        x = nx, y = ny;
        if (i % 400 == 399) {
            const double p[2] = {x, y};
            const num::Interval e = fd.eval_point(p);
            CHECK(e.lo <= 1e-12);
            CHECK(e.hi <= 1e-7);
        }
    }
}

TEST_CASE("a barycentric state with a projection gives the euclidean system's distances", "[distance]") {
    const rt::AttractorDistance bary(rt::test::sierpinski_bary());
    const rt::AttractorDistance eucl(rt::test::sierpinski());
    CHECK(bary.dimension() == 2);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-0.5, 1.5);
    for (int i = 0; i < 30; ++i) {
        const double p[2] = {u(rng), u(rng)};
        const num::Interval a = bary.eval_point(p), b = eucl.eval_point(p);
        CHECK(a.lo <= b.hi);
        CHECK(b.lo <= a.hi);
        CHECK(a.hi - a.lo <= 1e-6 * 1.001);
    }
}

TEST_CASE("the widths reach epsilon; a small node budget leaves a wider but proven interval", "[distance]") {
    const ir::Automaton fern = rt::test::fern();
    const double p[2] = {1.0, 5.0};
    const double ref = reference_distance(fern, p[0], p[1], 1e-4);
    for (double eps : {1e-2, 1e-4, 1e-8}) {
        rt::DistanceOptions o;
        o.epsilon = eps;
        const rt::DistanceResult r =
            rt::AttractorDistance(fern, o).query(std::vector<num::Interval>{1.0, 5.0}.data());
        CHECK(r.converged);
        CHECK(r.distance.hi - r.distance.lo <= eps * 1.001);
        CHECK(r.distance.lo <= ref + 1e-4);
        CHECK(r.distance.hi >= ref - 1e-4);
    }
    rt::DistanceOptions o;
    o.epsilon = 1e-9;
    o.max_nodes = 5;
    const rt::DistanceResult r =
        rt::AttractorDistance(fern, o).query(std::vector<num::Interval>{1.0, 5.0}.data());
    CHECK_FALSE(r.converged);
    CHECK(r.nodes <= 5);
    CHECK(r.distance.lo <= ref + 1e-4);
    CHECK(r.distance.hi >= ref - 1e-4);
}

TEST_CASE("eq. 2 brute force agrees with branch and bound within its error", "[distance]") {
    const ir::Automaton sier = rt::test::sierpinski();
    const rt::AttractorDistance dist(sier);
    const int level = dist.brute_force_level(1e-3);
    CHECK(level > 5);
    CHECK(level < 14);
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(-0.5, 1.5);
    for (int i = 0; i < 5; ++i) {
        const double p[2] = {u(rng), u(rng)};
        const rt::BruteForceResult bf = dist.brute_force(p, level);
        CHECK(bf.error <= 1e-3);
        CHECK(bf.leaves == static_cast<std::uint64_t>(std::pow(3, level)));
        const num::Interval e = dist.eval_point(p);
        CHECK(bf.estimate - bf.error <= e.hi);
        CHECK(bf.estimate + bf.error >= e.lo);
    }
}

TEST_CASE("bad automata give clear errors, odd queries safe answers", "[distance]") {
    // Expanding map: no bounding ball.
    ir::Automaton big =
        rt::test::ifs("big", {rt::test::affine2(2, 0, 0, 2, 0, 0),
                              rt::test::affine2(num::Rational(1, 2), 0, 0, num::Rational(1, 2), 1, 0)});
    CHECK_THROWS_WITH(rt::AttractorDistance(big), Catch::Contains("contract"));
    // A state without arcs: empty attractor.
    ir::Automaton empty;
    empty.name = "empty";
    empty.states.push_back({"s", ir::Space::euclidean(2), {}});
    CHECK_THROWS_WITH(rt::AttractorDistance(empty), Catch::Contains("empty"));
    // A non-affine operator.
    ir::Automaton bad = rt::test::ifs(
        "bad", {ir::Operator::from_exact(num::Matrix<num::Rational>{{1, 0, 0}, {0, 1, 0}, {1, 0, 1}})});
    CHECK_THROWS_WITH(rt::AttractorDistance(bad), Catch::Contains("affine"));
    rt::DistanceOptions o;
    o.epsilon = 0;
    CHECK_THROWS_AS(rt::AttractorDistance(rt::test::sierpinski(), o), std::invalid_argument);
    // Odd queries: NaN or infinite coordinates give [0, inf], an empty box gives empty.
    const rt::AttractorDistance d(rt::test::sierpinski());
    const double nan_point[2] = {std::nan(""), 0.5};
    CHECK(d.eval_point(nan_point) == num::Interval(0.0, num::inf));
    const num::Interval wide[2] = {{0, num::inf}, {0, 1}}, none[2] = {num::Interval::empty(), {0, 1}};
    CHECK(d.eval_box(wide) == num::Interval(0.0, num::inf));
    CHECK(d.eval_box(none).is_empty());
}

TEST_CASE("far points: tight enclosures up to the largest double and beyond", "[distance]") {
    // The Sierpinski triangle lies in the unit square, so the distance from p lies within sqrt(2) of
    // |p|. Far points once had squares overflowing: [1.3e154, inf] from 1e160 away.
    const rt::AttractorDistance d(rt::test::sierpinski());
    const long double reach = std::sqrt(2.0L);
    const double directions[][2] = {{1, 0}, {0, -1}, {-0.6, 0.8}, {0.3, 0.4}};
    for (int k = 0; k <= 1023; k += 11)
        for (const auto& u : directions) {
            const double p[2] = {std::ldexp(u[0], k), std::ldexp(u[1], k)};
            const long double norm =
                std::hypot(static_cast<long double>(p[0]), static_cast<long double>(p[1]));
            INFO("2^" << k << " (" << u[0] << ", " << u[1] << ")");
            const num::Interval e = d.eval_point(p);
            CHECK(e.lo <= norm + reach);
            CHECK(e.hi >= norm - reach);
            CHECK(e.hi - e.lo <= 1e-12 * static_cast<double>(norm) + 1e-5);
            // Past 2^40 the search stops within a few ulps of the distance: epsilon (1e-6) is below
            // the rounding there, and such queries ran to the node budget. (Nearer, from below the
            // triangle, the whole lower edge lies within epsilon of the nearest distance: the search
            // may end at the budget, its result still proven.)
            const num::Interval box[2] = {num::Interval(p[0]), num::Interval(p[1])};
            if (k >= 40) CHECK(d.query(box).converged);
        }
    // Past the largest double: from the largest double (to a rounding) to infinity.
    const double beyond[2] = {1.5e308, -1.5e308};
    const num::Interval e = d.eval_point(beyond);
    CHECK(e.lo >= std::nextafter(std::numeric_limits<double>::max(), 0.0) / (1 + 1e-15));
    CHECK(e.hi == num::inf);
}

TEST_CASE("distances in R4 through the library", "[distance]") {
    // The language has spaces up to R3, the library any: the segment from 0 to (1, 0, 0, 0) as the
    // attractor of x / 2 and x / 2 + (1/2, 0, 0, 0).
    ir::Automaton segment;
    segment.name = "segment";
    segment.states.push_back({"s", ir::Space::euclidean(4), {}});
    for (int k = 0; k < 2; ++k) {
        num::Matrix<num::Rational> m(5, 5);
        for (std::size_t i = 0; i < 4; ++i) m(i, i) = num::Rational(1, 2);
        m(4, 4) = 1;
        m(0, 4) = num::Rational(k, 2);
        segment.arcs.push_back({0, 0, ir::Operator::from_exact(m), std::nullopt, ""});
    }
    const rt::AttractorDistance d(segment);
    const double p[4] = {3, 0, 0, 4}; // nearest point (1, 0, 0, 0)
    const num::Interval e = d.eval_point(p);
    CHECK(e.lo <= std::sqrt(20.0));
    CHECK(e.hi >= std::sqrt(20.0));
    CHECK(e.hi - e.lo <= 2e-6);
}

TEST_CASE("distances in R3 and from several threads", "[distance]") {
    rt::DistanceOptions o;
    o.epsilon = 1e-8;
    const rt::AttractorDistance dist(rt::test::tetrahedron(), o);
    CHECK(dist.dimension() == 3);
    const double origin[3] = {0, 0, 0}, out[3] = {-1, -1, -1}, mid[3] = {0.5, 0.5, 0};
    CHECK(dist.eval_point(origin).lo == 0);
    CHECK(dist.eval_point(mid).lo == 0);
    // The nearest point is the vertex 0 (the attractor lies in the positive octant). A point facing a
    // face instead would need ever more nodes: every node within epsilon of the distance is refined.
    const num::Interval e = dist.eval_point(out);
    CHECK(e.lo <= std::sqrt(3.0));
    CHECK(e.hi >= std::sqrt(3.0));
    CHECK(e.hi - e.lo <= 1e-8 * 1.001);

    // One const object queried from two threads gives the answers of one thread.
    rt::DistanceOptions fo;
    fo.epsilon = 1e-4;
    const rt::AttractorDistance fern(rt::test::fern(), fo);
    std::vector<std::array<double, 2>> ps;
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<double> u(-3, 3);
    for (int i = 0; i < 60; ++i) ps.push_back({u(rng), u(rng) + 4});
    std::vector<num::Interval> serial, a(ps.size()), b(ps.size());
    for (const auto& p : ps) serial.push_back(fern.eval_point(p.data()));
    std::thread t1([&] {
        for (std::size_t i = 0; i < ps.size(); ++i) a[i] = fern.eval_point(ps[i].data());
    });
    std::thread t2([&] {
        for (std::size_t i = ps.size(); i-- > 0;) b[i] = fern.eval_point(ps[i].data());
    });
    t1.join(), t2.join();
    CHECK(a == serial);
    CHECK(b == serial);
}

namespace {

// dist(p, A) - r as an evaluator, the way an expression engine would call the runtime.
class Thickened : public ir::Evaluator {
public:
    Thickened(std::shared_ptr<const rt::AttractorDistance> d, double r) : d_(std::move(d)), r_(r) {}
    int dimension() const override { return d_->dimension(); }
    std::string engine() const override { return "test"; }
    double eval_point(const double* p) override { return num::midpoint(d_->eval_point(p)) - r_; }
    num::Interval eval_box(const num::Interval* box) override {
        const num::Interval e = d_->eval_box(box);
        num::UpwardRounding up;
        return num::sub(e, num::Interval(r_));
    }
    std::unique_ptr<Evaluator> clone() const override { return std::make_unique<Thickened>(*this); }

private:
    std::shared_ptr<const rt::AttractorDistance> d_;
    double r_;
};

} // namespace

TEST_CASE("a subdivision of dist(p, A) - r never puts a chaos-game point outside", "[distance]") {
    const ir::Automaton s = rt::test::sierpinski();
    rt::DistanceOptions o;
    o.epsilon = 1e-4;
    Thickened f(std::make_shared<const rt::AttractorDistance>(s, o), 0.01);
    rt::RssOptions ro;
    ro.depth = 7;
    const rt::RssResult cover = rt::subdivide(f, {{-0.25, 1.25}, {-0.25, 1.25}}, ro);
    CHECK(cover.inside > 0);
    CHECK(cover.outside > 0);
    std::set<std::tuple<int, std::uint32_t, std::uint32_t>> outside;
    for (const rt::Cell& c : cover.cells)
        if (c.cls == rt::CellClass::outside) outside.insert({c.level, c.ix, c.iy});
    std::mt19937_64 rng(8);
    double x = 0.2, y = 0.2;
    std::size_t wrong = 0;
    for (int i = 0; i < 20000; ++i) {
        const auto& m = s.arcs[rng() % 3].op.nearest;
        x = m(0, 0) * x + m(0, 2), y = m(1, 1) * y + m(1, 2);
        if (i < 20) continue;
        for (int level = 0; level <= ro.depth; ++level) {
            const double n = static_cast<double>(cover.cells_per_axis(level));
            const auto ix = static_cast<std::uint32_t>(std::floor((x + 0.25) / 1.5 * n));
            const auto iy = static_cast<std::uint32_t>(std::floor((y + 0.25) / 1.5 * n));
            if (outside.count({level, ix, iy})) ++wrong;
        }
    }
    CHECK(wrong == 0);
}

TEST_CASE("distance to the Cantor set in R1", "[distance]") {
    ir::Automaton cantor;
    cantor.name = "cantor";
    cantor.states.push_back({"c", ir::Space::euclidean(1), {}});
    for (int k : {0, 2})
        cantor.arcs.push_back({0, 0,
                               ir::Operator::from_exact(num::Matrix<num::Rational>{
                                   {num::Rational(1, 3), num::Rational(k, 3)}, {0, 1}}),
                               std::nullopt, ""});
    rt::DistanceOptions o;
    o.epsilon = 1e-9;
    const rt::AttractorDistance dist(cantor, o);
    CHECK(dist.dimension() == 1);
    // The middle third's centre is 1/6 from 1/3 and 2/3; 1/4 is in the set (0.0202... in base 3).
    const double half = 0.5, quarter = 0.25, left = -1;
    const num::Interval a = dist.eval_point(&half), b = dist.eval_point(&quarter), c = dist.eval_point(&left);
    CHECK(a.lo <= 1.0 / 6 + 1e-15);
    CHECK(a.hi >= 1.0 / 6 - 1e-15);
    CHECK(a.hi - a.lo <= 1e-9);
    CHECK(b.lo == 0);
    CHECK(b.hi <= 1e-9);
    CHECK(c.contains(1.0));
    const num::Interval box{0.4, 0.45}; // min 1/3 away: 0.4 - 1/3; max 0.45 - 1/3
    const num::Interval e = dist.eval_box(&box);
    CHECK(e.lo <= 0.4 - 1.0 / 3);
    CHECK(e.hi >= 0.45 - 1.0 / 3);
}

TEST_CASE("bounding balls are found at every scale, and hold the attractor", "[distance]") {
    // {x/2 + t, x/2} on the x axis: the attractor is the segment [0, 2t], within 2t of any of its points.
    // Translations from 1e-300 to 1e-15 and from 1e160 up were refused as "not contracting".
    for (const double t :
         {1e-300, 1e-200, 1e-100, 1e-16, 1e-15, 1e-12, 1.0, 1e12, 1e100, 1e160, 1e200, 1e300}) {
        INFO("translation " << t);
        const num::Rational half(1, 2), tr = num::Rational::from_double(t);
        const ir::Automaton z = rt::test::ifs(
            "z", {rt::test::affine2(half, 0, 0, half, tr, 0), rt::test::affine2(half, 0, 0, half, 0, 0)});
        const std::vector<rt::StateBall> balls = rt::bounding_balls(z);
        REQUIRE(balls.size() == 1);
        const rt::StateBall& b = balls[0];
        REQUIRE(std::isfinite(b.radius));
        // Both ends of the segment lie in the ball (the distance from the centre, rounded up)...
        for (const double x : {0.0, 2 * t}) {
            const double dx = std::fabs(x - b.centre[0]), dy = std::fabs(b.centre[1]);
            const double far = std::max(dx, dy), near = std::min(dx, dy);
            CHECK(far * (1 + 1e-15) * std::sqrt(1 + (near / far) * (near / far)) <= b.radius);
        }
        // ... and the ball is not much larger than the segment.
        CHECK(b.radius <= 4 * t);
    }
    // Maps that do not contract keep their message.
    const num::Rational two(2), half(1, 2);
    const ir::Automaton grows =
        rt::test::ifs("grows", {rt::test::affine2(two, 0, 0, two, num::Rational::from_double(1e-16), 0),
                                rt::test::affine2(half, 0, 0, half, 0, 0)});
    CHECK_THROWS_WITH(rt::bounding_balls(grows),
                      Catch::Contains("its operators do not contract in the euclidean norm"));
}
