// Shared pieces of the LLVM backend's tests: the two engines as template parameters, shape
// compilation, random boxes and points, and bit-exact comparison.
#pragma once

#include "backend/interp/interpreter.hpp"
#include "backend/llvm/jit.hpp"
#include "driver/pipeline.hpp"
#include "ir/graph.hpp"
#include "ir/tape.hpp"

#include <bit>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace frac::test {

using ir::Interval;

// The engines the conformance suite is instantiated for.
struct InterpEngine {
    static constexpr const char* name = "interp";
    static std::unique_ptr<ir::Evaluator> make(const ir::Tape& t, const ir::EvalOptions& o = {}) {
        return interp::make_interpreter(t, o);
    }
};
struct JitEngine {
    static constexpr const char* name = "jit";
    static std::unique_ptr<ir::Evaluator> make(const ir::Tape& t, const ir::EvalOptions& o = {}) {
        return jit::make_jit(t, o);
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
