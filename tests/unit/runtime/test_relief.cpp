// The relief of a 3D cover: pixels over the shape are drawn, the rest stays white; a flat top is
// evenly lit, a ball is lit from the upper left (its upper-left flank brighter than the lower right).
#include "runtime/relief.hpp"
#include "runtime/rss.hpp"
#include "shapes.hpp"

#include <catch2/catch.hpp>

using namespace frac;
using namespace frac::rt;
using frac::rt::test::Ball;

namespace {

int brightness(const Image& img, int x, int row) {
    const auto k =
        (static_cast<std::size_t>(row) * static_cast<std::size_t>(img.width) + static_cast<std::size_t>(x)) *
        3;
    return img.rgb[k] + img.rgb[k + 1] + img.rgb[k + 2];
}

} // namespace

TEST_CASE("the relief of a ball: drawn over the ball, white beyond it, lit from the upper left", "[relief]") {
    Ball ball(0.8);
    RssOptions o;
    o.depth = 6;
    const RssResult r = subdivide(ball, {{-1, 1}, {-1, 1}, {-1, 1}}, o);
    const Image img = relief_image(r, 64);
    REQUIRE(img.width == 64);
    REQUIRE(img.height == 64);
    CHECK(brightness(img, 32, 32) < 3 * 255);                 // the top of the ball
    CHECK(brightness(img, 1, 1) == 3 * 255);                  // a corner beyond it
    CHECK(brightness(img, 22, 22) > brightness(img, 42, 42)); // upper-left flank (row 22) vs lower right
    CHECK_THROWS_AS(relief_image(r, 8), std::invalid_argument);
}
