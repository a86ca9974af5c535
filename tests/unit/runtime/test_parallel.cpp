// Parallel subdivision gives the same cover, cell for cell, whatever the thread count.
#include "backend/interp/interpreter.hpp"
#include "driver/pipeline.hpp"
#include "ir/tape.hpp"
#include "runtime/rss.hpp"

#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <tuple>
#include <vector>

using namespace frac;

namespace {

rt::RssResult cover(const std::string& shape, int depth, int threads, int split = 2) {
    static auto c = driver::compile_source("t.frac", "import \"fractals\";\nimport \"solids\";");
    REQUIRE(c->ok());
    const front::ShapeInfo* s = c->module.find_shape(shape);
    REQUIRE(s);
    auto eval = interp::make_interpreter(ir::build_tape(c->module.graph, s->root, s->dimension));
    rt::RssOptions o;
    o.depth = depth;
    o.threads = threads;
    o.split = split;
    o.batch = 512; // several batches per level, so that chunks and batches interleave
    rt::RssResult r = rt::subdivide(*eval, s->box, o);
    CHECK(eval->stats.calls == r.evaluated); // the clones' work is counted too
    return r;
}

bool same_cells(const rt::RssResult& a, const rt::RssResult& b) {
    if (a.cells.size() != b.cells.size()) return false;
    for (std::size_t i = 0; i < a.cells.size(); ++i) {
        const rt::Cell &x = a.cells[i], &y = b.cells[i];
        if (x.level != y.level || x.cls != y.cls || x.ix != y.ix || x.iy != y.iy || x.iz != y.iz)
            return false;
    }
    return true;
}

} // namespace

TEST_CASE("1, 2 and 3 threads give identical covers", "[rss][parallel]") {
    for (const char* shape : {"carpet", "takagi", "triangle_stripes"}) {
        INFO(shape);
        const rt::RssResult one = cover(shape, 8, 1);
        const rt::RssResult two = cover(shape, 8, 2);
        const rt::RssResult three = cover(shape, 8, 3);
        CHECK(same_cells(one, two));
        CHECK(same_cells(one, three));
        CHECK(one.boundary == two.boundary);
        CHECK(one.inside == three.inside);
    }
}

TEST_CASE("parallel 3D subdivision with split 3 is deterministic", "[rss][parallel]") {
    const rt::RssResult one = cover("menger3", 3, 1, 3);
    const rt::RssResult two = cover("menger3", 3, 2, 3);
    CHECK(same_cells(one, two));
    CHECK(one.levels.size() == 4);
}

TEST_CASE("each level holds exactly the children of the undecided cells before it, row-major",
          "[rss][parallel]") {
    // Checked against the cells themselves, whatever the cover's own order of making them: level k's
    // cells sorted by (iz, iy, ix) are its cells as made, and they are the split^d children of each
    // undecided (subdivided) cell of level k - 1.
    for (const auto& [shape, depth, split, threads] :
         {std::tuple{"carpet", 7, 2, 2}, std::tuple{"triangle_stripes", 6, 3, 3},
          std::tuple{"menger3", 3, 3, 2}, std::tuple{"menger_holes", 4, 2, 2}}) {
        INFO(shape << " split " << split << ", " << threads << " threads");
        const rt::RssResult r = cover(shape, depth, threads, split);
        const int d = r.dimension();
        std::vector<std::vector<rt::Cell>> levels(static_cast<std::size_t>(depth) + 1);
        for (const rt::Cell& c : r.cells) levels.at(c.level).push_back(c);
        REQUIRE(levels[0].size() == 1);
        for (int k = 1; k <= depth; ++k) {
            const auto& cells = levels[static_cast<std::size_t>(k)];
            std::vector<std::array<std::uint32_t, 3>> made, want;
            for (const rt::Cell& c : cells) made.push_back({c.iz, c.iy, c.ix});
            CHECK(std::is_sorted(made.begin(), made.end()));
            const auto s = static_cast<std::uint32_t>(split);
            for (const rt::Cell& p : levels[static_cast<std::size_t>(k - 1)]) {
                if (p.cls != rt::CellClass::subdivided) continue;
                for (std::uint32_t cz = 0; cz < (d == 3 ? s : 1); ++cz)
                    for (std::uint32_t cy = 0; cy < s; ++cy)
                        for (std::uint32_t cx = 0; cx < s; ++cx)
                            want.push_back({d == 3 ? p.iz * s + cz : 0, p.iy * s + cy, p.ix * s + cx});
            }
            std::sort(want.begin(), want.end());
            CHECK(made == want);
            CHECK(r.levels[static_cast<std::size_t>(k)].evaluated == cells.size());
        }
    }
}
