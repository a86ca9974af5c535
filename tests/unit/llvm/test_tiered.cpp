// The tiered engine ("auto"): the interpreter's bits before the compile finishes and after it, counters
// carried across the switch, pruning once the code is ready, covers equal to the JIT's.
#include "engines.hpp"

#include "runtime/rss.hpp"

#include <chrono>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <thread>
#include <unistd.h>

using namespace frac;
using namespace frac::test;

namespace {

const ir::Tape& only_tape(const Model& m) {
    REQUIRE(m.tapes.size() == 1);
    return m.tapes[0];
}

const char* const scene = R"(
fn disk(p, c, r) = sqrt((p.x - c.x)^2 + (p.y - c.y)^2) - r;
shape scene(x, y) over [-1, 1] × [-1, 1] =
    min(max(disk((x, y), (0, 0), 0.8), -disk((x, y), (0.3, 0.1), 0.3)),
        min(disk((x, y), (-0.6, 0.5), 0.2), y + 0.9 - sum(i in 0.., dz(2^i * x) / 2^i) / 4));
)";

} // namespace

TEST_CASE("which tapes the JIT computes bit for bit as the interpreter", "[llvm][tiered]") {
    // Exact operations, and powers with an integer exponent (the JIT's pow calls the core's powi).
    CHECK(jit::tiers_exactly(only_tape(compile(scene))));
    CHECK(jit::tiers_exactly(only_tape(compile("shape s(x, y) = y - sum(i in 0.., dz(3^i * x) / 3^i);"))));
    CHECK(jit::tiers_exactly(only_tape(compile("shape s(x, y) = y - x^3;"))));
    CHECK(jit::tiers_exactly(
        only_tape(compile("shape s(x, y) = y - sum(i in 0.., dz(3^(2 * i + 1) * x) / 3^(i + 1));"))));
    // Every shape of the solids (the sponge's 3^(17 + k) included).
    const Model solids = compile("import \"solids\";");
    for (std::size_t i = 0; i < solids.tapes.size(); ++i) {
        INFO(solids.shape(i).name);
        CHECK(jit::tiers_exactly(solids.tapes[i]));
    }
    // Inline kernels a few ulps wider than the core's.
    for (const char* loose :
         {"shape s(x, y) = sin(x) - y;", "shape s(x, y) = cos(x) - y;", "shape s(x, y) = exp(x) - y;",
          "shape s(x, y) = tan(x) - y;", "shape s(x, y) = log(x) - y;", "shape s(x, y) = x^y;",
          "shape s(x, y) = x^0.5 - y;", "shape s(x, y) = atan2(y, x) + x^3;",
          "shape s(x, y) = y - sum(i in 0.., dz(2^(i / 2) * x) / 2^i);"}) {
        INFO(loose);
        const Model m = compile(loose);
        CHECK_FALSE(jit::tiers_exactly(only_tape(m)));
        CHECK_THROWS_AS(jit::make_tiered(only_tape(m), {}, {}), std::invalid_argument);
    }
}

TEST_CASE("a tiered evaluator gives the interpreter's bits before and after its code is ready",
          "[llvm][tiered]") {
    const Model m = compile(scene);
    const ir::Tape& tape = only_tape(m);
    BoxMaker r(7);
    const std::vector<Interval> range{{-1, 1}, {-1, 1}};
    std::vector<Interval> boxes;
    std::vector<double> points;
    constexpr std::size_t n = 3000;
    for (std::size_t i = 0; i < n; ++i) {
        for (const Interval& c : r.box(range)) boxes.push_back(c);
        for (double c : r.point(range)) points.push_back(c);
    }
    auto reference = interp::make_interpreter(tape);
    std::vector<Interval> want(n);
    std::vector<double> want_points(n);
    reference->eval_boxes(boxes.data(), n, want.data());
    reference->eval_points(points.data(), n, want_points.data());

    auto tiered = jit::make_tiered(tape, {}, {});
    CHECK(tiered->engine() == "auto");
    CHECK(tiered->instruction_count() == reference->instruction_count());
    auto check_all = [&](ir::Evaluator& e, const char* when) {
        INFO(when);
        std::vector<Interval> got(n);
        std::vector<double> got_points(n);
        e.eval_boxes(boxes.data(), n, got.data());
        e.eval_points(points.data(), n, got_points.data());
        for (std::size_t i = 0; i < n; ++i) {
            INFO("box " << i << " " << hex_box(&boxes[2 * i], 2));
            REQUIRE(same(got[i], want[i]));
            REQUIRE(same(got_points[i], want_points[i]));
            REQUIRE(same(e.eval_box(&boxes[2 * i]), want[i]));
        }
    };
    check_all(*tiered, "at once (usually interpreted)");
    auto twin = tiered->clone();
    jit::wait_for_tier(*tiered);
    check_all(*tiered, "after the compile");
    check_all(*twin, "a clone made before the compile finished");
    // The counters add up across the switch: two passes count what two interpreted passes count.
    auto counted = interp::make_interpreter(tape);
    check_all(*counted, "the interpreter");
    CHECK(tiered->stats.calls == 2 * counted->stats.calls);
    CHECK(tiered->stats.series_terms == 2 * counted->stats.series_terms);
    CHECK(tiered->stats.series_capped == 2 * counted->stats.series_capped);
    CHECK(counted->stats.series_terms > 0);
    tiered->stats = {};
    tiered->eval_box(boxes.data());
    CHECK(tiered->stats.calls == 1);
}

TEST_CASE("once its code is ready a tiered evaluator prunes with the JIT", "[llvm][tiered][prune]") {
    const Model m = compile(scene);
    auto tiered = jit::make_tiered(only_tape(m), {}, {});
    jit::wait_for_tier(*tiered);
    const Interval cell[2] = {{0.5, 0.55}, {-0.95, -0.9}};
    std::shared_ptr<ir::Evaluator> pruned = tiered->specialize(cell, 1e9);
    const ir::SpecializeStats& st = tiered->specialize_stats;
    INFO("requests " << st.requests << " unpruned " << st.unpruned << " too little " << st.too_little
                     << " declined " << st.declined << " compiled " << st.compiled << " fallbacks "
                     << st.fallbacks);
    REQUIRE(pruned);
    CHECK(pruned->instruction_count() < tiered->instruction_count());
    CHECK(tiered->specialize_stats.requests == 1);
    CHECK(same(pruned->eval_box(cell), tiered->eval_box(cell)));
}

TEST_CASE("covers with the tiered engine are the JIT's, on several threads", "[llvm][tiered][rss]") {
    const Model m = compile(scene);
    const front::ShapeInfo& s = m.shape(0);
    for (int threads : {1, 2}) {
        INFO(threads << " threads");
        auto jt = jit::make_jit(only_tape(m));
        auto tiered = jit::make_tiered(only_tape(m), {}, {});
        rt::RssOptions o;
        o.depth = 9;
        o.threads = threads;
        const rt::RssResult a = rt::subdivide(*jt, s.box, o);
        const rt::RssResult b = rt::subdivide(*tiered, s.box, o);
        CHECK(rt::same_cover(a, b));
        CHECK(b.evaluated == a.evaluated);
    }
}

TEST_CASE("a tape with loose kernels changes engine only at a checkpoint past its threshold",
          "[llvm][tiered]") {
    const Model m =
        compile("shape s(x, y) over [-3, 3] × [-3, 3] = sin(3 * x) * cos(2 * y) + exp(x / 4) - 1.2;");
    const ir::Tape& tape = only_tape(m);
    REQUIRE_FALSE(jit::tiers_exactly(tape));
    BoxMaker r(11);
    const std::vector<Interval> range{{-3, 3}, {-3, 3}};
    std::vector<Interval> boxes;
    constexpr std::size_t n = 2000;
    for (std::size_t i = 0; i < n; ++i)
        for (const Interval& c : r.box(range)) boxes.push_back(c);
    std::vector<Interval> by_interp(n), by_jit(n), got(n);
    interp::make_interpreter(tape)->eval_boxes(boxes.data(), n, by_interp.data());
    jit::make_jit(tape)->eval_boxes(boxes.data(), n, by_jit.data());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < n; ++i) differ += !same(by_interp[i], by_jit[i]);
    REQUIRE(differ > 0); // the kernels' ulps: the test could not tell the engines apart otherwise

    auto tiered = jit::make_tiered(tape, {}, {}, jit::TierSwitch::checkpoints);
    const std::uint64_t threshold = jit::checkpoint_evaluations(tape);
    REQUIRE(threshold > 1);
    const auto all_same = [&](const std::vector<Interval>& want) {
        tiered->eval_boxes(boxes.data(), n, got.data());
        for (std::size_t i = 0; i < n; ++i)
            if (!same(got[i], want[i])) return false;
        return true;
    };
    // Interpreted, however long the compile has had, until a checkpoint has passed the threshold.
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    CHECK(all_same(by_interp));
    tiered->checkpoint(threshold - 1);
    CHECK(all_same(by_interp));
    CHECK_FALSE(tiered->specialize(boxes.data(), 1e9)); // nothing pruned before the switch
    tiered->checkpoint(threshold);
    CHECK(all_same(by_jit));
    CHECK(tiered->clone()->eval_box(boxes.data()) == by_jit[0]);
}

TEST_CASE("covers with checkpoints are the same on any threads and in every run", "[llvm][tiered][rss]") {
    const Model m =
        compile("shape s(x, y) over [-3, 3] × [-3, 3] = sin(3 * x) * cos(2 * y) + exp(x / 4) - 1.2;");
    const ir::Tape& tape = only_tape(m);
    rt::RssOptions o;
    o.depth = 13;
    o.keep_cells = true;
    std::vector<rt::RssResult> covers;
    for (int threads : {1, 2, 2, 1}) {
        auto tiered = jit::make_tiered(tape, {}, {}, jit::TierSwitch::checkpoints);
        o.threads = threads;
        covers.push_back(rt::subdivide(*tiered, m.shape(0).box, o));
        INFO("run " << covers.size() << ", " << threads << " threads");
        CHECK(rt::same_cover(covers.front(), covers.back()));
    }
    // Past the threshold: the switch happened inside these covers.
    CHECK(covers.front().evaluated > 2 * jit::checkpoint_evaluations(tape));
}

TEST_CASE("a tiered evaluator moves from the fast code to the optimised one once that repays",
          "[llvm][tiered]") {
    // An exact tape (moves at any call) and one with inline kernels (moves at checkpoints): the fast
    // code first, then the optimised code once the evaluations reach optimize_at, the same bits
    // throughout.
    for (const char* source :
         {scene, "shape s(x, y) over [-3, 3] × [-3, 3] = sin(2 * x) * cos(y) - 0.2 * y;"}) {
        const Model m = compile(source);
        const ir::Tape& tape = only_tape(m);
        const bool exact = jit::tiers_exactly(tape);
        INFO(source);
        auto tiered = jit::make_tiered(tape, {}, {},
                                       exact ? jit::TierSwitch::when_ready : jit::TierSwitch::checkpoints);
        auto reference = jit::make_jit(tape); // optimised code: the same bits as the fast code
        REQUIRE(jit::tier_status(*tiered));
        CHECK_FALSE(jit::tier_status(*reference));
        jit::wait_for_tier(*tiered);
        if (!exact) tiered->checkpoint(jit::checkpoint_evaluations(tape));
        BoxMaker r(11);
        const std::size_t n = 4096;
        std::vector<Interval> boxes, got(n), want(n);
        for (std::size_t k = 0; k < n; ++k) {
            const auto b = r.box({{-1, 1}, {-1, 1}});
            boxes.insert(boxes.end(), b.begin(), b.end());
        }
        reference->eval_boxes(boxes.data(), n, want.data());
        tiered->eval_boxes(boxes.data(), n, got.data());
        jit::TierStatus st = *jit::tier_status(*tiered);
        CHECK(st.tier == jit::Tier::fast);
        CHECK(st.evaluated == n);
        CHECK(st.optimize_at >= 1);
        CHECK(st.optimize_at < std::numeric_limits<std::uint64_t>::max()); // set by the fast compile
        // Until the threshold, no optimised compile; at it, one is asked for.
        while (st.evaluated + n < st.optimize_at) {
            tiered->eval_boxes(boxes.data(), n, got.data());
            st = *jit::tier_status(*tiered);
            REQUIRE_FALSE(st.optimize_asked);
        }
        while (!st.optimize_asked) {
            tiered->eval_boxes(boxes.data(), n, got.data());
            st = *jit::tier_status(*tiered);
        }
        for (std::size_t k = 0; k < n; ++k) REQUIRE(same(got[k], want[k]));
        REQUIRE(jit::wait_for_optimized_tier(*tiered));
        CHECK(jit::tier_status(*tiered)->optimized_ready);
        tiered->eval_boxes(boxes.data(), n, got.data());
        CHECK(jit::tier_status(*tiered)->tier == jit::Tier::optimized);
        for (std::size_t k = 0; k < n; ++k) REQUIRE(same(got[k], want[k]));
        // A clone made now starts on the optimised code at its first call.
        auto clone = tiered->clone();
        clone->eval_boxes(boxes.data(), n, got.data());
        CHECK(jit::tier_status(*clone)->tier == jit::Tier::optimized);
        for (std::size_t k = 0; k < n; ++k) REQUIRE(same(got[k], want[k]));
    }
}

TEST_CASE("with a warm code cache the tiered engine starts on the optimised code", "[llvm][tiered]") {
    const Model m = compile(scene);
    const ir::Tape& tape = only_tape(m);
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("frac-test-tiered-cache-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    jit::JitConfig config;
    config.cache_dir = (dir / "cache").string();
    const std::vector<Interval> box{{-0.5, 0.25}, {0.1, 0.2}};
    {
        // A cold cache: the fast code first, stored under its own key.
        auto tiered = jit::make_tiered(tape, {}, config);
        jit::wait_for_tier(*tiered);
        tiered->eval_box(box.data());
        CHECK(jit::tier_status(*tiered)->tier == jit::Tier::fast);
    }
    // The optimised code, stored by a plain JIT: now the tiered engine takes it from the cache at once
    // and never compiles.
    const Interval want = jit::make_jit(tape, {}, config)->eval_box(box.data());
    const auto dir_of_cache = dir / "cache";
    const auto stored = std::distance(std::filesystem::directory_iterator(dir_of_cache),
                                      std::filesystem::directory_iterator());
    CHECK(stored == 2); // the fast code's and the optimised code's
    auto tiered = jit::make_tiered(tape, {}, config);
    jit::wait_for_tier(*tiered);
    CHECK(same(tiered->eval_box(box.data()), want));
    const jit::TierStatus st = *jit::tier_status(*tiered);
    CHECK(st.tier == jit::Tier::optimized);
    CHECK(st.optimize_at == std::numeric_limits<std::uint64_t>::max());
    CHECK(std::distance(std::filesystem::directory_iterator(dir_of_cache),
                        std::filesystem::directory_iterator()) == stored);
    // Only from the cache: a tape not in it is not compiled.
    jit::JitConfig only = config;
    only.cache_only = true;
    CHECK_THROWS_AS(jit::make_jit(only_tape(compile("shape s(x, y) = x * y - 0.125;")), {}, only),
                    jit::NotCached);
    std::filesystem::remove_all(dir);
}

TEST_CASE("a compile that waits for the interpreter's work takes warm cached code at once",
          "[llvm][tiered]") {
    const Model m = compile(scene);
    const ir::Tape& tape = only_tape(m);
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("frac-test-tiered-probe-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    jit::JitConfig config;
    config.cache_dir = (dir / "cache").string();
    const std::vector<Interval> box{{-0.5, 0.25}, {0.1, 0.2}};
    const auto idle = [] {
        while (jit::background_compile_pending()) std::this_thread::sleep_for(std::chrono::milliseconds{1});
    };
    const std::chrono::nanoseconds hour = std::chrono::hours{1};
    {
        // A cold cache: the look into it finds nothing, and the compile still waits.
        auto tiered = jit::make_tiered(tape, {}, config, jit::TierSwitch::when_ready, hour);
        idle();
        tiered->eval_box(box.data());
        CHECK(jit::tier_status(*tiered)->tier == jit::Tier::interpreter);
        CHECK_FALSE(jit::tier_status(*tiered)->compile_started);
    }
    const Interval want = jit::make_jit(tape, {}, config)->eval_box(box.data());
    // A warm one: the code is taken without waiting an hour of interpreted work.
    auto tiered = jit::make_tiered(tape, {}, config, jit::TierSwitch::when_ready, hour);
    idle();
    CHECK(same(tiered->eval_box(box.data()), want));
    CHECK(jit::tier_status(*tiered)->tier == jit::Tier::optimized);
    CHECK(jit::tier_status(*tiered)->compile_started);
    // Without a cache there is nothing to look into.
    auto uncached = jit::make_tiered(tape, {}, {}, jit::TierSwitch::when_ready, hour);
    idle();
    uncached->eval_box(box.data());
    CHECK(jit::tier_status(*uncached)->tier == jit::Tier::interpreter);
    std::filesystem::remove_all(dir);
}

TEST_CASE("a compile that waits starts when the work foreseen would repay it, not by the time spent",
          "[llvm][tiered]") {
    const Model m = compile(scene);
    const ir::Tape& tape = only_tape(m);
    const std::vector<Interval> box{{-0.5, 0.25}, {0.1, 0.2}};
    const Interval want = jit::make_jit(tape)->eval_box(box.data());
    {
        // An hour of interpreted work to repay: a forecast of a thousand evaluations does not start
        // the compile, one of 10^18 does.
        auto tiered = jit::make_tiered(tape, {}, {}, jit::TierSwitch::when_ready, std::chrono::hours{1});
        tiered->foresee(1e18); // no rate measured yet: nothing is decided
        CHECK_FALSE(jit::tier_status(*tiered)->compile_started);
        for (int i = 0; i < 100; ++i) CHECK(same(tiered->eval_box(box.data()), want));
        tiered->foresee(1000);
        CHECK_FALSE(jit::tier_status(*tiered)->compile_started);
        tiered->clone()->foresee(1e18); // clones share the state
        CHECK(jit::tier_status(*tiered)->compile_started);
        jit::wait_for_tier(*tiered);
        CHECK(same(tiered->eval_box(box.data()), want));
        CHECK(jit::tier_status(*tiered)->tier != jit::Tier::interpreter);
    }
    {
        // Once the work to come is foreseen, the time spent no longer starts it: 1 ns of interpreted
        // work would have.
        auto tiered =
            jit::make_tiered(tape, {}, {}, jit::TierSwitch::when_ready, std::chrono::nanoseconds{1});
        tiered->foresee(0);
        for (int i = 0; i < 100; ++i) CHECK(same(tiered->eval_box(box.data()), want));
        CHECK_FALSE(jit::tier_status(*tiered)->compile_started);
        CHECK(jit::tier_status(*tiered)->tier == jit::Tier::interpreter);
    }
    {
        // A compile that starts at once has nothing to decide.
        auto tiered = jit::make_tiered(tape, {}, {});
        tiered->foresee(0);
        CHECK(jit::tier_status(*tiered)->compile_started);
    }
}
