// Parallel subdivision gives the same cover, cell for cell, whatever the thread count.
#include "backend/interp/interpreter.hpp"
#include "driver/pipeline.hpp"
#include "ir/tape.hpp"
#include "runtime/rss.hpp"

#include <catch2/catch.hpp>

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
