// Min/max pruning per region (ir/specialize.hpp) with both engines: pruned tapes are well formed and
// smaller, give the unpruned enclosure bit for bit on sub-boxes of the box they were recorded on,
// are the same for both engines, are compiled once (cache), and leave every RSS cover unchanged.
#include "engines.hpp"

#include "backend/interp/flat_interpreter.hpp"
#include "backend/interp/interpreter.hpp"
#include "bench/large_models.hpp"
#include "driver/engines.hpp"
#include "ir/specialize.hpp"
#include "runtime/rss.hpp"

#include <cmath>
#include <fmt/format.h>
#include <fstream>
#include <set>
#include <sstream>

using namespace frac;
using namespace frac::test;

namespace {

// A CSG composition: two fractals and classical parts under min/max, and a select.
const char* csg_model = R"(
import "fractals";
fn placed_carpet(x, y, x0, y0, s) = max(carpet((x - x0) / s, (y - y0) / s) * s, rect((x, y), (x0, y0), (x0 + s, y0 + s)));
shape scene(x, y) over [0, 2] × [0, 1] =
    min(placed_carpet(x, y, 0.1, 0.1, 0.8), max(triangle(x - 1.1, y - 0.1), rect((x, y), (1.1, 0.1), (1.9, 0.9))),
        disk((x, y), (1.0, 0.5), 0.05));
shape chooser(x, y) over [-1, 1] × [-1, 1] = if x < 0 then carpet(x + 1, y) else disk((x, y), (0.5, 0), 0.3);
shape partial(x, y) over [0, 1] × [-1, 1] = min(x - 10, sqrt(y));
shape quadrant(x, y) over [-1, 1] × [-1, 1] = if x < 0 and y < 0 then carpet(x + 1, y + 1) else disk((x, y), (0.5, 0), 0.3);
)";

std::string read_file(const std::string& path) {
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

const ir::Tape& tape_of(const Model& m, const std::string& name) {
    for (std::size_t i = 0; i < m.tapes.size(); ++i)
        if (m.shape(i).name == name) return m.tapes[i];
    FAIL("no shape " << name);
    throw std::logic_error("unreachable");
}
const front::ShapeInfo& info_of(const Model& m, const std::string& name) {
    for (std::size_t i = 0; i < m.tapes.size(); ++i)
        if (m.shape(i).name == name) return m.shape(i);
    FAIL("no shape " << name);
    throw std::logic_error("unreachable");
}

// A random sub-box of `box`.
std::vector<Interval> sub_box(BoxMaker& r, const std::vector<Interval>& box) {
    std::vector<Interval> s;
    for (const Interval& x : box) {
        double a = r.uniform(x.lo, x.hi), b = r.uniform(x.lo, x.hi);
        if (a > b) std::swap(a, b);
        if (r.pick(4) == 0) b = a; // thin
        s.push_back({a, b});
    }
    return s;
}

// Boxes of a few cells of every level of a cover (cells where the tape has choices to make).
std::vector<std::vector<Interval>> cover_boxes(ir::Evaluator& e, const std::vector<Interval>& root, int depth,
                                               std::size_t stride) {
    rt::RssOptions o;
    o.depth = depth;
    const rt::RssResult r = rt::subdivide(e, root, o);
    std::vector<std::vector<Interval>> boxes;
    for (std::size_t k = 0; k < r.cells.size(); k += stride) {
        std::vector<Interval> b;
        for (int a = 0; a < r.dimension(); ++a) b.push_back(r.cell_interval(r.cells[k], a));
        boxes.push_back(b);
    }
    return boxes;
}

} // namespace

TEST_CASE("pruned tapes are well formed, smaller, and exact on sub-boxes", "[llvm][prune]") {
    const Model m = compile(csg_model);
    const ir::Tape& tape = tape_of(m, "scene");
    auto in = InterpEngine::make(tape);
    auto jt = JitEngine::make(tape);
    interp::ChoiceRecorder rec(tape, {});
    BoxMaker r(2024);
    std::size_t pruned_boxes = 0, compared = 0;
    for (const auto& box : cover_boxes(*in, info_of(m, "scene").box, 5, 7)) {
        const std::vector<ir::Choice> choices = rec.record(box.data());
        REQUIRE(choices.size() == tape.blocks[0].size());
        if (!ir::any_decided(choices)) continue;
        ++pruned_boxes;
        const ir::Tape p = ir::specialize(tape, choices);
        INFO("box " << hex_box(box.data(), 2));
        REQUIRE(ir::verify_tape(p).empty());
        CHECK(p.instruction_count() < tape.instruction_count());
        // Specialising twice the same way gives the same tape (the cache key is canonical).
        CHECK(ir::tape_key(p) == ir::tape_key(ir::specialize(tape, choices)));
        auto pi = InterpEngine::make(p);
        auto pj = JitEngine::make(p);
        for (int k = 0; k < 8; ++k) {
            const std::vector<Interval> s = k == 0 ? box : sub_box(r, box);
            const Interval full = in->eval_box(s.data());
            const Interval pruned_i = pi->eval_box(s.data());
            const Interval pruned_j = pj->eval_box(s.data());
            INFO("sub-box " << hex_box(s.data(), 2) << ": full " << hex(full) << ", pruned "
                            << hex(pruned_i));
            CHECK(same(full, pruned_i));     // isotone enclosures: the dropped operands never matter
            CHECK(same(pruned_i, pruned_j)); // both engines run the pruned tape alike
            CHECK(same(full, jt->eval_box(s.data())));
            ++compared;
        }
    }
    CHECK(pruned_boxes >= 10);
    CHECK(compared >= 80);
}

TEST_CASE("both engines specialise alike and compile each pruned tape once", "[llvm][prune]") {
    const Model m = compile(csg_model);
    const ir::Tape& tape = tape_of(m, "scene");
    auto in = InterpEngine::make(tape);
    auto jt = JitEngine::make(tape);
    // A box where only the disk and the triangle's square matter, and a sub-box of it.
    const std::vector<Interval> box{{0.95, 1.05}, {0.45, 0.55}};
    const std::vector<Interval> inner{{0.97, 1.0}, {0.5, 0.52}};
    // The JIT compiles when the expected evaluations repay it; asked for few, it declines (or
    // hands the pruned tape to the interpreter), asked for many it compiles.
    auto sj = jt->specialize(box.data(), 1e12);
    auto si = in->specialize(box.data(), 1e12);
    REQUIRE(sj);
    REQUIRE(si);
    CHECK(sj->engine() == "jit");
    CHECK(sj->instruction_count() == si->instruction_count());
    CHECK(sj->instruction_count() < tape.instruction_count());
    CHECK(jt->specialize_stats.compiled == 1);
    CHECK(in->specialize_stats.pushes == 1); // the interpreter runs the pruned tape as it is
    CHECK(in->specialize_stats.compiled == 0);
    // Asked again, from a clone: the same evaluator, from the cache.
    auto clone = jt->clone();
    auto again = clone->specialize(box.data(), 1e12);
    CHECK(again == sj);
    CHECK(clone->specialize_stats.hits == 1);
    CHECK(clone->specialize_stats.compiled == 0);
    CHECK(jt->specialize(box.data(), 1e3) == sj); // compiled already: used whatever the demand
    // The interpreter makes a tape for each cell that asks, when its descendants repay it: not for one.
    const auto asked = in->specialize_stats.requests;
    CHECK_FALSE(in->specialize(box.data(), 1));
    CHECK(in->specialize_stats.requests == asked); // not even recorded
    CHECK_FALSE(in->specialize(box.data(), interp::interp_min_expected_evaluations));
    // The specialisation is exact on sub-boxes, with both engines.
    for (const auto& b : {box, inner}) {
        const Interval full = in->eval_box(b.data());
        CHECK(same(full, sj->clone()->eval_box(b.data())));
        CHECK(same(full, si->clone()->eval_box(b.data())));
    }
    // Specialisations specialise further, through the same cache.
    auto deeper = sj->specialize(inner.data(), 1e12);
    if (deeper) CHECK(deeper->instruction_count() <= sj->instruction_count());
}

TEST_CASE("the JIT declines to compile a pruned tape that would not repay it", "[llvm][prune]") {
    const Model m = compile(csg_model);
    const ir::Tape& tape = tape_of(m, "scene");
    auto jt = JitEngine::make(tape);
    // The carpet's corner: the carpet's series stays, the rest goes; one evaluation does not pay
    // for a compile, and the interpreter is slower on the carpet's series than the JIT on the scene.
    const std::vector<Interval> box{{0.1, 0.2}, {0.1, 0.2}};
    // Too few descendants to repay recording the choices: not even asked.
    CHECK_FALSE(jt->specialize(box.data(), 1));
    CHECK(jt->specialize_stats.requests == 0);
    CHECK_FALSE(jt->specialize(box.data(), jit::jit_min_expected_evaluations));
    // Where the interpreter's fixed part alone costs more than the JIT's evaluation of the scene, no
    // pruned tape can pay either: the choices are not even recorded.
    const bool fallback_may_pay =
        interp::cover_eval_ns_fixed < ir::eval_ns(jit::jit_prune_costs, ir::tape_cost(tape));
    CHECK(jt->specialize_stats.requests == (fallback_may_pay ? 1 : 0));
    CHECK(jt->specialize_stats.declined == (fallback_may_pay ? 1 : 0));
    CHECK(jt->specialize_stats.compiled == 0);
    // Where only the disk is left, the interpreter runs the small pruned tape when the rule says
    // that is faster than the JIT on the whole scene.
    const std::vector<Interval> disk_box{{0.98, 1.02}, {0.48, 0.52}};
    interp::ChoiceRecorder rec(tape, {});
    const ir::Tape disk_only = ir::specialize(tape, rec.record(disk_box.data()));
    const bool interp_faster =
        interp::cover_eval_ns(disk_only) < ir::eval_ns(jit::jit_prune_costs, ir::tape_cost(tape));
    auto tier2 = jt->specialize(disk_box.data(), jit::jit_min_expected_evaluations);
    CHECK(bool(tier2) == interp_faster);
    if (tier2) {
        CHECK(tier2->engine() == "interp");
        CHECK(tier2->instruction_count() == disk_only.instruction_count());
        CHECK(jt->specialize_stats.fallbacks == 1);
        CHECK(same(tier2->eval_box(disk_box.data()), jt->eval_box(disk_box.data())));
    }
}

TEST_CASE("the JIT records no choices where no outcome could repay the recording", "[llvm][prune]") {
    // Three balls: a short tape. The JIT's evaluation of it is mostly its fixed part, which the
    // interpreter's fixed part alone exceeds, and the cells of a cover do not demand enough to repay a
    // compile: every request would be declined after its recording was paid for.
    const Model m = compile(R"(
import "csg";
shape balls(x, y, z) over [-2, 2] × [-2, 2] × [-2, 2] =
    min(sphere((x, y, z), (-1, 0, 0), 0.5), sphere((x, y, z), (1, 0, 0), 0.5), sphere((x, y, z), (0, 1, 0), 0.5));
)");
    const ir::Tape& tape = tape_of(m, "balls");
    const double cost = ir::tape_cost(tape);
    REQUIRE(interp::cover_eval_ns_fixed >= ir::eval_ns(jit::jit_prune_costs, cost));
    auto jt = JitEngine::make(tape);
    // Around the left ball only the left ball matters: the interpreter would prune there.
    const std::vector<Interval> box{{-1.6, -0.4}, {-0.6, 0.6}, {-0.6, 0.6}};
    auto in = InterpEngine::make(tape);
    CHECK(in->specialize(box.data(), 1e4));
    const double few = 1e4; // a deep cell's descendants: far from repaying a 20 ms compile
    REQUIRE(few * jit::jit_prune_costs.eval_ns_per_cost * cost < jit::jit_prune_costs.compile_ns_fixed);
    CHECK_FALSE(jt->specialize(box.data(), few));
    CHECK(jt->specialize_stats.requests == 0); // not even recorded
    // ... which the evaluator says for a whole level of such cells, so a cover does not ask them one by
    // one; the interpreter's cover does.
    CHECK_FALSE(jt->may_specialize_now(few));
    CHECK(jt->may_specialize_now(1e12));
    CHECK(in->may_specialize_now(few));
    {
        rt::RssOptions o;
        o.depth = 7;
        const std::vector<Interval> root(3, Interval(-2, 2));
        auto jc = JitEngine::make(tape);
        auto ic = InterpEngine::make(tape);
        const rt::RssResult jr = rt::subdivide(*jc, root, o);
        const rt::RssResult ir_ = rt::subdivide(*ic, root, o);
        CHECK(rt::same_cover(jr, ir_));
        std::uint64_t jit_asked = 0, interp_asked = 0;
        for (const rt::PruneLevel& l : jr.prune_levels) jit_asked += l.requests;
        for (const rt::PruneLevel& l : ir_.prune_levels) interp_asked += l.requests;
        CHECK(jit_asked == 0);
        CHECK(interp_asked > 0);
    }
    // A cell whose descendants alone would repay compiling: asked, recorded, compiled.
    auto compiled = jt->specialize(box.data(), 1e12);
    CHECK(jt->specialize_stats.requests == 1);
    REQUIRE(compiled);
    CHECK(compiled->engine() == "jit");
    CHECK(compiled->instruction_count() < tape.instruction_count());
    // The rule itself: a long tape is worth recording for the fallback, a short one is not.
    ir::SpecializationCache cache([](const ir::Tape&) -> std::unique_ptr<ir::Evaluator> { return nullptr; },
                                  jit::jit_prune_costs,
                                  [](const ir::Tape& t) { return interp::make_interpreter(t); },
                                  [](const ir::Tape& t) { return interp::cover_eval_ns(t); });
    const auto record = [](double c) { return interp::tape_eval_ns_per_cost * c; };
    CHECK_FALSE(cache.may_pay(cost, few, record(cost)));
    CHECK(cache.may_pay(cost, 1e12, record(cost)));
    // A tape long enough for the interpreter to run an empty pruned tape faster, and a demand that
    // repays no compile of it: only the fallback can pay, and an engine without one does not record.
    const double per_cost = jit::jit_prune_costs.eval_ns_per_cost;
    const double long_cost = 2 * interp::cover_eval_ns_fixed / per_cost;
    const double some = 0.5 * jit::jit_prune_costs.compile_ns_fixed / (per_cost * long_cost);
    CHECK(cache.may_pay(long_cost, some, record(long_cost)));
    ir::SpecializationCache no_fallback(
        [](const ir::Tape&) -> std::unique_ptr<ir::Evaluator> { return nullptr; }, jit::jit_prune_costs);
    CHECK_FALSE(no_fallback.may_pay(long_cost, some, record(long_cost)));
    CHECK(no_fallback.may_pay(long_cost, 4 * some, record(long_cost)));
    // Too few descendants to repay the recording even if they all ran an empty tape on the fallback.
    const double saved_each = ir::eval_ns(jit::jit_prune_costs, long_cost) - interp::cover_eval_ns_fixed;
    CHECK_FALSE(cache.may_pay(long_cost, 0.9 * record(long_cost) / saved_each, record(long_cost)));
    CHECK(cache.may_pay(long_cost, 1.1 * record(long_cost) / saved_each, record(long_cost)));
}

TEST_CASE("the second tier's evaluation cost is that of the interpreter running the pruned tape",
          "[llvm][prune]") {
    const Model m = compile(csg_model);
    const ir::Tape& scene = tape_of(m, "scene");
    REQUIRE_FALSE(interp::runs_flat(scene)); // the carpet's series
    CHECK(interp::eval_ns_per_cost(scene) == interp::tape_eval_ns_per_cost);
    const std::vector<Interval> disk_box{{0.98, 1.02}, {0.48, 0.52}};
    interp::ChoiceRecorder rec(scene, {});
    const ir::Tape disk_only = ir::specialize(scene, rec.record(disk_box.data()));
    REQUIRE(interp::runs_flat(disk_only));
    CHECK(interp::eval_ns_per_cost(disk_only) == interp::flat_eval_ns_per_cost);
    // bench/bench_prune measures both: the flat interpreter is the faster.
    CHECK(interp::flat_eval_ns_per_cost < interp::tape_eval_ns_per_cost);
}

TEST_CASE("the interpreter prunes from the values its last evaluation left", "[llvm][prune]") {
    const Model m = compile(csg_model);
    auto a = InterpEngine::make(tape_of(m, "scene"));
    auto b = InterpEngine::make(tape_of(m, "scene"));
    BoxMaker r(5);
    int pruned = 0;
    for (int k = 0; k < 200; ++k) {
        const std::vector<Interval> box = sub_box(r, {{0, 2}, {0, 1}});
        const Interval value = a->eval_box(box.data());
        auto after = a->specialize_after_eval(0, box.data(), 1e12);
        auto fresh = b->specialize(box.data(), 1e12);
        REQUIRE(bool(after) == bool(fresh));
        if (!after) continue;
        ++pruned;
        CHECK(after->instruction_count() == fresh->instruction_count());
        CHECK(same(after->eval_box(box.data()), fresh->eval_box(box.data())));
        CHECK(same(after->eval_box(box.data()), value));
    }
    CHECK(pruned > 20);
    CHECK(a->stats.calls == 200); // no evaluation of its own
}

TEMPLATE_TEST_CASE("may_specialize says whether pruning can ever happen", "[llvm][prune]", InterpEngine,
                   JitEngine, TieredEngine) {
    const Model m = compile(csg_model);
    ir::EvalOptions off;
    off.prune = false;
    CHECK(TestType::make(tape_of(m, "scene"))->may_specialize());
    CHECK_FALSE(TestType::make(tape_of(m, "scene"), off)->may_specialize());
    // The carpet alone has no min or max in its top-level code to prune.
    const Model plain = compile("import \"fractals\"; shape c(x, y) = carpet(x, y);");
    auto carpet = TestType::make(tape_of(plain, "c"));
    CHECK_FALSE(carpet->may_specialize());
    const std::vector<Interval> cell{{0.1, 0.2}, {0.1, 0.2}};
    CHECK_FALSE(carpet->specialize(cell.data(), 1e12));
}

TEMPLATE_TEST_CASE("what pruning must not touch", "[llvm][prune]", InterpEngine, JitEngine) {
    const Model m = compile(csg_model);
    SECTION("an operand that may become empty on a sub-box is kept") {
        auto e = TestType::make(tape_of(m, "partial"));
        // x - 10 < sqrt(y) wherever sqrt(y) is defined, but sqrt(y) is empty for y < 0: pruning it
        // would turn empty enclosures (outside) into defined ones.
        const std::vector<Interval> across{{0, 1}, {-1, 1}};
        CHECK_FALSE(e->specialize(across.data(), 1e12));
        CHECK(e->specialize_stats.unpruned == 1);
        const std::vector<Interval> above{{0, 1}, {0.25, 1}};
        auto p = e->specialize(above.data(), 1e12);
        REQUIRE(p);
        CHECK(p->instruction_count() < e->instruction_count());
    }
    SECTION("choices inside a series are never pruned") {
        const Model f = compile("import \"fractals\";");
        auto e = TestType::make(tape_of(f, "carpet"));
        const std::vector<Interval> box{{0.4, 0.6}, {0.1, 0.2}};
        CHECK_FALSE(e->specialize(box.data(), 1e12));
    }
    SECTION("a decided select keeps its branch") {
        auto e = TestType::make(tape_of(m, "chooser"));
        const std::vector<Interval> right{{0.2, 0.8}, {-0.5, 0.5}};
        auto p = e->specialize(right.data(), 1e12);
        REQUIRE(p);
        CHECK(p->instruction_count() < e->instruction_count());
        const std::vector<Interval> sub{{0.3, 0.4}, {-0.1, 0.2}};
        CHECK(same(p->eval_box(sub.data()), e->eval_box(sub.data())));
        const std::vector<Interval> across{{-0.2, 0.2}, {-0.5, 0.5}};
        CHECK_FALSE(e->specialize(across.data(), 1e12));
    }
    SECTION("a false operand decides an and, whatever the other") {
        auto e = TestType::make(tape_of(m, "quadrant"));
        // x < 0 is false, y < 0 unknown: the and is false, the select takes the disk.
        const std::vector<Interval> box{{0.2, 0.8}, {-0.5, 0.5}};
        auto p = e->specialize(box.data(), 1e12);
        REQUIRE(p);
        CHECK(p->instruction_count() < e->instruction_count() / 2); // the carpet's series is gone
        const std::vector<Interval> sub{{0.25, 0.3}, {-0.1, 0.4}};
        CHECK(same(p->eval_box(sub.data()), e->eval_box(sub.data())));
    }
    SECTION("pruning off") {
        ir::EvalOptions off;
        off.prune = false;
        auto e = TestType::make(tape_of(m, "scene"), off);
        const std::vector<Interval> box{{0.95, 1.05}, {0.45, 0.55}};
        CHECK_FALSE(e->specialize(box.data(), 1e12));
        CHECK(e->specialize_stats.requests == 0);
    }
}

TEMPLATE_TEST_CASE("RSS covers are the same with and without pruning", "[llvm][prune][rss]", InterpEngine,
                   JitEngine, TieredEngine) {
    // The CSG shapes of the tests, of the bench and of the examples, and every stdlib shape.
    std::vector<std::pair<std::string, std::string>> sources = {
        {"tests", csg_model},
        {"bench/csg_scene.frac", read_file(std::string(FRAC_SOURCE_DIR) + "/bench/csg_scene.frac")},
        {"examples/menger_frame.frac",
         read_file(std::string(FRAC_SOURCE_DIR) + "/examples/menger_frame.frac")},
    };
    for (const std::string& file : stdlib_files()) sources.push_back({file, "import \"" + file + "\";"});
    std::set<std::string> seen;
    std::uint64_t pruned_evaluations = 0;
    for (const auto& [where, text] : sources) {
        const Model m = compile(text);
        for (std::size_t i = 0; i < m.tapes.size(); ++i) {
            const front::ShapeInfo& s = m.shape(i);
            if (!seen.insert(s.name).second) continue;
            INFO(where << ": shape " << s.name);
            ir::EvalOptions off;
            off.prune = false;
            auto plain = TestType::make(m.tapes[i], off);
            auto pruning = TestType::make(m.tapes[i]);
            rt::RssOptions o;
            o.depth = s.dimension == 2 ? 7 : 4;
            o.threads = 2; // pruned variants are evaluated per thread too
            const rt::RssResult a = rt::subdivide(*plain, s.box, o);
            const rt::RssResult b = rt::subdivide(*pruning, s.box, o);
            CHECK(rt::same_cover(a, b));
            CHECK(a.pruned_evaluations == 0);
            pruned_evaluations += b.pruned_evaluations;
        }
    }
    // The interpreter prunes the CSG shapes (the JIT at these depths compiles none: too few boxes).
    if (std::string(TestType::name) == "interp") CHECK(pruned_evaluations > 1000);
}

TEST_CASE("pruned covers are identical across engines", "[llvm][prune][rss]") {
    const Model m = compile(read_file(std::string(FRAC_SOURCE_DIR) + "/bench/csg_scene.frac"));
    const front::ShapeInfo& s = info_of(m, "csg_scene");
    auto in = InterpEngine::make(tape_of(m, "csg_scene"));
    auto jt = JitEngine::make(tape_of(m, "csg_scene"));
    rt::RssOptions o;
    o.depth = 8;
    const rt::RssResult a = rt::subdivide(*in, s.box, o);
    const rt::RssResult b = rt::subdivide(*jt, s.box, o);
    CHECK(rt::same_cover(a, b));
    CHECK(a.pruned_evaluations > a.evaluated / 2);
    CHECK(in->specialize_stats.requests > 0);
    // The JIT records only far enough above the depth (jit_min_expected_evaluations).
    CHECK(jt->specialize_stats.requests > 0);
    CHECK(jt->specialize_stats.requests < in->specialize_stats.requests);
    // Which cells evaluate which pruned function does not depend on the thread count.
    auto in2 = InterpEngine::make(tape_of(m, "csg_scene"));
    o.threads = 2;
    const rt::RssResult c = rt::subdivide(*in2, s.box, o);
    CHECK(rt::same_cover(a, c));
    CHECK(c.pruned_evaluations == a.pruned_evaluations);
    CHECK(c.specializations == a.specializations);
    CHECK(in2->stats.series_terms == in->stats.series_terms);
}

TEMPLATE_TEST_CASE("a 3D CSG cover is the same with and without pruning", "[llvm][prune][rss]", InterpEngine,
                   JitEngine) {
    const Model m = compile(read_file(std::string(FRAC_SOURCE_DIR) + "/examples/menger_frame.frac"));
    const front::ShapeInfo& s = info_of(m, "sponge_in_frame");
    ir::EvalOptions off;
    off.prune = false;
    auto plain = TestType::make(tape_of(m, "sponge_in_frame"), off);
    auto pruning = TestType::make(tape_of(m, "sponge_in_frame"));
    rt::RssOptions o;
    o.depth = 7; // deep enough for cells prune_min_remaining levels above the depth to be split
    o.keep_cells = true;
    o.threads = 2;
    const rt::RssResult a = rt::subdivide(*plain, s.box, o);
    const rt::RssResult b = rt::subdivide(*pruning, s.box, o);
    CHECK(rt::same_cover(a, b));
    // The JIT records only where a pruned tape could repay it (tested above): not on this short tape.
    if (std::string(TestType::name) == "interp") {
        CHECK(pruning->specialize_stats.requests > 0);
        CHECK(b.pruned_evaluations > 0);
    }
}

TEST_CASE("a large model's tapes shrink down the tree, and its cover stays the same", "[llvm][prune][rss]") {
    // Text strokes, buildings and blends: 600 clauses, thousands of instructions.
    const bench::LargeModel big = bench::large_model(600);
    const Model m = compile(big.source);
    const ir::Tape& tape = tape_of(m, big.name);
    const front::ShapeInfo& s = info_of(m, big.name);
    ir::EvalOptions off;
    off.prune = false;
    auto plain = InterpEngine::make(tape, off);
    auto pruning = InterpEngine::make(tape);
    rt::RssOptions o;
    o.depth = 8;
    const rt::RssResult a = rt::subdivide(*plain, s.box, o);
    const rt::RssResult b = rt::subdivide(*pruning, s.box, o);
    CHECK(rt::same_cover(a, b));
    // Every level with children asks to prune, and the functions shrink down the tree (each cell's is
    // its parent's or a pruned one of it; the mix of cells changes from level to level) to the last
    // level whose cells prune (in 2D 3 levels above the depth: interp_min_expected_evaluations): at the
    // depth a cell evaluates a small part of the model.
    const auto mean = [&](int k) {
        const auto level = static_cast<std::size_t>(k);
        return b.prune_levels[level].instructions / static_cast<double>(b.levels[level].evaluated);
    };
    for (int k = 0; k < o.depth; ++k) CHECK(b.prune_levels[static_cast<std::size_t>(k)].requests > 0);
    const double full = static_cast<double>(tape.instruction_count());
    INFO("instructions per evaluation: " << mean(2) << " at level 2, " << mean(5) << " at 5, "
                                         << mean(o.depth) << " at the depth, " << full << " unpruned");
    CHECK(mean(5) < 0.5 * mean(2));
    CHECK(mean(o.depth) < mean(5));
    CHECK(mean(o.depth) < 0.04 * full);
    CHECK(b.prune_levels[static_cast<std::size_t>(o.depth)].requests == 0); // no children to prune for
    CHECK(pruning->specialize_stats.requests ==
          pruning->specialize_stats.unpruned + pruning->specialize_stats.too_little +
              pruning->specialize_stats.pushes + pruning->specialize_stats.hits); // hits: a sibling's tape
}

TEST_CASE("the default engine interprets a large model with choices, and compiles a small one",
          "[llvm][prune]") {
    const bench::LargeModel big = bench::large_model(200);
    const Model m = compile(big.source);
    const front::ShapeInfo& s = info_of(m, big.name);
    CHECK(tape_of(m, big.name).instruction_count() > 1000);
    driver::EngineOptions options; // the default engine: "jit"
    CHECK(driver::make_evaluator(m.c->module, s.root, s.dimension, options)->engine() == "interp");
    const Model small = compile(csg_model);
    const front::ShapeInfo& scene = info_of(small, "scene");
    CHECK(driver::make_evaluator(small.c->module, scene.root, scene.dimension, options)->engine() == "jit");
}

namespace {

// A sum of `terms` square roots of distances to distinct points (no min/max to prune), written as groups of
// 100 terms so that the parser's recursion stays shallow.
std::string long_sum(int terms) {
    std::string sum;
    for (int g = 0; g * 100 < terms; ++g) {
        std::string group;
        for (int i = g * 100; i < std::min(terms, (g + 1) * 100); ++i)
            group += fmt::format("{}sqrt((x - {:.6f})^2 + (y - {:.6f})^2 + 0.01)", group.empty() ? "" : " + ",
                                 std::fmod(i * 0.6180339887, 1.0), std::fmod(i * 0.7548776662, 1.0));
        sum += (sum.empty() ? "(" : " + (") + group + ")";
    }
    return fmt::format("shape s(x, y) over [-1, 1] × [-1, 1] = ({}) / {} - 0.75;\n", sum, terms);
}

} // namespace

TEST_CASE("a tape past 10,000 instructions: the JIT compiles it with fast machine code, the default engine "
          "only once the interpreted work foretells a long job, and past 40,000 both interpret",
          "[llvm][prune]") {
    const Model m = compile(long_sum(1500));
    const front::ShapeInfo& s = info_of(m, "s");
    const ir::Tape& tape = tape_of(m, "s");
    const std::size_t n = tape.instruction_count();
    INFO(n << " instructions");
    REQUIRE(n > 10000);
    REQUIRE(n < 40000);
    driver::EngineOptions options;
    options.engine = "interp";
    const auto interpreted = driver::make_evaluator(m.c->module, s.root, s.dimension, options);
    const std::vector<ir::Interval> boxes = {{0.1, 0.2}, {0.3, 0.4}, {-1, 1},
                                             {-1, 1},    {0.5, 0.5}, {0.25, 0.75}};
    std::vector<ir::Interval> want(3), got(3);
    interpreted->eval_boxes(boxes.data(), 3, want.data());
    const auto same = [&](ir::Evaluator& e) {
        e.eval_boxes(boxes.data(), 3, got.data());
        for (std::size_t i = 0; i < 3; ++i) {
            CHECK(got[i].lo == want[i].lo);
            CHECK(got[i].hi == want[i].hi);
        }
    };

    // Asked for by name: compiled at once, the fast machine code, the interpreter's bits.
    options.engine = "jit";
    const auto jitted = driver::make_evaluator(m.c->module, s.root, s.dimension, options);
    REQUIRE(jitted->engine() == "jit");
    REQUIRE(jit::compile_info(*jitted) != nullptr);
    CHECK(jit::compile_info(*jitted)->fast_codegen);
    same(*jitted);

    // The default engine: interpreted, no compile started, until the interpreter has worked three
    // times what the compile will take.
    CHECK(jit::long_tape_start_after(tape).count() ==
          static_cast<std::int64_t>(3 * 0.15e6 * static_cast<double>(n)));
    options.engine = "auto";
    const auto automatic = driver::make_evaluator(m.c->module, s.root, s.dimension, options);
    REQUIRE(automatic->engine() == "auto");
    same(*automatic);
    CHECK(jit::tier_status(*automatic)->tier == jit::Tier::interpreter);
    CHECK_FALSE(jit::tier_status(*automatic)->compile_started);

    // The same rule with a delay of 1 ns: no compile before the first call, one once a clone's call
    // (the time is shared) has worked that long; its fast code is the last tier.
    jit::JitConfig fast;
    fast.fast_codegen = true;
    const auto tiered =
        jit::make_tiered(tape, {}, fast, jit::TierSwitch::when_ready, std::chrono::nanoseconds{1});
    const auto clone = tiered->clone();
    CHECK_FALSE(jit::tier_status(*tiered)->compile_started);
    same(*clone);
    CHECK(jit::tier_status(*tiered)->compile_started);
    jit::wait_for_tier(*tiered);
    same(*tiered);
    CHECK(jit::tier_status(*tiered)->tier == jit::Tier::optimized); // the fast code, with nothing after it
    CHECK_FALSE(jit::wait_for_optimized_tier(*tiered));

    const Model huge = compile(long_sum(6000));
    const front::ShapeInfo& hs = info_of(huge, "s");
    REQUIRE(tape_of(huge, "s").instruction_count() > 40000);
    for (const char* engine : {"jit", "auto"}) {
        options.engine = engine;
        CHECK(driver::make_evaluator(huge.c->module, hs.root, hs.dimension, options)->engine() == "interp");
    }
}
