// Evaluator::eval_cells: the verdicts of cells from their integer coordinates and a level's grid table
// are those of eval_boxes on the cells' boxes followed by ir::classify, with the same counters: for the
// JIT's generated code (every lane width and rounding form) and for the default implementation (the
// interpreter), on 2D and 3D tapes, cells at the root's edges included.
#include "engines.hpp"

#include "runtime/cover.hpp"

#include <array>
#include <stdexcept>

using namespace frac;
using namespace frac::test;

namespace {

// The cells of level n (cells per axis) over `root`, as the cover builds them (runtime/rss.cpp), each
// checked against grid::cell: the outer cells clamped to the root.
ir::CellGrid level_grid(const std::vector<Interval>& root, std::uint64_t n) {
    ir::CellGrid g;
    std::vector<Interval> points;
    rt::grid::level_cells(root, n, g, points);
    num::UpwardRounding up;
    for (int a = 0; a < g.dimension(); ++a) {
        const Interval x = root[static_cast<std::size_t>(a)];
        for (std::uint64_t i = 0; i < n; ++i)
            REQUIRE(g.axis(a)[i] == rt::grid::cell(x, rt::grid::width(x), i, n));
    }
    return g;
}

// Coordinates of `count` cells of an n^d grid, `stride` values per cell (the others filled with junk):
// every cell of the grid's faces first (the boxes clamped to the root), then pseudo-random ones.
std::vector<std::uint32_t> some_cells(int d, std::uint32_t n, std::size_t count, std::size_t stride,
                                      std::uint32_t seed) {
    std::vector<std::uint32_t> c;
    std::mt19937 rng(seed);
    auto push = [&](std::array<std::uint32_t, 3> x) {
        for (std::size_t a = 0; a < stride; ++a)
            c.push_back(a < static_cast<std::size_t>(d) ? x[a] : 0xdeadbeef);
    };
    for (std::uint32_t i = 0; i < n && c.size() / stride < count / 2; ++i) {
        push({i, 0, d == 3 ? n - 1 : 0});
        push({0, i, 0});
        push({n - 1, i, d == 3 ? i : 0});
        push({i, n - 1, d == 3 ? n - 1 - i : 0});
    }
    std::uniform_int_distribution<std::uint32_t> any(0, n - 1);
    while (c.size() / stride < count) push({any(rng), any(rng), d == 3 ? any(rng) : 0});
    c.resize(count * stride);
    return c;
}

// The reference: the cells' boxes, eval_boxes, classify.
std::vector<ir::CellVerdict> by_boxes(ir::Evaluator& e, const ir::CellGrid& g, const std::uint32_t* coords,
                                      std::size_t stride, std::size_t n, bool closed) {
    const auto d = static_cast<std::size_t>(g.dimension());
    std::vector<Interval> boxes(n * d), out(n);
    for (std::size_t k = 0; k < n; ++k) g.box(coords + k * stride, &boxes[k * d]);
    e.eval_boxes(boxes.data(), n, out.data());
    std::vector<ir::CellVerdict> v(n);
    for (std::size_t k = 0; k < n; ++k) v[k] = ir::classify(out[k], closed);
    return v;
}

bool same_stats(const ir::EvalStats& a, const ir::EvalStats& b) {
    return a.calls == b.calls && a.series_terms == b.series_terms && a.series_capped == b.series_capped;
}

// eval_cells against the reference on one evaluator (fresh counters on each side).
void check_cells(ir::Evaluator& e, const ir::CellGrid& g, const std::vector<std::uint32_t>& coords,
                 std::size_t stride, bool closed, std::array<std::size_t, 3>* seen = nullptr) {
    const std::size_t n = coords.size() / stride;
    e.stats = {};
    const std::vector<ir::CellVerdict> want = by_boxes(e, g, coords.data(), stride, n, closed);
    const ir::EvalStats want_stats = e.stats;
    e.stats = {};
    std::vector<ir::CellVerdict> got(n + 1, ir::CellVerdict{7});
    e.eval_cells(g, coords.data(), stride, n, got.data(), closed);
    CHECK(got[n] == ir::CellVerdict{7}); // nothing written past the end
    got.resize(n);
    std::size_t differ = 0;
    for (std::size_t k = 0; k < n; ++k) {
        differ += got[k] != want[k];
        if (seen) ++(*seen)[static_cast<std::size_t>(want[k])];
    }
    CHECK(differ == 0);
    CHECK(same_stats(e.stats, want_stats));
}

struct Case {
    std::string import, shape;
};
const std::vector<Case> cases = {
    {"fractals", "carpet"},     // 2D, series
    {"fractals", "triangle"},   // 2D, series
    {"solids", "menger_holes"}, // 3D, series
    {"solids", "cantor_dust3"}, // 3D
    {"noise", "rough_ground"},  // 3D, sin and cos kernels
};

const ir::Tape& tape_of(const Model& m, const std::string& shape) {
    for (std::size_t i = 0; i < m.tapes.size(); ++i)
        if (m.shape(i).name == shape) return m.tapes[i];
    throw std::logic_error("no shape " + shape);
}

const front::ShapeInfo& info_of(const Model& m, const std::string& shape) {
    for (std::size_t i = 0; i < m.tapes.size(); ++i)
        if (m.shape(i).name == shape) return m.shape(i);
    throw std::logic_error("no shape " + shape);
}

} // namespace

TEST_CASE("eval_cells gives the verdicts of eval_boxes and classify", "[llvm][cells]") {
    std::vector<jit::JitConfig> configs = {jit::JitConfig{},
                                           jit::codegen_config(jit::JitConfig::Rounding::constrained, 1),
                                           jit::codegen_config(jit::JitConfig::Rounding::constrained, 4)};
    if (jit::host_has_avx512()) configs.push_back(jit::codegen_config(jit::JitConfig::Rounding::avx512, 1));
    for (const Case& c : cases) {
        const Model m = compile("import \"" + c.import + "\";");
        const ir::Tape& t = tape_of(m, c.shape);
        const front::ShapeInfo& s = info_of(m, c.shape);
        const int d = s.dimension;
        std::vector<std::unique_ptr<ir::Evaluator>> engines;
        for (const jit::JitConfig& config : configs) engines.push_back(jit::make_jit(t, {}, config));
        engines.push_back(InterpEngine::make(t));
        std::array<std::size_t, 3> seen{0, 0, 0};
        for (std::uint32_t n : {1u, 3u, 9u, 64u, 243u, 729u}) {
            if (d == 3 && n > 243) continue;
            const ir::CellGrid g = level_grid(s.box, n);
            REQUIRE(g.nonempty());
            for (std::size_t stride : {static_cast<std::size_t>(d), std::size_t{4}, std::size_t{5}}) {
                for (std::size_t count : {std::size_t{1}, std::size_t{7}, std::size_t{1203}}) {
                    const auto coords =
                        some_cells(d, n, count, stride, n * 31 + static_cast<std::uint32_t>(count));
                    for (bool closed : {false, true})
                        for (std::size_t e = 0; e < engines.size(); ++e) {
                            INFO(c.shape << ": " << n << " cells per axis, stride " << stride << ", " << count
                                         << " cells, closed " << closed << ", engine " << e);
                            check_cells(*engines[e], g, coords, stride, closed, &seen);
                        }
                }
            }
        }
        INFO(c.shape);
        CHECK(seen[static_cast<std::size_t>(ir::CellVerdict::undecided)] > 0);
        CHECK(seen[static_cast<std::size_t>(ir::CellVerdict::inside)] +
                  seen[static_cast<std::size_t>(ir::CellVerdict::outside)] >
              0);
    }
}

TEST_CASE("the JIT's eval_cells agrees with the default implementation and the interpreter",
          "[llvm][cells]") {
    const Model m = compile("import \"fractals\"; import \"solids\";");
    for (const std::string shape : {"carpet", "menger_holes"}) {
        const ir::Tape& t = tape_of(m, shape);
        const front::ShapeInfo& s = info_of(m, shape);
        const int d = s.dimension;
        auto jt = make_jit_exact_calls(t);
        auto in = InterpEngine::make(t);
        for (std::uint32_t n : {27u, 81u}) {
            const ir::CellGrid g = level_grid(s.box, n);
            const auto coords = some_cells(d, n, 2000, 4, n);
            const std::size_t k = coords.size() / 4;
            std::vector<ir::CellVerdict> a(k), b(k), c(k);
            jt->stats = {};
            jt->eval_cells(g, coords.data(), 4, k, a.data(), false);
            const ir::EvalStats sa = jt->stats;
            jt->stats = {};
            jt->ir::Evaluator::eval_cells(g, coords.data(), 4, k, b.data(), false); // the default
            const ir::EvalStats sb = jt->stats;
            in->stats = {};
            in->eval_cells(g, coords.data(), 4, k, c.data(), false);
            INFO(shape << ", " << n << " cells per axis");
            CHECK(a == b);
            CHECK(a == c);
            CHECK(same_stats(sa, sb));
            CHECK(same_stats(sa, in->stats));
        }
    }
}

TEST_CASE("eval_cells on a grid with an empty entry, and on bad input", "[llvm][cells]") {
    const Model m = compile("import \"fractals\";");
    const ir::Tape& t = tape_of(m, "carpet");
    auto jt = jit::make_jit(t);
    auto in = InterpEngine::make(t);
    ir::CellGrid g;
    const std::uint64_t cells[2] = {4, 3};
    g.assign(2, cells, [](int a, std::uint64_t i) {
        if (a == 1 && i == 1) return Interval::empty();
        const double x = static_cast<double>(i) / 4;
        return Interval{x, x + 0.25};
    });
    CHECK_FALSE(g.nonempty());
    std::vector<std::uint32_t> coords;
    for (std::uint32_t y = 0; y < 3; ++y)
        for (std::uint32_t x = 0; x < 4; ++x) coords.insert(coords.end(), {x, y});
    for (ir::Evaluator* e : {jt.get(), in.get()}) {
        check_cells(*e, g, coords, 2, false);
        std::vector<ir::CellVerdict> v(12);
        e->eval_cells(g, coords.data(), 2, 12, v.data(), false);
        for (std::size_t k = 4; k < 8; ++k) CHECK(v[k] == ir::CellVerdict::outside); // f undefined there

        std::vector<std::uint32_t> bad = coords;
        bad[2 * 7 + 1] = 3; // y = 3 of 3 cells
        CHECK_THROWS_AS(e->eval_cells(g, bad.data(), 2, 12, v.data(), false), std::out_of_range);
        CHECK_THROWS_AS(e->eval_cells(g, coords.data(), 1, 12, v.data(), false), std::invalid_argument);
        ir::CellGrid g3;
        const std::uint64_t c3[3] = {2, 2, 2};
        g3.assign(3, c3, [](int, std::uint64_t i) { return Interval{0.5 * static_cast<double>(i), 0.5}; });
        CHECK_THROWS_AS(e->eval_cells(g3, coords.data(), 3, 1, v.data(), false), std::invalid_argument);
        e->eval_cells(g, coords.data(), 2, 0, v.data(), false); // nothing to do
    }
    ir::CellGrid h;
    const std::uint64_t huge[2] = {4, (std::uint64_t{1} << 32) + 1};
    CHECK_THROWS_AS(h.assign(2, huge,
                             [](int, std::uint64_t) {
                                 return Interval{0, 1};
                             }),
                    std::invalid_argument);
    CHECK_THROWS_AS(h.assign(4, huge,
                             [](int, std::uint64_t) {
                                 return Interval{0, 1};
                             }),
                    std::invalid_argument);
}
