// Recursive space subdivision gives the same cover with both engines: same cells, same classes,
// same series term counts, for every standard-library shape.
#include "engines.hpp"

#include "runtime/rss.hpp"

#include <set>

using namespace frac;
using namespace frac::test;

namespace {

bool same_cells(const rt::RssResult& a, const rt::RssResult& b, std::string& why) {
    if (a.cells.size() != b.cells.size()) {
        why = "cell counts " + std::to_string(a.cells.size()) + " and " + std::to_string(b.cells.size());
        return false;
    }
    for (std::size_t k = 0; k < a.cells.size(); ++k) {
        const rt::Cell& x = a.cells[k];
        const rt::Cell& y = b.cells[k];
        if (x.level != y.level || x.cls != y.cls || x.ix != y.ix || x.iy != y.iy || x.iz != y.iz) {
            why = "cell " + std::to_string(k) + " (level " + std::to_string(x.level) + ", " +
                  std::to_string(x.ix) + ", " + std::to_string(x.iy) + ", " + std::to_string(x.iz) +
                  ") differs";
            return false;
        }
    }
    return true;
}

} // namespace

TEST_CASE("identical RSS covers for every stdlib shape", "[llvm][rss]") {
    std::set<std::string> seen;
    for (const std::string& file : stdlib_files()) {
        const Model m = compile("import \"" + file + "\";");
        for (std::size_t i = 0; i < m.tapes.size(); ++i) {
            const front::ShapeInfo& s = m.shape(i);
            if (!seen.insert(s.name).second) continue;
            INFO(file << ": shape " << s.name);
            auto in = InterpEngine::make(m.tapes[i]);
            auto jt = JitEngine::make(m.tapes[i]);
            rt::RssOptions o;
            o.depth = s.dimension == 2 ? 7 : 4;
            const rt::RssResult ri = rt::subdivide(*in, s.box, o);
            const rt::RssResult rj = rt::subdivide(*jt, s.box, o);
            std::string why;
            CHECK(same_cells(ri, rj, why));
            INFO(why);
            CHECK(ri.boundary == rj.boundary);
            CHECK(ri.evaluated == rj.evaluated);
            CHECK(in->stats.calls == jt->stats.calls);
            // Term counts: the inline sin/cos/exp/tan/log kernels enclose a few ulps more loosely and
            // adaptive truncation looks at widths, so they are compared with the core's calls.
            auto jx = make_jit_exact_calls(m.tapes[i]);
            rt::subdivide(*jx, s.box, o);
            CHECK(in->stats.series_terms == jx->stats.series_terms);
            CHECK(in->stats.series_capped == jx->stats.series_capped);
        }
    }
}

TEST_CASE("identical RSS covers of the carpet with split 3 and depth 6", "[llvm][rss]") {
    const Model m = compile("import \"fractals\";");
    for (std::size_t i = 0; i < m.tapes.size(); ++i) {
        if (m.shape(i).name != "carpet") continue;
        auto in = InterpEngine::make(m.tapes[i]);
        auto jt = JitEngine::make(m.tapes[i]);
        rt::RssOptions o;
        o.depth = 6;
        o.split = 3;
        const rt::RssResult ri = rt::subdivide(*in, m.shape(i).box, o);
        const rt::RssResult rj = rt::subdivide(*jt, m.shape(i).box, o);
        std::string why;
        CHECK(same_cells(ri, rj, why));
        CHECK(ri.boundary >= 8 * 8 * 8 * 8 * 8 * 8); // at least the carpet's 8^6 cells
        CHECK(rj.boundary == ri.boundary);
    }
}

TEST_CASE("both engines prove exactly the 20^k cubes of the stdlib sponge", "[llvm][rss]") {
    // menger_lattice computes with integers only, so on the unit cells of a split-3 cover both engines'
    // enclosures are exact and the closed rule (hi <= 0) proves the level-k sponge's cubes inside.
    const Model m = compile("import \"solids\";\nshape s3(x, y, z) over [0, 27] × [0, 27] × [0, 27] = "
                            "menger_lattice((x, y, z), 3);");
    for (std::size_t i = 0; i < m.tapes.size(); ++i) {
        const front::ShapeInfo& s = m.shape(i);
        if (s.name != "menger3" && s.name != "s3") continue;
        INFO(s.name);
        const int k = s.name == "s3" ? 3 : 2;
        auto in = InterpEngine::make(m.tapes[i]);
        auto jt = JitEngine::make(m.tapes[i]);
        rt::RssOptions o;
        o.depth = k;
        o.split = 3;
        o.closed_inside = true;
        const rt::RssResult ri = rt::subdivide(*in, s.box, o);
        const rt::RssResult rj = rt::subdivide(*jt, s.box, o);
        std::string why;
        CHECK(same_cells(ri, rj, why));
        INFO(why);
        CHECK(ri.inside == (k == 3 ? 8000u : 400u));
        CHECK(rj.inside == ri.inside);
    }
}
