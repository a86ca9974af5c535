// Pictures of a 2D subdivision: ASCII golden, raster colours, PNG and SVG files, errors.
#include "runtime/picture.hpp"
#include "runtime/rss.hpp"
#include "shapes.hpp"

#include <catch2/catch.hpp>
#include <png.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unistd.h>

using namespace frac;
using namespace frac::rt;
using frac::rt::test::Ball;
using frac::rt::test::Disk;
using frac::rt::test::HalfDefined;
using frac::rt::test::HalfPlane;

namespace fs = std::filesystem;

namespace {

const std::vector<Interval> square{{-1.0, 1.0}, {-1.0, 1.0}};

RssResult disk_result(int depth, bool keep = true) {
    Disk disk(0, 0, 0.75);
    RssOptions o;
    o.depth = depth;
    o.keep_cells = keep;
    return subdivide(disk, square, o);
}

// A fresh directory for the files of one test, removed at the end.
struct TempDir {
    fs::path path;
    TempDir() {
        path = fs::temp_directory_path() /
               ("frac-runtime-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter()++));
        fs::create_directories(path);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
    static int& counter() {
        static int n = 0;
        return n;
    }
};

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::size_t count(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

struct Pixel {
    int r, g, b;
    bool operator==(const Pixel&) const = default;
};

// Pixel at (x, y) with y counted from the top row.
Pixel at(const Image& img, int x, int y) {
    const std::uint8_t* p = &img.rgb[(static_cast<std::size_t>(y) * img.width + x) * 3];
    return {p[0], p[1], p[2]};
}

} // namespace

TEST_CASE("picture: ASCII golden of a disk", "[picture]") {
    const RssResult r = disk_result(3);
    // r = 0.75 on [-1, 1]^2, depth 3 (cells of 1/4, characters of 1/8). The cells [3/4, 1] x [0, 1/4]
    // touch the circle at (3/4, 0): boundary, not outside.
    const std::string expected = "......++++......\n"
                                 "......++++......\n"
                                 "..++++++++++++..\n"
                                 "..++++++++++++..\n"
                                 "..++########++..\n"
                                 "..++########++..\n"
                                 "++++########++++\n"
                                 "++++########++++\n"
                                 "++++########++++\n"
                                 "++++########++++\n"
                                 "..++########++..\n"
                                 "..++########++..\n"
                                 "..++++++++++++..\n"
                                 "..++++++++++++..\n"
                                 "......++++......\n"
                                 "......++++......\n";
    CHECK(ascii_picture(r, 16, 16) == expected);
}

TEST_CASE("picture: ASCII rules", "[picture]") {
    // Half-plane x < 0.3 on [-1, 1]^2: inside on the left, outside on the right, boundary between.
    HalfPlane f(1, 0, -0.3);
    RssOptions o;
    o.depth = 6;
    const RssResult r = subdivide(f, square, o);
    // Characters are 0.1 wide; depth-6 cells 1/32: the cells around x = 0.3 reach into [0.2, 0.4].
    const std::string row = "############++......\n";
    CHECK(ascii_picture(r, 20, 3) == row + row + row);
    // One character for the whole root meets every class.
    CHECK(ascii_picture(r, 1, 1) == "+\n");
    CHECK_THROWS_AS(ascii_picture(r, 0, 3), std::invalid_argument);
    CHECK_THROWS_AS(ascii_picture(r, 3, 5000), std::invalid_argument);

    // ':' needs inside and outside leaves in one character without a boundary cell, which a sound
    // enclosure of a function defined everywhere cannot give (the cells between would be
    // undecided); an undefined region (empty enclosure = outside) next to an inside one does.
    HalfDefined h;
    o.depth = 3;
    const RssResult hr = subdivide(h, {{-1.2, 0.8}, {-1.0, 1.0}}, o);
    CHECK(ascii_picture(hr, 5, 2) == "..:++\n..:++\n");
}

TEST_CASE("picture: raster colours and size", "[picture]") {
    const RssResult r = disk_result(6);
    const Image cover = render(r, PictureKind::cover, 64);
    REQUIRE(cover.width == 64);
    REQUIRE(cover.height == 64);
    CHECK(at(cover, 32, 32) == Pixel{200, 200, 200}); // centre: inside, light grey
    CHECK(at(cover, 0, 0) == Pixel{255, 255, 255});   // corner: outside, white
    // On the circle x = 0.75 (pixel column 56), y = 0: a boundary cell, black.
    CHECK(at(cover, 56, 32) == Pixel{0, 0, 0});

    const Image process = render(r, PictureKind::process, 64);
    CHECK(at(process, 0, 0) == Pixel{0, 0, 0});       // the root's outline
    CHECK(at(process, 56, 31) == Pixel{0, 0, 0});     // an outline of the 4-pixel cells of level 4
    CHECK(at(process, 55, 30) == Pixel{226, 60, 40}); // boundary: red (cells of 1 px: no outline)
    CHECK(at(process, 5, 60) == Pixel{255, 255, 255});

    const Image both = render(r, PictureKind::both, 64);
    CHECK(both.width == 2 * 64 + 2);
    CHECK(both.height == 64);
    CHECK(at(both, 64 + 2 + 32, 32) == Pixel{200, 200, 200}); // right panel = cover
    CHECK(at(both, 65, 10) == Pixel{255, 255, 255});          // the gap

    // y axis up: a half-plane y > 0.5 is inside at the top of the picture.
    HalfPlane upper(0, -1, 0.5);
    RssOptions o;
    o.depth = 4;
    const RssResult u = subdivide(upper, square, o);
    const Image img = render(u, PictureKind::cover, 32);
    CHECK(at(img, 16, 1) == Pixel{200, 200, 200});
    CHECK(at(img, 16, 30) == Pixel{255, 255, 255});

    // A wide root keeps its aspect ratio.
    Disk disk(0, 0, 0.5);
    const std::vector<Interval> wide{{-2.0, 2.0}, {-1.0, 1.0}};
    const RssResult w = subdivide(disk, wide, o);
    const Image wi = render(w, PictureKind::process, 100);
    CHECK(wi.width == 100);
    CHECK(wi.height == 50);
    CHECK_THROWS_AS(render(w, PictureKind::cover, 0), std::invalid_argument);
}

TEST_CASE("picture: PNG files", "[picture]") {
    TempDir dir;
    const RssResult r = disk_result(7);
    for (PictureKind kind : {PictureKind::process, PictureKind::cover, PictureKind::both}) {
        const fs::path file = dir.path / ("disk" + std::to_string(static_cast<int>(kind)) + ".png");
        write_png(r, file.string(), kind, 128);
        const std::string bytes = slurp(file);
        REQUIRE(bytes.size() > 8);
        CHECK(std::memcmp(bytes.data(), "\x89PNG\r\n\x1a\n", 8) == 0);

        png_image png;
        std::memset(&png, 0, sizeof png);
        png.version = PNG_IMAGE_VERSION;
        REQUIRE(png_image_begin_read_from_file(&png, file.string().c_str()) != 0);
        CHECK(png.width == (kind == PictureKind::both ? 2u * 128 + 2 : 128u));
        CHECK(png.height == 128u);
        // Decode it back and compare with the in-memory rendering.
        png.format = PNG_FORMAT_RGB;
        std::vector<std::uint8_t> pixels(PNG_IMAGE_SIZE(png));
        REQUIRE(png_image_finish_read(&png, nullptr, pixels.data(), 0, nullptr) != 0);
        CHECK(pixels == render(r, kind, 128).rgb);
    }
    const std::string bad = (dir.path / "no-such-dir" / "x.png").string();
    try {
        write_png(r, bad, PictureKind::cover, 16);
        FAIL("no error");
    } catch (const std::runtime_error& e) {
        CHECK_THAT(e.what(), Catch::Matchers::Contains(bad));
        CHECK_THAT(e.what(), Catch::Matchers::Contains("No such file"));
    }
}

TEST_CASE("picture: SVG files", "[picture]") {
    TempDir dir;
    const RssResult r = disk_result(5);
    const fs::path process = dir.path / "p.svg", cover = dir.path / "c.svg", both = dir.path / "b.svg";
    write_svg(r, process.string(), PictureKind::process);
    write_svg(r, cover.string(), PictureKind::cover);
    write_svg(r, both.string(), PictureKind::both);
    const std::string p = slurp(process), c = slurp(cover), b = slurp(both);
    for (const std::string* s : {&p, &c, &b}) {
        CHECK(s->rfind("<?xml", 0) == 0);
        CHECK(count(*s, "<svg ") == 1);
        CHECK(s->size() >= 7);
        CHECK(s->substr(s->size() - 7) == "</svg>\n");
        CHECK(count(*s, "<g") == count(*s, "</g>"));
        CHECK(count(*s, "<rect") == count(*s, "/>"));
    }
    // One rect per cell (plus the background): all cells in the process picture, inside and
    // boundary leaves in the cover.
    CHECK(count(p, "<rect") == 1 + r.evaluated);
    CHECK(count(c, "<rect") == 1 + r.inside + r.boundary);
    CHECK(count(b, "<rect") == 1 + r.evaluated + r.inside + r.boundary);
    CHECK(p.find("width=\"1024\" height=\"1024\"") != std::string::npos);
    CHECK(b.find("width=\"2064\" height=\"1024\"") != std::string::npos);

    // Cells below 0.3 units of the 1024-unit panel are left out of the process picture only:
    // level 12 cells are 0.25 units.
    const RssResult deep = disk_result(12);
    const fs::path dp = dir.path / "deep.svg", dc = dir.path / "deepc.svg";
    write_svg(deep, dp.string(), PictureKind::process);
    write_svg(deep, dc.string(), PictureKind::cover);
    CHECK(count(slurp(dp), "<rect") == 1 + deep.evaluated - deep.levels[12].evaluated);
    CHECK(count(slurp(dc), "<rect") == 1 + deep.inside + deep.boundary);

    CHECK_THROWS_AS(write_svg(r, (dir.path / "none" / "x.svg").string(), PictureKind::cover),
                    std::runtime_error);
}

TEST_CASE("picture: needs a 2D result with cells", "[picture]") {
    Ball ball(0.5);
    RssOptions o;
    o.depth = 2;
    const RssResult r3 = subdivide(ball, {{-1.0, 1.0}, {-1.0, 1.0}, {-1.0, 1.0}}, o);
    using Catch::Matchers::Contains;
    CHECK_THROWS_WITH(ascii_picture(r3, 8, 8), Contains("use slices"));
    CHECK_THROWS_WITH(render(r3, PictureKind::cover, 8), Contains("use slices"));
    CHECK_THROWS_AS(write_svg(r3, "/tmp/never-written.svg", PictureKind::cover), std::invalid_argument);
    const RssResult counts_only = disk_result(4, false);
    CHECK_THROWS_WITH(ascii_picture(counts_only, 8, 8), Contains("keep_cells"));
    CHECK_THROWS_AS(write_png(counts_only, "/tmp/never-written.png", PictureKind::cover, 8),
                    std::invalid_argument);
}
