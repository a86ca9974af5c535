// MPFI soundness oracle: random expressions, high-precision point values and a containment check.
//
// An evaluator under test maps an expression and a box (one interval per variable) to an interval. It is
// sound when that interval contains the exact value of the expression at every point of the box where the
// expression is defined. check_soundness draws random (expression, box) pairs, asks the evaluator for its
// enclosure and compares it with an MPFI enclosure (>= 128 bits) of the exact value at several points of
// the box. Reused by the tests of the numeric core, the IR interpreter and the JIT.
#pragma once

#include "numeric/interval.hpp"

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <random>
#include <string>
#include <vector>

namespace frac::oracle {

namespace num = frac::num;

// The builtins. Arity: Const and Var 0; Add Sub Mul Div Min Max Pow Atan2 2; everything else 1.
enum class Op : std::uint8_t {
    Const, // value
    Var,   // coordinate `var` of the point
    Add,
    Sub,
    Mul,
    Div,
    Neg,
    Sqr,
    PowInt, // args[0]^n
    Pow,    // args[0]^args[1], real exponent (num::pow semantics)
    Sqrt,
    Abs,
    Min,
    Max,
    Floor,
    Ceil,
    Mod1,
    Dz,
    Sin,
    Cos,
    Tan,
    Exp,
    Log,
    Atan2, // atan2(args[0] = y, args[1] = x)
};
inline constexpr int kNumOps = static_cast<int>(Op::Atan2) + 1;

const char* op_name(Op op);
int arity(Op op);

struct Expr {
    Op op = Op::Const;
    int var = 0;        // Var: coordinate index
    double value = 0.0; // Const: the (exact) double value
    std::int64_t n = 0; // PowInt: the exponent
    std::vector<Expr> args;
};

// Readable, re-parseable-by-eye form, e.g. "sin(add(x0, 0x1.8p+0))"; constants print in hex.
std::string to_string(const Expr& e);
// Number of nodes.
std::size_t size(const Expr& e);

// A random expression of depth <= max_depth over variables x0 .. x{num_vars-1} (num_vars >= 1).
// Draws every op with equal probability at inner nodes; arguments of sqrt/log/pow/div are often shaped
// (abs, positive offsets) so that the expression is defined on much of the box.
Expr random_expr(std::mt19937_64& rng, int max_depth, int num_vars);

// A random box of num_vars intervals: varied widths (thin, tiny, unit, wide, huge), positions (near 0,
// near integers and half-integers, near multiples of pi/2, negative, large) and rarely unbounded.
std::vector<num::Interval> random_box(std::mt19937_64& rng, int num_vars);

// An MPFI enclosure [left, right] of an exact value v, rounded to doubles both ways.
struct PointValue {
    num::Interval outer;     // [RD(left), RU(right)]: contains v
    double left_up = 0.0;    // RU(left) <= RU(v): every correct double upper bound is >= this
    double right_down = 0.0; // RD(right) >= RD(v): every correct double lower bound is <= this

    // Whether an enclosure can be correct. When MPFI is tight (left and right between the same two
    // doubles, or thin) this is exactly "contains outer"; when MPFI is loose it is weaker but still a
    // necessary condition, so a loose oracle value never produces a false alarm.
    bool admits(num::Interval enclosure) const {
        return enclosure.lo <= right_down && left_up <= enclosure.hi;
    }
    // outer spans at most one gap between doubles: admits() is then as strict as containment.
    bool precise() const;
};

// MPFI enclosure (at `bits` >= 53 bits) of the exact value of e at the point; nullopt when the point is
// outside the domain of some subexpression or the oracle cannot decide the value (an argument enclosure
// straddles a discontinuity of floor/ceil/mod1, a branch cut, a pole or a domain boundary).
std::optional<PointValue> eval_mpfi(const Expr& e, const double* point, int bits = 128);

// The reference enclosure: a direct recursion over frac::num. The caller must hold UpwardRounding.
// Semantics every evaluator must match (up to soundness): Const is thin, Pow follows num::pow.
num::Interval eval_reference(const Expr& e, const num::Interval* box);

using Enclosure = std::function<num::Interval(const Expr&, const num::Interval* box)>;

struct Options {
    int max_depth = 4;
    int points_per_pair = 4; // point 0: lower corner, 1: upper corner, 2: centre, then random points
    int bits = 128;
    // Engines that compile (the JIT) check many boxes per expression and compile many expressions at
    // once: expressions are drawn `exprs_per_block` at a time and handed to `prepare` before any of their
    // pairs is evaluated; each expression is then paired with `boxes_per_expr` boxes. The Expr that the
    // enclosure receives is an element of the vector `prepare` saw. With 1 and 1 the drawing is the same
    // as one expression and one box per pair.
    int boxes_per_expr = 1;
    int exprs_per_block = 1;
    std::function<void(const std::vector<Expr>&)> prepare;
};

struct Report {
    std::uint64_t pairs = 0;
    std::uint64_t points_checked = 0;
    std::uint64_t violations = 0;        // points whose value the evaluator's enclosure cannot contain
    std::uint64_t undefined_skipped = 0; // points where eval_mpfi gave nullopt
    std::uint64_t imprecise = 0;         // checked points where MPFI was not precise() (weaker check)
    std::uint64_t bad_enclosures = 0;    // NaN bounds or rounding mode not restored (also violations)
    std::array<std::uint64_t, kNumOps> op_nodes{};   // nodes of each op in the drawn expressions
    std::array<std::uint64_t, kNumOps> op_checked{}; // ... in expressions with >= 1 checked point
    std::string first_violation;                     // expression, box, point and both enclosures

    // Multi-line human-readable summary: totals and per-op counts.
    std::string summary() const;
    // Whether the check did not shrink: more points checked than pairs drawn (4 points a pair, a few
    // undefined), and every operator of the table in some checked expression.
    bool covered() const;
};

// For n_pairs random (expression, box) pairs from `seed`: evaluate `enclosure` on the box (it is called
// in round-to-nearest and must leave the rounding mode as it found it) and check with PointValue::admits
// that it can contain the exact value at each of the box's sample points. Deterministic for a given seed
// and options.
Report check_soundness(std::uint64_t n_pairs, std::uint64_t seed, int num_vars, const Enclosure& enclosure,
                       const Options& options = {});

} // namespace frac::oracle
