// The JIT computes what the interpreter computes, bit for bit: every standard-library shape, an
// expression for every opcode, random expression graphs, and the options that change series.
#include "crosscheck.hpp"

#include "ir/graph.hpp"

#include <set>

using namespace frac;
using namespace frac::test;

namespace {

std::vector<Interval> default_range(int d) {
    return std::vector<Interval>(static_cast<std::size_t>(d), {-2, 2});
}

} // namespace

TEST_CASE("every stdlib shape: JIT and interpreter agree bit for bit", "[llvm][crosscheck]") {
    std::set<std::string> seen;
    for (const std::string& file : stdlib_files()) {
        const Model m = compile("import \"" + file + "\";");
        for (std::size_t i = 0; i < m.tapes.size(); ++i) {
            const front::ShapeInfo& s = m.shape(i);
            if (!seen.insert(s.name).second) continue; // imported by an earlier file
            INFO(file << ": shape " << s.name);
            FRAC_REQUIRE_IDENTICAL(cross_check_all(m.tapes[i], s.box, 1000 + i, 1500));
        }
    }
}

TEST_CASE("fast and optimised machine code agree bit for bit, inline kernels included",
          "[llvm][crosscheck]") {
    // The tiered engine moves from the first to the second whenever the second is ready: every tape,
    // the ones with the loose inline kernels (sin, cos, exp, ...) too, must give the same bits.
    using R = jit::JitConfig::Rounding;
    std::vector<jit::JitConfig> configs = {jit::codegen_config(R::automatic, 0),
                                           jit::codegen_config(R::constrained, 4)};
    if (jit::host_has_avx512()) configs.push_back(jit::codegen_config(R::avx512, 1));
    std::vector<std::pair<ir::Tape, std::vector<Interval>>> tapes;
    std::set<std::string> seen;
    for (const std::string& file : stdlib_files()) {
        const Model m = compile("import \"" + file + "\";");
        for (std::size_t i = 0; i < m.tapes.size(); ++i)
            if (seen.insert(m.shape(i).name).second) tapes.emplace_back(m.tapes[i], m.shape(i).box);
    }
    for (const char* e : {"sin(x) * cos(3 * y) + tan(x - y)", "exp(x) - log(abs(y) + 1)", "atan2(y, x) + x^y",
                          "pow(abs(x), 1/3) + sin(x * y)^2"}) {
        const Model m = compile(std::string("shape s(x, y) = ") + e + ";");
        tapes.emplace_back(m.tapes[0], default_range(2));
    }
    std::size_t compared = 0, loose = 0;
    for (const jit::JitConfig& config : configs)
        for (std::size_t t = 0; t < tapes.size(); ++t) {
            const auto& [tape, range] = tapes[t];
            INFO(describe(config) << ", tape " << t);
            loose += has_loose_kernel(tape);
            auto optimised = jit::make_jit(tape, {}, config);
            auto fast = jit::make_jit(tape, {}, fast_codegen(config));
            BoxMaker mk(31 + t);
            const std::size_t n = 200;
            std::vector<Interval> boxes;
            std::vector<double> points;
            for (std::size_t k = 0; k < n; ++k) {
                const auto b = mk.box(range);
                boxes.insert(boxes.end(), b.begin(), b.end());
                const auto p = mk.point(range);
                points.insert(points.end(), p.begin(), p.end());
            }
            std::vector<Interval> bo(n), bf(n);
            optimised->eval_boxes(boxes.data(), n, bo.data());
            fast->eval_boxes(boxes.data(), n, bf.data());
            std::vector<double> po(n), pf(n);
            optimised->eval_points(points.data(), n, po.data());
            fast->eval_points(points.data(), n, pf.data());
            for (std::size_t k = 0; k < n; ++k) {
                INFO("box " << hex_box(&boxes[k * static_cast<std::size_t>(tape.inputs)], tape.inputs));
                REQUIRE(same(bo[k], bf[k]));
                REQUIRE(same(po[k], pf[k]));
                ++compared;
            }
            CHECK(optimised->stats.series_terms == fast->stats.series_terms);
        }
    CHECK(loose >= configs.size() * 4); // the inline kernels were among them
    CHECK(compared >= 200 * tapes.size() * configs.size());
}

TEST_CASE("series options: fixed term counts and small term limits agree", "[llvm][crosscheck]") {
    const Model m = compile("import \"fractals\"; import \"koch\";");
    for (int variant = 0; variant < 3; ++variant) {
        ir::EvalOptions o;
        if (variant == 0) o.adaptive_terms = false;
        if (variant == 1) o.max_terms = 3;
        if (variant == 2) {
            o.max_terms = 1;
            o.adaptive_terms = false;
        }
        for (std::size_t i = 0; i < m.tapes.size(); ++i) {
            INFO("variant " << variant << ": shape " << m.shape(i).name);
            FRAC_REQUIRE_IDENTICAL(cross_check_all(m.tapes[i], m.shape(i).box, 77 + i, 300, o));
        }
    }
}

TEST_CASE("an expression for every opcode agrees", "[llvm][crosscheck]") {
    // Each line is a shape over x, y; together they use every arithmetic and logic opcode, with
    // operands of every sign (the default range is [-2, 2] and BoxMaker goes beyond it).
    const char* exprs[] = {
        "x + y",
        "x - y",
        "x * y",
        "x / y",
        "1 / x",
        "-x",
        "x^2",
        "x^3",
        "x^4",
        "x^-1",
        "x^-2",
        "x^0 + y",
        "x^y",
        "abs(x)^y",
        "x^0.5",
        "pow(abs(x), 1/3)",
        "sqrt(x)",
        "sqrt(x^2 + y^2)",
        "abs(x - y)",
        "min(x, y)",
        "max(x, y)",
        "min(x, 1, y)",
        "floor(x * 3)",
        "ceil(y / 3)",
        "mod(x, 1)",
        "mod(3 * x, 1) - y",
        "dz(x)",
        "dz(5 * x + y)",
        "sin(x)",
        "cos(3 * y)",
        "tan(x)",
        "exp(x)",
        "log(x)",
        "log(abs(x) + y)",
        "atan2(y, x)",
        "if x < y then x else y",
        "if x <= y then x * x else -y",
        "if x > 0 then 1 else -1",
        "if x >= y and y > 0 then x else y",
        "if x == y then 1 else 0",
        "if x != 0.5 or y < 0 then x else 2",
        "if not (x < y) then x else y + 1",
        "if x < 0 then sqrt(x) else log(y)",
        "x / (y - y)",
        "x / 0",
        "(x - 1) / (y * y)",
        "x * 0",
        "0 * log(x)",
        "sqrt(-1 - x * x)",
        "x^(-3) + y^6",
        "x * y * x - y^5",
        "[0.1, 0.2] * x + [-1, 1] / y",
        "exp(x * 800) - exp(y)",
        "1e300 * x * x + y",
        "-x^2 + dz(x * 1e17)",
        // Products by a positive factor, thin or not, down to results that round to -0 (the
        // corners' first zero decides the sign); sums and quotients the JIT knows cannot be NaN.
        "x * [2, 3] + [0.5, 0.75] * y",
        "min(x * 1e-5, 0) * [1e-320, 1e-300]",
        "min(x * 1e-5, 0) * 1e-320",
        "max(y, 0) * [1e-320, 1e-300] - x * 4e-324",
        "(x * 1e308 * 10) * [1, 2] + dz(y)",
        "dz(x) - dz(y) + mod(x * 1e308 * 10, 1)",
        "(x * 1e308 * 10) / [2, 3] + y / 3",
    };
    int k = 0;
    for (const char* e : exprs) {
        const Model m = compile(std::string("shape s(x, y) = ") + e + ";");
        INFO(e);
        FRAC_REQUIRE_IDENTICAL(
            cross_check_all(m.tapes[0], default_range(2), 500 + static_cast<std::uint64_t>(k++), 400));
    }
}

TEST_CASE("series of every kind agree: finite, infinite, with B, nested, orbits", "[llvm][crosscheck]") {
    int k = 0;
    for (const std::string& e : series_kinds()) {
        auto c = driver::compile_source("t.frac", series_maps + "shape s(x, y) = " + e + ";");
        INFO(e);
        INFO(c->diags.render(c->sources));
        REQUIRE(c->ok()); // every kind must compile: a skipped case would shrink the check silently
        const ir::Tape t = ir::build_tape(c->module.graph, c->module.shapes[0].root, 2);
        FRAC_REQUIRE_IDENTICAL(
            cross_check_all(t, {{0, 1}, {0, 1}}, 900 + static_cast<std::uint64_t>(k), 600));
        ir::EvalOptions o;
        o.max_terms = 4;
        FRAC_REQUIRE_IDENTICAL(
            cross_check_all(t, {{-1, 1}, {-1, 1}}, 950 + static_cast<std::uint64_t>(k++), 200, o));
    }
}

TEST_CASE("random expression graphs agree", "[llvm][crosscheck]") {
    BoxMaker mk(4242);
    for (int n = 0; n < 300; ++n) {
        ir::Graph g;
        const ir::NodeId root = random_node(g, mk, 5);
        const ir::Tape t = ir::build_tape(g, root, 2);
        INFO("graph " << n << ":\n" << ir::print_tape(t));
        FRAC_REQUIRE_IDENTICAL(
            cross_check_all(t, default_range(2), 7000 + static_cast<std::uint64_t>(n), 60));
    }
}

TEST_CASE("closed expressions (no coordinates) agree", "[llvm][crosscheck]") {
    ir::Graph g;
    const ir::NodeId root = g.op(ir::Op::Add, g.constant(1.0), g.constant(Interval{0.1, 0.2}, 0.15));
    const ir::Tape t = ir::build_tape(g, root, 0);
    auto in = interp::make_interpreter(t);
    auto jt = jit::make_jit(t);
    CHECK(jt->dimension() == 0);
    CHECK(same(in->eval_box(nullptr), jt->eval_box(nullptr)));
    CHECK(same(in->eval_point(nullptr), jt->eval_point(nullptr)));
}

TEST_CASE("dz floor ceil and mod agree on boxes ending at their breakpoints", "[llvm][crosscheck]") {
    // Every box whose ends are integers, half-integers, thirds and quarters, their neighbouring doubles,
    // at small and large magnitudes (past 2^52 every double is an integer): the JIT's shortcuts for dz
    // (its bounds from ceil lo and the integer nearest lo) must give the core's bits at each corner case.
    std::vector<double> ends = {-0.0, 1e-310, -1e-310, num::inf, -num::inf};
    for (double k : {-3.0, -1.0, 0.0, 1.0, 2.0, 0x1p52 - 1, 0x1p52, 0x1p53, 1e17, -1e300})
        for (double f : {0.0, 0.5, -0.5, 1.0 / 3, 0.25, 0.75, 0.999999}) {
            const double v = k + f;
            ends.insert(ends.end(), {v, std::nextafter(v, num::inf), std::nextafter(v, -num::inf)});
        }
    std::vector<Interval> boxes;
    for (double lo : ends)
        for (double hi : ends)
            if (lo <= hi && lo != num::inf && hi != -num::inf)
                boxes.insert(boxes.end(), {{lo, hi}, {0.0, 0.0}});
    // And boxes a little narrower or wider than a period, anywhere, whose width rounds in every way.
    BoxMaker mk(31337);
    for (int n = 0; n < 20000; ++n) {
        const double lo = mk.pick(9) - 4 + std::ldexp(mk.uniform(-1, 1), -mk.pick(60));
        const double w = 1 + (mk.pick(2) ? 1 : -1) * std::ldexp(1.0, -mk.pick(64));
        boxes.insert(boxes.end(), {{lo, lo + w}, {0.0, 0.0}});
    }
    for (const char* e : {"dz(x)", "floor(x) + ceil(x)", "mod(x, 1)", "dz(x) - dz(x + 0.5)"}) {
        const Model m = compile(std::string("shape s(x, y) = y + ") + e + ";");
        auto in = interp::make_interpreter(m.tapes[0]);
        const std::size_t count = boxes.size() / 2;
        std::vector<Interval> expected(count);
        in->eval_boxes(boxes.data(), count, expected.data());
        for (const jit::JitConfig& config : jit_configs()) {
            auto jt = jit::make_jit(m.tapes[0], {}, config);
            std::vector<Interval> got(count);
            jt->eval_boxes(boxes.data(), count, got.data());
            std::size_t mismatches = 0;
            std::string first;
            for (std::size_t n = 0; n < count; ++n)
                if (!same(expected[n], got[n]) && mismatches++ == 0)
                    first =
                        hex_box(&boxes[2 * n], 2) + ": interp " + hex(expected[n]) + ", jit " + hex(got[n]);
            INFO(e << ", " << describe(config) << ": " << first);
            CHECK(mismatches == 0);
        }
    }
}
