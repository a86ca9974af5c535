#include "backend/interp/interpreter.hpp"
#include "driver/pipeline.hpp"
#include "ir/tape.hpp"

#include <catch2/catch.hpp>
#include <cmath>

using namespace frac;

namespace {

struct Shape {
    std::unique_ptr<front::Compilation> c;
    std::unique_ptr<ir::Evaluator> eval;
};

Shape shape(const std::string& text, const std::string& name = "s", ir::EvalOptions options = {}) {
    Shape s;
    s.c = driver::compile_source("t.frac", text);
    if (!s.c->ok()) FAIL(s.c->diags.render(s.c->sources));
    const front::ShapeInfo* info = s.c->module.find_shape(name);
    REQUIRE(info);
    s.eval =
        interp::make_interpreter(ir::build_tape(s.c->module.graph, info->root, info->dimension), options);
    return s;
}

ir::Interval box_eval(ir::Evaluator& e, ir::Interval x, ir::Interval y) {
    const ir::Interval b[2] = {x, y};
    return e.eval_box(b);
}

double takagi_reference(double x) {
    double s = 0, p = 1;
    for (int i = 0; i < 60; ++i, p *= 2) s += std::fabs(p * x - std::nearbyint(p * x)) / p;
    return s;
}

} // namespace

TEST_CASE("point and box evaluation of plain expressions", "[interp]") {
    auto s = shape("shape s(x, y) = x * x + y * y - 1;");
    const double p[2] = {0.5, 0.5};
    CHECK(s.eval->eval_point(p) == Approx(-0.5));
    const ir::Interval r = box_eval(*s.eval, {0, 1}, {0, 1});
    CHECK(r.lo <= -1.0);
    CHECK(r.hi >= 1.0);
    CHECK(s.eval->dimension() == 2);
    CHECK(s.eval->engine() == "interp");
}

TEST_CASE("Takagi series: point value and proven enclosure", "[interp][series]") {
    auto s = shape("shape s(x, y) = y - sum(i in 0.., dz(2^i * x) / 2^i);");
    for (double x : {0.1, 0.3, 1.0 / 3.0, 0.77}) {
        const double p[2] = {x, 0.0};
        const double t = takagi_reference(x);
        CHECK(-s.eval->eval_point(p) == Approx(t).epsilon(1e-14));
        const ir::Interval e = box_eval(*s.eval, ir::Interval(x), ir::Interval(0.0));
        CHECK(e.contains(-t));
        CHECK(num::width(e) < 1e-12);
    }
}

TEST_CASE("wide boxes are not charged for terms they cannot resolve", "[interp][series]") {
    auto s = shape("shape s(x, y) = min(i in 0.., (1/3 - min(dz(3^i * x), dz(3^i * y))) / 3^i);");
    s.eval->stats = {};
    box_eval(*s.eval, {0.1, 0.1 + 1.0 / 64}, {0.2, 0.2 + 1.0 / 64});
    const auto wide_terms = s.eval->stats.series_terms;
    s.eval->stats = {};
    box_eval(*s.eval, {0.1, 0.1 + 1e-9}, {0.2, 0.2 + 1e-9});
    const auto narrow_terms = s.eval->stats.series_terms;
    CHECK(wide_terms <= 6); // 3^i / 64 >= 1 from i = 4 on
    CHECK(narrow_terms > wide_terms);
    CHECK(s.eval->stats.series_capped == 0);
}

TEST_CASE("the carpet: holes are proven inside, the carpet is never proven", "[interp][series]") {
    auto s = shape("shape s(x, y) = min(i in 0.., (1/3 - min(dz(3^i * x), dz(3^i * y))) / 3^i);");
    CHECK(box_eval(*s.eval, {0.4, 0.6}, {0.4, 0.6}).hi < 0);   // central hole
    CHECK(box_eval(*s.eval, {0.13, 0.2}, {0.13, 0.2}).hi < 0); // a second-level hole
    const ir::Interval on =
        box_eval(*s.eval, {0.0, 0.01}, {0.0, 0.01}); // contains the corner (on the carpet)
    CHECK(on.lo < 0);
    CHECK(on.hi >= 0);
}

TEST_CASE("the devil's staircase tail with linear growth is sound", "[interp][series]") {
    auto s = shape("shape s(x, y) = y - sum(i in 1.., floor(i * x) / 2^i);");
    // E(1) = sum i / 2^i = 2
    const ir::Interval at1 = box_eval(*s.eval, ir::Interval(1.0), ir::Interval(0.0));
    CHECK(at1.contains(-2.0));
    // Over a wide box the enclosure must contain E at sampled points.
    const ir::Interval wide = box_eval(*s.eval, {0.2, 0.7}, ir::Interval(0.0));
    for (double x = 0.2; x <= 0.7; x += 0.01) {
        double e = 0, p = 2;
        for (int i = 1; i < 80; ++i, p *= 2) e += std::floor(i * x) / p;
        CHECK(wide.contains(-e));
    }
}

TEST_CASE("three-valued if takes the hull of both branches when undecided", "[interp]") {
    auto s = shape("shape s(x, y) = if x < 0.5 then 1 else 2;");
    CHECK(box_eval(*s.eval, {0, 0.25}, {0, 1}) == ir::Interval(1.0));
    CHECK(box_eval(*s.eval, {0.75, 1}, {0, 1}) == ir::Interval(2.0));
    CHECK(box_eval(*s.eval, {0.25, 0.75}, {0, 1}) == ir::Interval(1.0, 2.0));
}

TEST_CASE("the term limit caps slow series soundly", "[interp][series]") {
    ir::EvalOptions few;
    few.max_terms = 3;
    auto s = shape("shape s(x, y) = y - sum(i in 0.., dz(2^i * x) / 2^i);", "s", few);
    const ir::Interval e = box_eval(*s.eval, ir::Interval(0.3), ir::Interval(0.0));
    CHECK(e.contains(-takagi_reference(0.3)));
    CHECK(num::width(e) > 0.01);
    CHECK(s.eval->stats.series_capped == 1);
}

TEST_CASE("batches give the same results as single calls", "[interp]") {
    auto s = shape("shape s(x, y) = sin(3 * x) * cos(2 * y) - dz(x * y);");
    std::vector<ir::Interval> boxes;
    for (int i = 0; i < 20; ++i) {
        boxes.push_back({0.1 * i, 0.1 * i + 0.05});
        boxes.push_back({-0.1 * i, -0.1 * i + 0.2});
    }
    std::vector<ir::Interval> out(20);
    s.eval->eval_boxes(boxes.data(), 20, out.data());
    for (int i = 0; i < 20; ++i)
        CHECK(out[static_cast<std::size_t>(i)] == s.eval->eval_box(&boxes[2 * static_cast<std::size_t>(i)]));
    auto copy = s.eval->clone();
    CHECK(copy->eval_box(boxes.data()) == out[0]);
}
