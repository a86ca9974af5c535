// The legend strip: added below the picture, which it leaves unchanged, with swatches and words.
#include "runtime/legend.hpp"

#include <catch2/catch.hpp>

#include <algorithm>

using namespace frac::rt;

TEST_CASE("a legend is a strip below the picture with its swatches and words", "[legend]") {
    Image img;
    img.width = 512;
    img.height = 256;
    img.rgb.assign(512 * 256 * 3, 255);
    img.rgb[0] = 7; // a mark the legend must keep
    for (PictureKind kind : {PictureKind::process, PictureKind::cover, PictureKind::both}) {
        const Image out = with_legend(img, kind);
        REQUIRE(out.width == 512);
        REQUIRE(out.height == 256 + 12);
        CHECK(std::equal(img.rgb.begin(), img.rgb.end(), out.rgb.begin()));
        const auto strip = out.rgb.begin() + 512 * 256 * 3;
        const auto dark = std::count(strip, out.rgb.end(), 0);
        CHECK(dark > 100); // outlines and letters
        // The process legend has three entries, the cover's two: more ink for process and both.
        if (kind == PictureKind::cover) CHECK(dark < std::count(strip, out.rgb.end(), 255));
    }
}
