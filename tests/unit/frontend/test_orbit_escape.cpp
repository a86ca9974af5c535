// Escape certificates of orbit series: what the compiler derives, and what it refuses.
#include "driver/pipeline.hpp"
#include "ir/series_tail.hpp"

#include <catch2/catch.hpp>

using namespace frac;
using namespace frac::front;

namespace {

// The certificate of the series at the root of `shape`, which must have one.
const ir::OrbitEscape& escape_of(const Compilation& c, const char* shape) {
    const ShapeInfo* s = c.module.find_shape(shape);
    REQUIRE(s);
    const ir::OrbitEscape& e = c.module.graph[s->root].series.escape;
    REQUIRE(e.present);
    return e;
}

const ir::Node& root_of(const Compilation& c, const char* shape) {
    const ShapeInfo* s = c.module.find_shape(shape);
    REQUIRE(s);
    return c.module.graph[s->root];
}

std::string errors_of(const std::string& text) {
    auto c = driver::compile_source("t.frac", text);
    return c->diags.render(c->sources);
}

const char* polar_map =
    "fn fold(p) = let rho = sqrt(p.x^2 + p.y^2), phi = pi / 3 * (2 * dz(3 * atan2(abs(p.y), p.x) / "
    "pi / 2 + 1/4) - 1/2) in (3 * rho * cos(phi) - 1, 3 * rho * sin(phi));\n";

} // namespace

TEST_CASE("the Koch map: |M(q)| >= 3|q| - 1 gives the escape radius 1/2", "[escape]") {
    auto c = driver::compile_source("t.frac",
                                    std::string(polar_map) +
                                        "shape s(x, y) = min(k in 0.., p in orbit((x, y), fold) escape 1/2, "
                                        "(sqrt(p.x^2 + p.y^2) - 0.25) / 3^k);");
    REQUIRE(c->ok());
    const ir::Node& n = root_of(*c, "s");
    REQUIRE(n.op == ir::Op::SeriesMin);
    const ir::OrbitEscape& e = n.series.escape;
    REQUIRE(e.present);
    CHECK(e.radius == 0.5);
    CHECK(e.slope == 1.0);
    CHECK(e.offset == 0.0); // 1/2 - 0.25 > 0
    CHECK(e.growth == ir::Interval(3.0));
    CHECK(e.scale0 == ir::Interval(1.0));
    // The fold is 1-Lipschitz (|g'| = 1 up to the rounding of pi / 3 and 3 / pi), so M is 3-Lipschitz
    // and every term 1-Lipschitz in the initial point.
    CHECK(e.lipschitz == 1.0);
    CHECK(e.map_lipschitz >= 3.0);
    CHECK(e.map_lipschitz <= 3.0 * (1 + 1e-14));
}

TEST_CASE("no Lipschitz bound without a continuous fold", "[escape]") {
    // atan2(p.y, p.x) jumps across the negative x axis: the certificate holds, the Lipschitz bound is not
    // claimed.
    auto c =
        driver::compile_source("t.frac", "fn m(p) = let r = sqrt(p.x^2 + p.y^2), f = atan2(p.y, p.x) / 2 in "
                                         "(3 * r * cos(f) - 1, 3 * r * sin(f));\n"
                                         "shape s(x, y) = min(k in 0.., p in orbit((x, y), m) escape 1/2, "
                                         "(sqrt(p.x^2 + p.y^2) - 0.25) / 3^k);");
    REQUIRE(c->ok());
    CHECK(escape_of(*c, "s").lipschitz == 0.0);
}

TEST_CASE("escape bounds: a box outside the ball bounds every later term", "[escape]") {
    ir::OrbitEscape e;
    e.present = true;
    e.radius = 0.5;
    e.slope = 1.0;
    e.growth = ir::Interval(3.0);
    num::UpwardRounding up;
    const ir::Interval out[2] = {{0.7, 0.8}, {-0.1, 0.1}};
    const double b = ir::escape_bound(ir::Op::SeriesMin, e, out, 2, 2); // (|q| - 1/2) / 9 >= 0.2 / 9
    CHECK(b > 0.2 / 9 * (1 - 1e-12));
    CHECK(b <= 0.2 / 9);
    const ir::Interval straddling[2] = {{0.4, 0.8}, {0.0, 0.1}};
    CHECK(ir::escape_bound(ir::Op::SeriesMin, e, straddling, 2, 2) == -num::inf);
    CHECK(ir::escape_bound(ir::Op::SeriesMax, e, out, 2, 2) == -b);
    // Tightening keeps a well-formed tail on both sides.
    CHECK(ir::escape_tighten(ir::Op::SeriesMin, {-1.0, num::inf}, b) == ir::Interval(b, num::inf));
    CHECK(ir::escape_tighten(ir::Op::SeriesMin, {-1.0, -0.5}, b) == ir::Interval(b, b));
    CHECK(ir::escape_tighten(ir::Op::SeriesMax, {-num::inf, 1.0}, -b) == ir::Interval(-num::inf, -b));
}

TEST_CASE("signed permutations in 3D and max series are certified", "[escape]") {
    auto c = driver::compile_source(
        "t.frac",
        "fn m(p) = (3 * abs(p.y) - 1, -3 * p.z, 3 * abs(p.x));\n"
        "shape s(x, y) = min(k in 0.., p in orbit((x, y, 0), m) escape 0.6, (sqrt(p.x^2 + p.y^2 + p.z^2) - "
        "1) / "
        "3^k);\n"
        "shape t(x, y) = max(k in 0.., p in orbit((x, y, 0), m) escape 1/2, 2 * (0.1 - sqrt(p.x^2 + p.y^2 + "
        "p.z^2)) * 3^(-k));");
    REQUIRE(c->ok());
    const ir::OrbitEscape& s = escape_of(*c, "s");
    CHECK(s.offset < 0); // 0.6 - 1 < 0: the constant part of the bound is negative
    CHECK(s.offset >= -0.4 - 1e-15);
    CHECK(s.lipschitz == 1.0); // a signed permutation with abs: M is 3-Lipschitz
    CHECK(s.map_lipschitz == 3.0);
    const ir::OrbitEscape& t = escape_of(*c, "t");
    CHECK(t.slope == 1.0); // -(0.1 - |q|) = |q| - 0.1, the factor 2 goes to the scale
    CHECK(t.scale0 == ir::Interval(2.0));
    CHECK(t.growth == ir::Interval(3.0));
}

TEST_CASE("certificates that cannot be proven are compile errors that say why", "[escape]") {
    const std::string koch = polar_map;
    const std::string term = "(sqrt(p.x^2 + p.y^2) - 0.25) / 3^k";
    CHECK_THAT(
        errors_of(koch + "shape s(x, y) = min(k in 0.., p in orbit((x, y), fold) escape 0.4, " + term + ");"),
        Catch::Contains(
            "orbits provably escape only outside radius 1 / (3 - 1) = 0.5, above the claimed 0.4"));
    CHECK_THAT(
        errors_of("fn m(p) = (2 * p.x, 2 * p.y);\nshape s(x, y) = min(k in 0.., p in orbit((x, y), m) escape "
                  "1, (sqrt(p.x^2 + p.y^2) - 0.25) / 3^k);"),
        Catch::Contains("slower than the term's scale shrinks"));
    CHECK_THAT(
        errors_of("fn m(p) = (p.x * p.y, 3 * p.x);\nshape s(x, y) = min(k in 0.., p in orbit((x, y), m) "
                  "escape 1, (sqrt(p.x^2 + p.y^2) - 0.25) / 3^k);"),
        Catch::Contains("not recognised as growing"));
    CHECK_THAT(errors_of(koch + "shape s(x, y) = min(k in 0.., p in orbit((x, y), fold) escape 1/2, " + term +
                         " + dz(k * x) / 3^k);"),
               Catch::Contains("cannot prove this escape certificate"));
    CHECK_THAT(errors_of(koch + "shape s(x, y) = min(k in 0..5, p in orbit((x, y), fold) escape 1/2, " +
                         term + ");"),
               Catch::Contains("needs an infinite series"));
    CHECK_THAT(
        errors_of(koch + "shape s(x, y) = sum(k in 0.., p in orbit((x, y), fold) escape 1/2, " + term + ");"),
        Catch::Contains("not to a sum"));
    CHECK_THAT(
        errors_of(koch + "shape s(x, y) = min(k in 0.., p in orbit((x, y), fold) escape x, " + term + ");"),
        Catch::Contains("the escape radius must be a finite constant"));
}
