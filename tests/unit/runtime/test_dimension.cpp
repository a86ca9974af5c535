// Box-counting dimension from the per-level counts of one subdivision.
#include "runtime/dimension.hpp"
#include "runtime/rss.hpp"
#include "shapes.hpp"

#include <catch2/catch.hpp>

#include <stdexcept>

using namespace frac;
using namespace frac::rt;
using frac::rt::test::Ball;
using frac::rt::test::Constant;
using frac::rt::test::Disk;
using frac::rt::test::HalfPlane;
using frac::rt::test::NanShape;
using frac::rt::test::Stripes;

namespace {

const std::vector<Interval> unit{{0.0, 1.0}, {0.0, 1.0}};
const std::vector<Interval> square{{-1.0, 1.0}, {-1.0, 1.0}};

RssResult run(ir::Evaluator& f, const std::vector<Interval>& root, int depth, int split = 2) {
    RssOptions o;
    o.depth = depth;
    o.split = split;
    o.keep_cells = false; // box counting needs only the counts
    return subdivide(f, root, o);
}

} // namespace

TEST_CASE("dimension: a line has dimension 1", "[dimension]") {
    HalfPlane line(-0.5, 1, -0.1); // y = x/2 + 0.1
    const RssResult r = run(line, unit, 12);
    const DimensionEstimate d = box_counting(r, 4, 12);
    CHECK(d.dimension == Approx(1).margin(0.05));
    CHECK(d.r_squared > 0.999);
    REQUIRE(d.counts.size() == 9);
    CHECK(d.counts.front().first == 4);
    CHECK(d.counts.back().first == 12);
    for (const auto& [k, n] : d.counts) CHECK(n == r.levels[static_cast<std::size_t>(k)].undecided);
}

TEST_CASE("dimension: boundaries of a disk, of stripes, of a ball", "[dimension]") {
    Disk disk(0.1, 0.05, 0.6);
    CHECK(box_counting(run(disk, square, 12), 4, 12).dimension == Approx(1).margin(0.05));
    Stripes stripes(3);
    CHECK(box_counting(run(stripes, unit, 10), 3, 10).dimension == Approx(1).margin(0.05));
    Disk third(0.1, 0.05, 0.6);
    CHECK(box_counting(run(third, square, 7, 3), 3, 7).dimension == Approx(1).margin(0.05));
    Ball ball(0.75);
    CHECK(box_counting(run(ball, {{-1.0, 1.0}, {-1.0, 1.0}, {-1.0, 1.0}}, 7), 3, 7).dimension ==
          Approx(2).margin(0.08));
}

TEST_CASE("dimension: an undecided region fills the plane", "[dimension]") {
    NanShape nan(2);
    const DimensionEstimate d = box_counting(run(nan, unit, 5), 0, 5);
    CHECK(d.dimension == Approx(2).epsilon(1e-12));
    CHECK(d.r_squared == Approx(1).epsilon(1e-12));
}

TEST_CASE("dimension: errors", "[dimension]") {
    Disk disk(0, 0, 0.75);
    const RssResult r = run(disk, square, 6);
    CHECK_THROWS_AS(box_counting(r, -1, 4), std::invalid_argument);
    CHECK_THROWS_AS(box_counting(r, 4, 4), std::invalid_argument);
    CHECK_THROWS_AS(box_counting(r, 5, 4), std::invalid_argument);
    CHECK_THROWS_AS(box_counting(r, 0, 7), std::invalid_argument);
    CHECK_NOTHROW(box_counting(r, 0, 6));
    Constant in(2, -1.0);
    CHECK_THROWS_WITH(box_counting(run(in, square, 4), 0, 4), Catch::Matchers::Contains("level 0"));
}
