// Abstract interpretation of a series term over "(A + B i) gamma^i" forms.
#include "frontend/series_bounds.hpp"

#include <fmt/format.h>
#include <unordered_map>

namespace frac::front {

using ir::Graph;
using ir::Interval;
using ir::no_node;
using ir::NodeId;
using ir::Op;

namespace {

struct Failure {
    std::string why;
};

class Bounder {
public:
    Bounder(Graph& g, int level) : g_(g), level_(level) {}

    TermBound form(NodeId id) {
        if (auto it = memo_.find(id); it != memo_.end()) return it->second;
        TermBound f = compute(id);
        memo_.emplace(id, f);
        return f;
    }

private:
    bool depends(NodeId id) const { return (g_[id].index_mask >> level_) & 1; }
    NodeId konst(Interval v) { return g_.constant(v, num::midpoint(v)); }
    NodeId unit_interval() { return konst({0.0, 1.0}); }
    // The hull of two enclosures as a node: a select on an undecided condition.
    NodeId hull(NodeId a, NodeId b) { return g_.op(Op::Select, konst({0.0, 1.0}), a, b); }
    NodeId b_or_zero(NodeId b) { return b == no_node ? konst(Interval(0.0)) : b; }
    static bool same(Interval a, Interval b) { return a == b; }

    // Rewrites f with decay `gamma` >= f.gamma: (A + B i) f.gamma^i lies in ([0,1] A + [0,1] B i) gamma^i.
    TermBound slow_down(const TermBound& f, Interval gamma) {
        if (same(f.gamma, gamma)) return f;
        TermBound r;
        r.a = g_.op(Op::Mul, f.a, unit_interval());
        r.b = f.b == no_node ? no_node : g_.op(Op::Mul, f.b, unit_interval());
        r.gamma = gamma;
        return r;
    }

    // Brings two forms to a common decay, or fails.
    void align(TermBound& x, TermBound& y) {
        if (same(x.gamma, y.gamma)) return;
        if (x.gamma.hi <= y.gamma.lo) {
            x = slow_down(x, y.gamma);
        } else if (y.gamma.hi <= x.gamma.lo) {
            y = slow_down(y, x.gamma);
        } else {
            // Overlapping enclosures of (nearly) the same decay: each true decay lies in the hull.
            const Interval both = num::hull(x.gamma, y.gamma);
            x.gamma = y.gamma = both;
        }
    }

    TermBound index_free(NodeId a) { return {a, no_node, Interval(1.0), {}, {}}; }
    // A value about which nothing is known but that it is a number.
    TermBound unbounded(const std::string& why) {
        return {konst(Interval::entire()), no_node, Interval(1.0), why, why};
    }
    static std::string first(const std::string& a, const std::string& b) { return a.empty() ? b : a; }
    static std::string any(const TermBound& f) { return first(f.no_lower, f.no_upper); }

    // An enclosure, independent of i, of a value of form f; entire (with `why` set) when f grows with i.
    NodeId enclosure(const TermBound& f, const char* what, std::string& why) {
        if (!any(f).empty()) {
            why = any(f);
            return konst(Interval::entire());
        }
        if (f.b != no_node || f.gamma.hi > 1.0) {
            why = fmt::format("the argument of {} grows with the index", what);
            return konst(Interval::entire());
        }
        if (f.gamma == Interval(1.0)) return f.a;
        return g_.op(Op::Mul, f.a, unit_interval()); // gamma^i in (0, 1]
    }

    // op applied to an index-free enclosure of its argument; `nonnegative` ops keep a lower bound.
    TermBound apply_enclosed(Op op, const TermBound& x, bool nonnegative, std::int64_t imm = 0) {
        std::string why;
        TermBound r = index_free(g_.op(op, enclosure(x, ir::op_name(op), why), no_node, no_node, imm));
        if (!why.empty()) {
            r.no_upper = why;
            if (!nonnegative) r.no_lower = why;
        }
        return r;
    }

    TermBound compute(NodeId id) {
        // A copy: form() adds nodes to the graph, which may move its storage (a reference dangled).
        const ir::Node n = g_[id];
        if (!depends(id)) return index_free(id);
        auto arg = [&](int k) { return form(n.args[static_cast<std::size_t>(k)]); };
        switch (n.op) {
        case Op::Index: return {konst(Interval(0.0)), konst(Interval(1.0)), Interval(1.0), {}, {}};
        case Op::State: return unbounded("the orbit point grows without a proven bound");
        case Op::External:
            return unbounded("a distance to an attractor that depends on the index has no proven bound");
        case Op::Add:
        case Op::Sub: {
            TermBound x = arg(0), y = arg(1);
            align(x, y);
            TermBound r;
            r.gamma = x.gamma;
            r.a = g_.op(n.op, x.a, y.a);
            if (x.b != no_node || y.b != no_node) r.b = g_.op(n.op, b_or_zero(x.b), b_or_zero(y.b));
            const bool add = n.op == Op::Add;
            r.no_lower = first(x.no_lower, add ? y.no_lower : y.no_upper);
            r.no_upper = first(x.no_upper, add ? y.no_upper : y.no_lower);
            return r;
        }
        case Op::Neg: {
            TermBound x = arg(0);
            x.a = g_.op(Op::Neg, x.a);
            if (x.b != no_node) x.b = g_.op(Op::Neg, x.b);
            std::swap(x.no_lower, x.no_upper);
            return x;
        }
        case Op::Mul:
        case Op::Div: {
            const TermBound x = arg(0), y = arg(1);
            const bool mul = n.op == Op::Mul;
            if (!mul && (y.b != no_node || !any(y).empty()))
                throw Failure{"the divisor grows with the index"};
            if (x.b != no_node && y.b != no_node)
                throw Failure{"a product of two factors that grow with the index grows faster than linearly"};
            TermBound r;
            r.gamma = mul ? num::mul(x.gamma, y.gamma) : num::div(x.gamma, y.gamma);
            r.a = g_.op(n.op, x.a, y.a);
            if (x.b != no_node) r.b = g_.op(n.op, x.b, y.a);
            if (y.b != no_node) r.b = g_.op(Op::Mul, x.a, y.b);
            // A one-sided bound keeps its side only when the other factor is known positive (a
            // constant); otherwise both sides are lost.
            const TermBound& loose = any(x).empty() ? y : x;
            const TermBound& other = any(x).empty() ? x : y;
            if (!any(loose).empty()) {
                const bool positive_const = g_.is_const(other.a) && other.b == no_node &&
                                            g_[other.a].value.lo > 0 && any(other).empty();
                r.no_lower = positive_const ? loose.no_lower : any(loose);
                r.no_upper = positive_const ? loose.no_upper : any(loose);
            }
            return r;
        }
        case Op::Sqr:
        case Op::PowI: {
            const TermBound x = arg(0);
            const std::int64_t k = n.op == Op::Sqr ? 2 : n.imm;
            if (x.b != no_node || !any(x).empty()) return apply_enclosed(n.op, x, k % 2 == 0 && k > 0, n.imm);
            return {g_.op(n.op, x.a, no_node, no_node, n.imm), no_node, num::powi(x.gamma, k), {}, {}};
        }
        case Op::Pow: {
            // c^(p + q i) = c^p (c^q)^i for a constant base c > 0 and constant q.
            const NodeId base = n.args[0];
            const TermBound e = arg(1);
            if (depends(base) || !g_.is_const(base) || !(g_[base].value.lo > 0))
                throw Failure{"a power whose exponent depends on the index needs a positive constant base"};
            if (e.gamma != Interval(1.0) || e.b == no_node || !g_.is_const(e.b) || !any(e).empty())
                throw Failure{"the exponent of a power must be linear in the index"};
            const Interval gamma = num::pow(g_[base].value, g_[e.b].value);
            return {g_.op(Op::Pow, base, e.a), no_node, gamma, {}, {}};
        }
        // Bounded whatever their argument.
        case Op::Dz: return index_free(konst({0.0, 0.5}));
        case Op::Mod1: return index_free(konst({0.0, 1.0}));
        case Op::Sin:
        case Op::Cos: return index_free(konst({-1.0, 1.0}));
        case Op::Lt:
        case Op::Le:
        case Op::Gt:
        case Op::Ge:
        case Op::Eq:
        case Op::Ne:
        case Op::And:
        case Op::Or:
        case Op::Not: return index_free(konst({0.0, 1.0}));
        case Op::Atan2: return index_free(konst(num::hull(num::neg(num::pi()), num::pi())));
        case Op::Floor:
        case Op::Ceil: {
            const TermBound x = arg(0);
            if (x.gamma == Interval(1.0)) {
                // floor(v) in v + [-1, 0], ceil(v) in v + [0, 1]: linear forms stay linear.
                TermBound r = x;
                r.a =
                    g_.op(Op::Add, x.a, konst(n.op == Op::Floor ? Interval{-1.0, 0.0} : Interval{0.0, 1.0}));
                return r;
            }
            return apply_enclosed(n.op, x, false);
        }
        case Op::Abs: {
            const TermBound x = arg(0);
            // |A + B i| <= |A| + |B| i
            TermBound r = x;
            r.a = g_.op(Op::Mul, g_.op(Op::Abs, x.a), unit_interval());
            if (x.b != no_node) r.b = g_.op(Op::Mul, g_.op(Op::Abs, x.b), unit_interval());
            r.no_lower.clear();
            r.no_upper = any(x);
            return r;
        }
        case Op::Sqrt:
        case Op::Exp: return apply_enclosed(n.op, arg(0), true);
        case Op::Tan:
        case Op::Log: return apply_enclosed(n.op, arg(0), false);
        case Op::Min:
        case Op::Max:
        case Op::Select: {
            const bool select = n.op == Op::Select;
            TermBound x = arg(select ? 1 : 0), y = arg(select ? 2 : 1);
            align(x, y);
            TermBound r;
            r.gamma = x.gamma;
            if (!select && x.b == no_node && y.b == no_node) {
                // min/max of the enclosures; a min is bounded above when either operand is.
                r.a = g_.op(n.op, x.a, y.a);
                const bool is_min = n.op == Op::Min;
                r.no_lower = is_min ? first(x.no_lower, y.no_lower)
                                    : (x.no_lower.empty() || y.no_lower.empty() ? "" : x.no_lower);
                r.no_upper = is_min ? (x.no_upper.empty() || y.no_upper.empty() ? "" : x.no_upper)
                                    : first(x.no_upper, y.no_upper);
                return r;
            }
            // Each result is one of the operands: the hull of their forms bounds it.
            r.a = hull(x.a, y.a);
            if (x.b != no_node || y.b != no_node) r.b = hull(b_or_zero(x.b), b_or_zero(y.b));
            r.no_lower = first(x.no_lower, y.no_lower);
            r.no_upper = first(x.no_upper, y.no_upper);
            return r;
        }
        case Op::SeriesSum:
        case Op::SeriesMin:
        case Op::SeriesMax: throw Failure{"an inner series depends on the outer index"};
        case Op::Const:
        case Op::Var: break; // index-free, handled above
        }
        throw Failure{fmt::format("cannot bound '{}'", ir::op_name(n.op))};
    }

    Graph& g_;
    int level_;
    std::unordered_map<NodeId, TermBound> memo_;
};

} // namespace

std::optional<TermBound> bound_series_term(Graph& g, NodeId term, int level, Op kind, std::string& why) {
    try {
        Bounder b(g, level);
        TermBound f = b.form(term);
        if (!(f.gamma.hi < 1.0) || !(f.gamma.lo > 0.0)) {
            why = fmt::format(
                "its terms do not decay geometrically (they are bounded only by (A + B i) * {}^i); "
                "divide the term by c^i with c > 1",
                f.gamma.is_thin() ? fmt::format("{}", f.gamma.lo)
                                  : fmt::format("[{}, {}]", f.gamma.lo, f.gamma.hi));
            return std::nullopt;
        }
        // A min needs a lower bound of its terms, a max an upper bound, a sum both.
        if (kind != Op::SeriesMax && !f.no_lower.empty()) {
            why = "its terms are not bounded below: " + f.no_lower;
            return std::nullopt;
        }
        if (kind != Op::SeriesMin && !f.no_upper.empty()) {
            why = "its terms are not bounded above: " + f.no_upper;
            return std::nullopt;
        }
        return f;
    } catch (const Failure& f) {
        why = f.why;
        return std::nullopt;
    }
}

} // namespace frac::front
