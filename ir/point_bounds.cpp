#include "ir/point_bounds.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <vector>

namespace frac::ir {

namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

class Bounds {
public:
    explicit Bounds(Graph& g) : g_(g) {}

    PointBounds run(NodeId root) {
        for (NodeId id : cone(root)) memo_[id] = compute(id);
        return memo_.at(root);
    }

private:
    // The nodes `root` reads, in topological (id) order. Series are values at a point: not entered.
    std::vector<NodeId> cone(NodeId root) const {
        std::vector<NodeId> out, todo{root};
        std::unordered_map<NodeId, bool> seen;
        while (!todo.empty()) {
            const NodeId id = todo.back();
            todo.pop_back();
            if (!seen.emplace(id, true).second) continue;
            out.push_back(id);
            const Node& n = g_[id];
            if (is_series(n.op) || op_class(n.op) == OpClass::leaf) continue;
            for (int k = 0; k < arity(n.op); ++k) todo.push_back(n.args[static_cast<std::size_t>(k)]);
        }
        std::sort(out.begin(), out.end());
        return out;
    }

    NodeId c(double v) {
        // The enclosure of an infinite bound is entire; only its point value is read.
        return std::isfinite(v) ? g_.constant(v) : g_.constant(Interval::entire(), v);
    }
    PointBounds range(double lo, double hi) { return {c(lo), c(hi)}; }
    static bool exact(const PointBounds& b, NodeId id) { return b.lo == id && b.hi == id; }

    NodeId op(Op o, NodeId a, NodeId b = no_node, NodeId x = no_node, std::int64_t imm = 0) {
        return g_.op(o, a, b, x, imm);
    }
    // Point min and max skip a NaN operand, which would drop a bound that is not known: a NaN lower
    // (upper) bound enters them as -inf (+inf). `Ge(v, -inf)` is false only for NaN.
    NodeId no_nan(NodeId v, double fill) {
        if (g_.is_const(v)) return std::isnan(g_[v].point) ? c(fill) : v;
        return select(op(fill < 0 ? Op::Ge : Op::Le, v, c(fill)), v, c(fill));
    }
    NodeId lo_min(NodeId a, NodeId b) { return op(Op::Min, no_nan(a, -inf), no_nan(b, -inf)); }
    NodeId lo_max(NodeId a, NodeId b) { return op(Op::Max, no_nan(a, -inf), no_nan(b, -inf)); }
    NodeId hi_min(NodeId a, NodeId b) { return op(Op::Min, no_nan(a, inf), no_nan(b, inf)); }
    NodeId hi_max(NodeId a, NodeId b) { return op(Op::Max, no_nan(a, inf), no_nan(b, inf)); }
    NodeId select(NodeId cond, NodeId a, NodeId b) { return op(Op::Select, cond, a, b); }
    NodeId positive(NodeId x) { return op(Op::Gt, x, c(0.0)); }
    NodeId negative(NodeId x) { return op(Op::Lt, x, c(0.0)); }
    PointBounds monotone(Op o, const PointBounds& x, std::int64_t imm = 0) {
        return {op(o, x.lo, no_node, no_node, imm), op(o, x.hi, no_node, no_node, imm)};
    }
    // Lowest and highest of the four corner values of a binary operation.
    PointBounds corners(Op o, const PointBounds& x, const PointBounds& y) {
        const NodeId p[4] = {op(o, x.lo, y.lo), op(o, x.lo, y.hi), op(o, x.hi, y.lo), op(o, x.hi, y.hi)};
        return {lo_min(lo_min(p[0], p[1]), lo_min(p[2], p[3])),
                hi_max(hi_max(p[0], p[1]), hi_max(p[2], p[3]))};
    }
    // x^2 (or an even power): the lowest value is 0 when x may change sign.
    PointBounds even(const PointBounds& x, NodeId lo_pow, NodeId hi_pow) {
        const NodeId lo = select(positive(x.lo), lo_pow, select(negative(x.hi), hi_pow, c(0.0)));
        return {lo, hi_max(lo_pow, hi_pow)};
    }

    // The operation and operands of a node, copied: the graph grows (and moves its nodes) as bounds are
    // built, so no reference to a node is held across the building.
    struct Head {
        Op op;
        std::array<NodeId, 3> args;
        std::int64_t imm;
    };

    PointBounds compute(NodeId id) {
        if (g_[id].op == Op::Const) {
            // A constant's point value is a representative of its enclosure (a fold of interval constants
            // may even give a thin enclosure another point value): its bounds are the enclosure's ends.
            const Interval value = g_[id].value;
            if (value.is_empty()) return range(std::nan(""), std::nan("")); // undefined
            return value.is_thin() && g_[id].point == value.lo ? PointBounds{id, id}
                                                               : range(value.lo, value.hi);
        }
        const Head n{g_[id].op, g_[id].args, g_[id].imm};
        if (is_series(n.op) || op_class(n.op) == OpClass::leaf) return {id, id};
        PointBounds a[3];
        bool all_exact = true;
        for (int k = 0; k < arity(n.op); ++k) {
            const NodeId arg = n.args[static_cast<std::size_t>(k)];
            a[k] = memo_.at(arg);
            all_exact = all_exact && exact(a[k], arg);
        }
        if (all_exact) return {id, id};
        // Undefined values (NaN) vanish in a point min or max, which then returns the other operand,
        // whatever the bounds of this one say: bounds are NaN (unknown) wherever an operand's are, or
        // the operation may be undefined on the operands' range.
        NodeId ok = domain(n.op, a[0]);
        for (int k = 0; k < arity(n.op); ++k) ok = op(Op::And, ok, known(a[k]));
        const PointBounds r = bounds(id, a);
        if (g_.is_const(ok) && g_[ok].point == 1.0) return r;
        return {select(ok, r.lo, c(std::nan(""))), select(ok, r.hi, c(std::nan("")))};
    }

    // True when both bounds are numbers.
    NodeId known(const PointBounds& x) {
        return op(Op::And, op(Op::Ge, x.lo, c(-inf)), op(Op::Le, x.hi, c(inf)));
    }
    // True when `o` is defined at every value of x's range.
    NodeId domain(Op o, const PointBounds& x) {
        switch (o) {
        case Op::Sqrt:
        case Op::Log: return op(Op::Ge, x.lo, c(0.0));
        case Op::Dz:
        case Op::Mod1:
        case Op::Sin:
        case Op::Cos: return op(Op::And, op(Op::Gt, x.lo, c(-inf)), op(Op::Lt, x.hi, c(inf)));
        default: return c(1.0);
        }
    }

    PointBounds bounds(NodeId id, const PointBounds* a) {
        const Head n{g_[id].op, g_[id].args, g_[id].imm};
        const PointBounds& x = a[0];
        const PointBounds& y = a[1];
        switch (n.op) {
        case Op::Add: return {op(Op::Add, x.lo, y.lo), op(Op::Add, x.hi, y.hi)};
        case Op::Sub: return {op(Op::Sub, x.lo, y.hi), op(Op::Sub, x.hi, y.lo)};
        case Op::Neg: return {op(Op::Neg, x.hi), op(Op::Neg, x.lo)};
        case Op::Mul: return corners(Op::Mul, x, y);
        case Op::Div: {
            // A divisor that may contain 0 bounds nothing.
            const NodeId safe = op(Op::Or, positive(y.lo), negative(y.hi));
            const PointBounds q = corners(Op::Div, x, y);
            return {select(safe, q.lo, c(-inf)), select(safe, q.hi, c(inf))};
        }
        case Op::Sqr: return even(x, op(Op::Sqr, x.lo), op(Op::Sqr, x.hi));
        case Op::PowI:
            if (n.imm > 0 && n.imm % 2 == 1) return monotone(Op::PowI, x, n.imm);
            if (n.imm > 0)
                return even(x, op(Op::PowI, x.lo, no_node, no_node, n.imm),
                            op(Op::PowI, x.hi, no_node, no_node, n.imm));
            return range(-inf, inf);
        case Op::Pow: {
            // c^y for a constant base c > 0 is monotone in y; anything else is left unbounded.
            if (!exact(x, n.args[0]) || !g_.is_const(n.args[0]) || !(g_[n.args[0]].value.lo > 0))
                return range(-inf, inf);
            const NodeId at_lo = op(Op::Pow, n.args[0], y.lo), at_hi = op(Op::Pow, n.args[0], y.hi);
            return g_[n.args[0]].value.lo >= 1 ? PointBounds{at_lo, at_hi} : PointBounds{at_hi, at_lo};
        }
        case Op::Sqrt: {
            const NodeId zero = c(0.0);
            return {op(Op::Sqrt, op(Op::Max, x.lo, zero)), op(Op::Sqrt, hi_max(x.hi, zero))};
        }
        case Op::Exp:
        case Op::Floor:
        case Op::Ceil: return monotone(n.op, x);
        case Op::Log: return {select(positive(x.lo), op(Op::Log, x.lo), c(-inf)), op(Op::Log, x.hi)};
        case Op::Abs: {
            const NodeId lo = select(positive(x.lo), x.lo, select(negative(x.hi), op(Op::Neg, x.hi), c(0.0)));
            return {lo, hi_max(op(Op::Neg, x.lo), x.hi)};
        }
        case Op::Min:
        case Op::Max:
            return n.op == Op::Min ? PointBounds{lo_min(x.lo, y.lo), hi_min(x.hi, y.hi)}
                                   : PointBounds{lo_max(x.lo, y.lo), hi_max(x.hi, y.hi)};
        case Op::Select: {
            const PointBounds& t = a[1];
            const PointBounds& f = a[2];
            if (exact(a[0], n.args[0])) return {select(n.args[0], t.lo, f.lo), select(n.args[0], t.hi, f.hi)};
            return {lo_min(t.lo, f.lo), hi_max(t.hi, f.hi)}; // either branch
        }
        case Op::Mod1: return range(0.0, 1.0);
        case Op::Dz: return range(0.0, 0.5);
        case Op::Sin:
        case Op::Cos: return range(-1.0, 1.0);
        case Op::Atan2: return range(-4.0, 4.0); // |atan2| <= pi
        default: break;
        }
        // A truth value, or an operation without rules here: nothing is assumed of it.
        return op_class(n.op) == OpClass::logic ? range(0.0, 1.0) : range(-inf, inf);
    }

    Graph& g_;
    std::unordered_map<NodeId, PointBounds> memo_;
};

} // namespace

PointBounds point_bounds(Graph& g, NodeId id) {
    return Bounds(g).run(id);
}

} // namespace frac::ir
