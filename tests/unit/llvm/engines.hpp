// Shared pieces of the LLVM backend's tests and of the conformance suite (tests/conformance): the
// engines as template parameters, shape compilation, random boxes and points, and bit-exact comparison.
#pragma once

#include "backend/interp/interpreter.hpp"
#include "backend/llvm/aot.hpp"
#include "backend/llvm/jit.hpp"
#include "backend/llvm/tiered.hpp"
#include "driver/pipeline.hpp"
#include "ir/graph.hpp"
#include "ir/tape.hpp"

#include <bit>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace frac::test {

using ir::Interval;

// The engines the conformance suite is instantiated for. `counts_series`: the engine reports series
// terms and capped series in EvalStats (compiled models have no counters in their C ABI).
struct InterpEngine {
    static constexpr const char* name = "interp";
    static constexpr bool counts_series = true;
    static std::unique_ptr<ir::Evaluator> make(const ir::Tape& t, const ir::EvalOptions& o = {}) {
        return interp::make_interpreter(t, o);
    }
};
struct JitEngine {
    static constexpr const char* name = "jit";
    static constexpr bool counts_series = true;
    static std::unique_ptr<ir::Evaluator> make(const ir::Tape& t, const ir::EvalOptions& o = {}) {
        return jit::make_jit(t, o);
    }
};
// The command line's default engine ("auto"): the interpreter while the JIT compiles in the background,
// for tapes where both give the same bits; other tapes are compiled first, as the driver does.
struct TieredEngine {
    static constexpr const char* name = "auto";
    static constexpr bool counts_series = true;
    static std::unique_ptr<ir::Evaluator> make(const ir::Tape& t, const ir::EvalOptions& o = {}) {
        return jit::tiers_exactly(t) ? jit::make_tiered(t, o, {}) : jit::make_jit(t, o);
    }
};
// The JIT with the numeric core's calls in place of the inline sin, cos, exp, tan, log, pow and atan2 kernels
// (FRAC_JIT_EXACT_CALLS=1): the interpreter's bits, for the checks that compare engines bit for bit.
inline std::unique_ptr<ir::Evaluator> make_jit_exact_calls(const ir::Tape& t, const ir::EvalOptions& o = {},
                                                           const jit::JitConfig& config = {}) {
    setenv("FRAC_JIT_EXACT_CALLS", "1", 1);
    auto e = jit::make_jit(t, o, config);
    unsetenv("FRAC_JIT_EXACT_CALLS");
    return e;
}
// The tape compiled as `frac compile -o model.so` compiles it, loaded with dlopen (backend/llvm/aot.hpp).
struct AotEngine {
    static constexpr const char* name = "aot";
    static constexpr bool counts_series = false;
    static std::unique_ptr<ir::Evaluator> make(const ir::Tape& t, const ir::EvalOptions& o = {}) {
        return jit::make_aot(t, o);
    }
};

// Same bits (so 0 and -0 differ); any two NaNs count as equal.
inline bool same(double a, double b) {
    if (std::isnan(a) && std::isnan(b)) return true;
    return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}
inline bool same(Interval a, Interval b) {
    return same(a.lo, b.lo) && same(a.hi, b.hi);
}

inline std::string hex(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%a", v);
    return buf;
}
inline std::string hex(Interval v) {
    return "[" + hex(v.lo) + ", " + hex(v.hi) + "]";
}
inline std::string hex_box(const Interval* b, int d) {
    std::string s;
    for (int k = 0; k < d; ++k) s += (k ? " x " : "") + hex(b[k]);
    return s;
}

// A compiled model and the tapes of its shapes.
struct Model {
    std::unique_ptr<front::Compilation> c;
    std::vector<ir::Tape> tapes; // one per shape, in module order
    const front::ShapeInfo& shape(std::size_t i) const { return c->module.shapes[i]; }
};

inline Model compile(const std::string& text) {
    Model m;
    m.c = driver::compile_source("t.frac", text);
    if (!m.c->ok()) FAIL(m.c->diags.render(m.c->sources));
    for (const front::ShapeInfo& s : m.c->module.shapes)
        m.tapes.push_back(ir::build_tape(m.c->module.graph, s.root, s.dimension));
    return m;
}

// Every shape of the standard library (each file imported on its own).
inline std::vector<std::string> stdlib_files() {
    std::vector<std::string> names;
    for (const auto& [name, text] : front::embedded_stdlib()) names.push_back(name);
    return names;
}

// Series of every kind, as shapes over x, y: finite and infinite, with B, nested, orbits, escape
// certificates. Every one must compile: a skipped case would shrink the checks silently.
inline const std::vector<std::string>& series_kinds() {
    static const std::vector<std::string> exprs = {
        "sum(i in 0..5, x^i) - y",
        "min(i in 2..9, dz(2^i * x) - y / i)",
        "max(i in 0..0, x * i + y)",
        "y - sum(i in 0.., dz(2^i * x) / 2^i)",
        "y - sum(i in 1.., floor(i * x) / 2^i)",
        "y - max(i in 0.., (dz(3^i * x) - 1/3) / 3^i)",
        "min(i in 0.., (1/3 - min(dz(3^i * x), dz(3^i * y))) / 3^i)",
        "y - sum(i in 0.., sum(j in 0..3, dz(2^j * x) / 2^j) / 4^i)",
        "y - sum(i in 0.., sin(2^i * x) * x / 2^i)",
        "y - sum(i in 1.., i * x / 3^i)",
        "min(k in 0.., p in orbit((x, y), shrink), (sqrt(p.x^2 + p.y^2) - 0.3) / 2^k)",
        "min(k in 0.., p in orbit((x, y), swap), (dz(p.x) - 0.5 * dz(p.y)) / 2^k)",
        "max(k in 0.., p in orbit((x, y), grow), (dz(p.x) - abs(p.y)) / 3^k)",
        // Escape certificates (frontend/orbit_escape): tails tightened from the orbit box.
        "min(k in 0.., p in orbit((x, y), grow) escape 1/2, (sqrt(p.x^2 + p.y^2) - 0.2) / 3^k)",
        "max(k in 0.., p in orbit((x, y), grow) escape 1, (0.7 - sqrt(p.x^2 + p.y^2)) / 3^k) + 0.01",
        "min(k in 0.., p in orbit((x, y), fold) escape 1/2, (sqrt(p.x^2 + p.y^2) - 0.28) / 3^k)",
    };
    return exprs;
}
// The maps the orbits of series_kinds() use, to put before the shape.
inline const std::string series_maps =
    "fn shrink(p) = (p.x / 2 + 0.1, p.y / 2); fn swap(p) = (p.y, p.x);"
    "fn grow(p) = (3 * p.x, 3 * p.y - 1);"
    "fn fold(p) = let r = sqrt(p.x^2 + p.y^2), f = pi / 3 * (2 * dz(atan2(abs(p.y), p.x) * "
    "3 / pi / 2 + 1/4) - 1/2) in (3 * r * cos(f) - 1, 3 * r * sin(f));";

// Random boxes that stress the interval code: thin boxes, tiny to huge widths, boxes on integers,
// half-integers and thirds (where dz, floor and mod1 change), boxes around 0, unbounded coordinates.
class BoxMaker {
public:
    explicit BoxMaker(std::uint64_t seed) : rng_(seed) {}

    double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng_); }
    int pick(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng_); }

    double position(Interval range) {
        const double span = range.hi - range.lo;
        switch (pick(8)) {
        case 0: return range.lo + span * pick(9) / 8.0;           // dyadic points
        case 1: return range.lo + span * pick(28) / 27.0;         // triadic points
        case 2: return std::ldexp(uniform(-1, 1), -pick(60));     // near 0
        case 3: return uniform(range.lo - span, range.hi + span); // beyond the default box
        default: return uniform(range.lo, range.hi);
        }
    }
    Interval coordinate(Interval range) {
        const double c = position(range);
        switch (pick(12)) {
        case 0: return Interval(c);                                                    // thin
        case 1: return {c, c + std::ldexp(1.0, -pick(50))};                            // tiny
        case 2: return {c - std::ldexp(1.0, pick(40)), c + std::ldexp(1.0, pick(40))}; // huge
        case 3: return pick(2) ? Interval{-num::inf, c} : Interval{c, num::inf};
        case 4: return {-std::ldexp(1.0, -pick(30)), std::ldexp(1.0, -pick(30))}; // around 0
        default: {
            const double w = (range.hi - range.lo) * std::ldexp(1.0, -pick(14));
            return {c, c + w};
        }
        }
    }
    std::vector<Interval> box(const std::vector<Interval>& range) {
        std::vector<Interval> b;
        for (const Interval& r : range) b.push_back(coordinate(r));
        return b;
    }
    std::vector<double> point(const std::vector<Interval>& range) {
        std::vector<double> p;
        for (const Interval& r : range) p.push_back(position(r));
        return p;
    }

private:
    std::mt19937_64 rng_;
};

// Random expression graphs over x, y with every non-series opcode and constants of every kind.
// `typed`: graphs the language can write (finite constants; logic operations on truth values only,
// as conditions of selects), where point and interval semantics agree.
inline ir::NodeId random_node(ir::Graph& g, BoxMaker& mk, int depth, bool typed = false) {
    using ir::Op;
    if (depth == 0 || mk.pick(6) == 0) {
        switch (mk.pick(6)) {
        case 0: return g.var(0);
        case 1: return g.var(1);
        case 2: {
            const double vals[] = {0.0, -0.0, 1.0,    -1.0,  0.5,      3.0,
                                   0.1, 2.75, 1e-310, 1e300, num::inf, -num::inf};
            return g.constant(vals[mk.pick(typed ? 8 : 12)]);
        }
        case 3: return g.constant(Interval{-mk.uniform(0, 2), mk.uniform(0, 2)}, 0.0);
        case 4: return g.constant(Interval{0.0, 1.0}, 0.5);
        default: return g.var(mk.pick(2));
        }
    }
    static const Op ops[] = {Op::Add,  Op::Sub, Op::Mul, Op::Div, Op::Neg,   Op::Sqr,   Op::PowI, Op::Pow,
                             Op::Sqrt, Op::Abs, Op::Min, Op::Max, Op::Floor, Op::Ceil,  Op::Mod1, Op::Dz,
                             Op::Sin,  Op::Cos, Op::Tan, Op::Exp, Op::Log,   Op::Atan2, Op::Lt,   Op::Le,
                             Op::Gt,   Op::Ge,  Op::Eq,  Op::Ne,  Op::And,   Op::Or,    Op::Not,  Op::Select};
    const Op op = ops[mk.pick(static_cast<int>(std::size(ops)))];
    const int n = ir::arity(op);
    ir::NodeId a[3] = {ir::no_node, ir::no_node, ir::no_node};
    for (int k = 0; k < n; ++k) a[k] = random_node(g, mk, depth - 1, typed);
    const std::int64_t imm = op == Op::PowI ? mk.pick(9) - 4 : 0;
    if (typed && ir::op_class(op) == ir::OpClass::logic) {
        // A condition: a comparison, a truth value of unknown sign, or a combination of comparisons.
        static const Op tests[] = {Op::Lt, Op::Le, Op::Gt, Op::Ge};
        auto condition = [&] {
            if (mk.pick(4) == 0) return g.constant(Interval{0.0, 1.0}, 0.5);
            return g.op(tests[mk.pick(4)], random_node(g, mk, depth - 1, true),
                        random_node(g, mk, depth - 1, true));
        };
        ir::NodeId cond = condition();
        if (mk.pick(3) == 0) cond = g.op(mk.pick(2) ? Op::And : Op::Or, cond, condition());
        if (mk.pick(4) == 0) cond = g.op(Op::Not, cond);
        return g.op(Op::Select, cond, a[0], op == Op::Select ? a[1] : random_node(g, mk, depth - 1, true));
    }
    return g.op(op, a[0], a[1], a[2], imm);
}

} // namespace frac::test
