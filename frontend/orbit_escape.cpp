// Escape certificates of orbit series: affine-in-|q| bounds of the term and of the map's norm.
#include "frontend/orbit_escape.hpp"

#include "ir/semantics.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <map>
#include <unordered_map>

namespace frac::front {

using ir::Graph;
using ir::Interval;
using ir::no_node;
using ir::NodeId;
using ir::Op;

namespace {

constexpr double inf = num::inf;

// A step of the proof that does not go through, and why.
struct Unproven {
    std::string why;
};

// lower.a |q| + lower.b <= value <= upper.a |q| + upper.b for every orbit point q (|q| >= 0).
// Coefficients are doubles rounded so that the bounds stay valid; infinite when unknown.
struct Affine {
    double a = 0.0, b = 0.0;
};
struct Radial {
    Affine lower{0.0, -inf}, upper{0.0, inf};
};

// Sum of two affine bounds, rounded down (lower) or up (upper).
Affine sum(Affine x, Affine y, bool lower) {
    const Interval a = num::add(Interval(x.a), Interval(y.a)), b = num::add(Interval(x.b), Interval(y.b));
    return lower ? Affine{a.lo, b.lo} : Affine{a.hi, b.hi};
}
// c * x for every c in `c`: with |q| >= 0, min over c of c (a r + b) >= min(c a) r + min(c b).
Affine scale(Interval c, Affine x, bool lower) {
    const Interval a = num::mul(c, Interval(x.a)), b = num::mul(c, Interval(x.b));
    return lower ? Affine{a.lo, b.lo} : Affine{a.hi, b.hi};
}
bool bounded(const Affine& x) {
    return std::isfinite(x.a) && std::isfinite(x.b);
}

class Prover {
public:
    Prover(Graph& g, int level, int dims) : g_(g), level_(level), dims_(dims) {}

    bool reads_state(NodeId id) {
        if (auto it = state_memo_.find(id); it != state_memo_.end()) return it->second;
        const ir::Node& n = g_[id];
        bool r = n.op == Op::State && ir::state_level(n.imm) == level_;
        if (ir::is_series(n.op)) r = true; // an inner series may read the point; never linear here
        for (NodeId a : n.args)
            if (a != no_node && reads_state(a)) r = true;
        state_memo_.emplace(id, r);
        return r;
    }
    // Reads the index itself (the orbit point also changes with the index, but is not counted).
    bool reads_index(NodeId id) {
        if (!((g_[id].index_mask >> level_) & 1)) return false;
        if (auto it = index_memo_.find(id); it != index_memo_.end()) return it->second;
        const ir::Node& n = g_[id];
        bool r = (n.op == Op::Index && n.imm == level_) || ir::is_series(n.op);
        for (NodeId a : n.args)
            if (a != no_node && reads_index(a)) r = true;
        index_memo_.emplace(id, r);
        return r;
    }
    int state_component(NodeId id) const {
        const ir::Node& n = g_[id];
        return n.op == Op::State && ir::state_level(n.imm) == level_ ? ir::state_component(n.imm) : -1;
    }

    // An enclosure of a node over all orbit points, indices and coordinates.
    Interval enclose(NodeId id) {
        if (auto it = enclose_memo_.find(id); it != enclose_memo_.end()) return it->second;
        const ir::Node& n = g_[id];
        Interval r = Interval::entire();
        if (n.op == Op::Const) {
            r = n.value;
        } else if (n.op != Op::External &&
                   (ir::op_class(n.op) == ir::OpClass::arith || ir::op_class(n.op) == ir::OpClass::logic)) {
            Interval args[3];
            for (int k = 0; k < ir::arity(n.op); ++k) args[k] = enclose(n.args[static_cast<std::size_t>(k)]);
            r = ir::apply_interval(n.op, args, n.imm);
        }
        enclose_memo_.emplace(id, r);
        return r;
    }

    // |q| itself: sqrt of the sum of the squares of every component, each once.
    bool is_norm(NodeId id) {
        const ir::Node& n = g_[id];
        if (n.op != Op::Sqrt) return false;
        std::vector<int> seen(static_cast<std::size_t>(dims_), 0);
        std::vector<NodeId> stack{n.args[0]};
        while (!stack.empty()) {
            const ir::Node& m = g_[stack.back()];
            stack.pop_back();
            if (m.op == Op::Add) {
                stack.push_back(m.args[0]);
                stack.push_back(m.args[1]);
                continue;
            }
            int c = -1;
            if (m.op == Op::Sqr || (m.op == Op::PowI && m.imm == 2)) c = state_component(m.args[0]);
            if (m.op == Op::Mul && m.args[0] == m.args[1]) c = state_component(m.args[0]);
            if (c < 0 || c >= dims_) return false;
            ++seen[static_cast<std::size_t>(c)];
        }
        return std::all_of(seen.begin(), seen.end(), [](int k) { return k == 1; });
    }

    Radial radial(NodeId id) {
        if (auto it = radial_memo_.find(id); it != radial_memo_.end()) return it->second;
        const Radial r = compute_radial(id);
        radial_memo_.emplace(id, r);
        return r;
    }

    // The map's components as diag(l) u(q) + c; returns a, b with |M(q)| >= a |q| - b.
    std::pair<double, double> map_growth(const std::vector<NodeId>& map) {
        std::vector<Monomial> parts;
        Interval c_norm2(0.0);
        double l_min = inf;
        for (std::size_t k = 0; k < map.size(); ++k) {
            const Linear lin = linear(map[k]);
            if (lin.terms.size() != 1)
                throw Unproven{fmt::format(
                    "component {} of the map is not of the form l * u(q) + c with one non-constant part",
                    k + 1)};
            const auto& [factors, coeff] = *lin.terms.begin();
            for (NodeId f : factors)
                if (!reads_state(f))
                    throw Unproven{fmt::format(
                        "component {} of the map depends on something other than the orbit point", k + 1)};
            parts.push_back({factors, coeff});
            c_norm2 = num::add(c_norm2, num::sqr(lin.constant));
            const Interval mag = num::abs(coeff);
            l_min = std::min(l_min, mag.lo);
            l_max_ = std::max(l_max_, mag.hi);
        }
        const Affine u = norm_of_parts(parts);
        // |M(q)| >= l_min |u(q)| - |c| >= l_min (u.a |q| + u.b) - |c|
        const double a = num::mul(Interval(l_min), Interval(u.a)).lo;
        const double b = num::sub(num::sqrt(c_norm2), num::mul(Interval(l_min), Interval(u.b))).hi;
        return {a, b};
    }

    // A Lipschitz constant of the map (Euclidean), or inf. Valid after map_growth.
    double map_lipschitz() const { return num::mul(Interval(l_max_), Interval(u_lipschitz_)).hi; }

    // A Lipschitz constant of a function of the orbit point, or inf.
    double lipschitz(NodeId id) {
        const ir::Node& n = g_[id];
        if (!reads_state(id)) return n.op == Op::Const ? 0.0 : inf;
        if (is_norm(id) || state_component(id) >= 0) return 1.0;
        switch (n.op) {
        case Op::Add:
        case Op::Sub: return num::add(Interval(lipschitz(n.args[0])), Interval(lipschitz(n.args[1]))).hi;
        case Op::Neg:
        case Op::Abs:
        case Op::Dz:
        case Op::Sin:
        case Op::Cos: return lipschitz(n.args[0]); // 1-Lipschitz functions
        case Op::Min:
        case Op::Max: return std::max(lipschitz(n.args[0]), lipschitz(n.args[1]));
        case Op::Mul:
        case Op::Div: return scaled_lipschitz(n, [&](NodeId x) { return lipschitz(x); });
        default: return inf;
        }
    }

    // The term as D(q) * scale0 / growth^k.
    struct Split {
        NodeId d = no_node;
        Interval scale0{1.0}, growth{1.0};
    };
    Split split_term(NodeId term) {
        Split s;
        collect_factors(term, true, s);
        if (s.d == no_node) throw Unproven{"the term does not depend on the orbit point"};
        return s;
    }

private:
    struct Monomial {
        std::vector<NodeId> factors; // sorted
        Interval coeff;
    };
    struct Linear {
        std::map<std::vector<NodeId>, Interval> terms; // product of factors -> coefficient
        Interval constant{0.0};
    };

    static Linear atom(NodeId id) {
        Linear l;
        l.terms[{id}] = Interval(1.0);
        return l;
    }
    static Linear scaled(Linear l, Interval c) {
        for (auto& [f, k] : l.terms) k = num::mul(k, c);
        l.constant = num::mul(l.constant, c);
        return l;
    }
    // Linear combination of products of non-constant factors, through + - and constant factors.
    Linear linear(NodeId id) {
        const ir::Node& n = g_[id];
        switch (n.op) {
        case Op::Const: {
            Linear l;
            l.constant = n.value;
            return l;
        }
        case Op::Add:
        case Op::Sub: {
            Linear x = linear(n.args[0]);
            const Linear y = scaled(linear(n.args[1]), Interval(n.op == Op::Add ? 1.0 : -1.0));
            for (const auto& [f, k] : y.terms) {
                auto [it, fresh] = x.terms.emplace(f, k);
                if (!fresh) it->second = num::add(it->second, k);
            }
            x.constant = num::add(x.constant, y.constant);
            return x;
        }
        case Op::Neg: return scaled(linear(n.args[0]), Interval(-1.0));
        case Op::Div:
            if (g_.is_const(n.args[1]))
                return scaled(linear(n.args[0]), num::div(Interval(1.0), g_[n.args[1]].value));
            return atom(id);
        case Op::Mul: {
            if (g_.is_const(n.args[0])) return scaled(linear(n.args[1]), g_[n.args[0]].value);
            if (g_.is_const(n.args[1])) return scaled(linear(n.args[0]), g_[n.args[1]].value);
            const Linear x = linear(n.args[0]), y = linear(n.args[1]);
            // A product of two monomials is a monomial: (k1 f) (k2 g) = k1 k2 (f g).
            if (x.terms.size() == 1 && y.terms.size() == 1 && x.constant == Interval(0.0) &&
                y.constant == Interval(0.0)) {
                std::vector<NodeId> f = x.terms.begin()->first;
                f.insert(f.end(), y.terms.begin()->first.begin(), y.terms.begin()->first.end());
                std::sort(f.begin(), f.end());
                Linear l;
                l.terms[f] = num::mul(x.terms.begin()->second, y.terms.begin()->second);
                return l;
            }
            return atom(id);
        }
        default: return atom(id);
        }
    }

    // A lower bound of |u| for u = (product of factors of each part).
    Affine norm_of_parts(const std::vector<Monomial>& parts) {
        // Polar coordinates put back together: (R cos f, R sin f) has norm |R| >= R.
        if (parts.size() == 2) {
            auto split_trig = [&](const std::vector<NodeId>& f, Op want, NodeId& angle,
                                  std::vector<NodeId>& rest) {
                for (std::size_t k = 0; k < f.size(); ++k)
                    if (g_[f[k]].op == want) {
                        angle = g_[f[k]].args[0];
                        rest = f;
                        rest.erase(rest.begin() + static_cast<std::ptrdiff_t>(k));
                        return true;
                    }
                return false;
            };
            NodeId f0 = no_node, f1 = no_node;
            std::vector<NodeId> r0, r1;
            if (split_trig(parts[0].factors, Op::Cos, f0, r0) &&
                split_trig(parts[1].factors, Op::Sin, f1, r1) && f0 == f1 && r0 == r1 && r0.size() <= 1) {
                if (r0.empty()) return {0.0, 1.0};
                // (|q| cos g(t), |q| sin g(t)), t the angle of a reflection of q: |du|^2 = d|q|^2 +
                // |q|^2 g'^2 dt^2 along any segment, so u is max(1, |g'|)-Lipschitz.
                const NodeId t = reflected_angle(f0);
                if (is_norm(r0[0]) && t != no_node) u_lipschitz_ = std::max(1.0, angle_lipschitz(f0, t));
                return radial(r0[0]).lower;
            }
        }
        // A signed permutation of the coordinates (abs included) keeps the norm.
        std::vector<int> seen(static_cast<std::size_t>(dims_), 0);
        bool permutation = parts.size() == static_cast<std::size_t>(dims_);
        for (const Monomial& p : parts) {
            if (p.factors.size() != 1) {
                permutation = false;
                break;
            }
            NodeId f = p.factors[0];
            if (g_[f].op == Op::Abs) f = g_[f].args[0];
            const int c = state_component(f);
            if (c < 0 || c >= dims_ || seen[static_cast<std::size_t>(c)]++) permutation = false;
        }
        if (permutation) {
            u_lipschitz_ = 1.0; // abs and signed permutations are 1-Lipschitz
            return {1.0, 0.0};
        }
        // Otherwise |u| >= |u_k| >= u_k for the component with the largest lower slope.
        Affine best{0.0, 0.0};
        for (const Monomial& p : parts) {
            if (p.factors.size() != 1) continue;
            const Affine lo = radial(p.factors[0]).lower;
            if (bounded(lo) && lo.a > best.a) best = lo;
        }
        if (!(best.a > 0))
            throw Unproven{"the map is not recognised as growing with |q| (expected l * u(q) + c with u a "
                           "rotation, reflection or polar re-assembly of q)"};
        return best;
    }

    Radial compute_radial(NodeId id) {
        const ir::Node& n = g_[id];
        if (!reads_state(id)) {
            const Interval v = enclose(id);
            return {{0.0, v.lo}, {0.0, v.hi}};
        }
        if (is_norm(id)) return {{1.0, 0.0}, {1.0, 0.0}};
        if (state_component(id) >= 0) return {{-1.0, 0.0}, {1.0, 0.0}};
        switch (n.op) {
        case Op::Add:
        case Op::Sub: {
            const Radial x = radial(n.args[0]);
            Radial y = radial(n.args[1]);
            if (n.op == Op::Sub) y = negate(y);
            return {sum(x.lower, y.lower, true), sum(x.upper, y.upper, false)};
        }
        case Op::Neg: return negate(radial(n.args[0]));
        case Op::Mul:
        case Op::Div: {
            const bool div = n.op == Op::Div;
            if (div && !g_.is_const(n.args[1])) break;
            // A constant factor, or a bounded factor times a nonnegative one.
            NodeId x = n.args[0], y = n.args[1];
            if (!div && g_.is_const(x)) std::swap(x, y);
            if (g_.is_const(y)) {
                const Interval c = div ? num::div(Interval(1.0), g_[y].value) : g_[y].value;
                return times(radial(x), c);
            }
            Radial rx = radial(x), ry = radial(y);
            if (!(ry.lower.a == 0 && ry.upper.a == 0)) std::swap(rx, ry);
            if (ry.lower.a == 0 && ry.upper.a == 0 && bounded(ry.lower) && bounded(ry.upper) &&
                rx.lower.a >= 0 && rx.lower.b >= 0) {
                const double c1 = ry.lower.b, c2 = ry.upper.b; // x >= 0, y in [c1, c2]
                Radial r;
                r.lower = scale(Interval(c1), c1 >= 0 ? rx.lower : rx.upper, true);
                r.upper = scale(Interval(c2), c2 >= 0 ? rx.upper : rx.lower, false);
                return r;
            }
            break;
        }
        case Op::Abs: {
            const Radial x = radial(n.args[0]);
            Radial r;
            r.lower = x.lower.a >= 0 && x.lower.b >= 0 ? x.lower : Affine{0.0, 0.0};
            r.upper = {std::max(x.upper.a, -x.lower.a), std::max(x.upper.b, -x.lower.b)};
            return r;
        }
        default: break;
        }
        const Interval v = enclose(id); // bounded whatever the point: sin, cos, dz, ...
        return {{0.0, v.lo}, {0.0, v.hi}};
    }
    static Radial negate(const Radial& x) { return {{-x.upper.a, -x.upper.b}, {-x.lower.a, -x.lower.b}}; }
    static Radial times(const Radial& x, Interval c) {
        if (c.lo >= 0) return {scale(c, x.lower, true), scale(c, x.upper, false)};
        if (c.hi <= 0) return {scale(c, x.upper, true), scale(c, x.lower, false)};
        return {}; // unknown sign: nothing is known
    }

    // index term: e0 + e1 k with constant e0, e1 (k the index of this series).
    std::pair<Interval, Interval> index_affine(NodeId id) {
        const ir::Node& n = g_[id];
        if (!reads_index(id)) {
            if (!g_.is_const(id))
                throw Unproven{
                    "an exponent of the term's scale is not a constant plus a multiple of the index"};
            return {n.value, Interval(0.0)};
        }
        switch (n.op) {
        case Op::Index: return {Interval(0.0), Interval(1.0)};
        case Op::Add:
        case Op::Sub: {
            const auto x = index_affine(n.args[0]), y = index_affine(n.args[1]);
            if (n.op == Op::Add) return {num::add(x.first, y.first), num::add(x.second, y.second)};
            return {num::sub(x.first, y.first), num::sub(x.second, y.second)};
        }
        case Op::Neg: {
            const auto x = index_affine(n.args[0]);
            return {num::neg(x.first), num::neg(x.second)};
        }
        case Op::Mul:
            if (g_.is_const(n.args[0]) || g_.is_const(n.args[1])) {
                const bool first = g_.is_const(n.args[0]);
                const Interval c = g_[n.args[first ? 0 : 1]].value;
                const auto x = index_affine(n.args[first ? 1 : 0]);
                return {num::mul(c, x.first), num::mul(c, x.second)};
            }
            break;
        default: break;
        }
        throw Unproven{"an exponent of the term's scale is not a constant plus a multiple of the index"};
    }

    // c^e with e a thin integer computed exactly where the double result is exact (3^1 = 3).
    static Interval power(Interval c, Interval e) {
        if (e.is_thin() && e.lo == std::nearbyint(e.lo) && std::fabs(e.lo) < 0x1p52)
            return num::powi(c, static_cast<std::int64_t>(e.lo));
        return num::pow(c, e);
    }

    // Splits the term's product into the part on the orbit point and the part on the index.
    void collect_factors(NodeId id, bool numerator, Split& s) {
        const ir::Node& n = g_[id];
        if (n.op == Op::Mul || n.op == Op::Div) {
            collect_factors(n.args[0], numerator, s);
            collect_factors(n.args[1], n.op == Op::Mul ? numerator : !numerator, s);
            return;
        }
        const bool on_state = reads_state(id), on_index = reads_index(id);
        if (on_state && on_index)
            throw Unproven{
                "the term is not a product of a function of the orbit point and a function of the index"};
        if (on_state) {
            if (!numerator || s.d != no_node)
                throw Unproven{"the orbit point must appear in one factor of the term's numerator"};
            s.d = id;
            return;
        }
        // The factor as f0 / g^k: S(k) = scale0 / growth^k multiplies by f0 and by g.
        Interval f0, g(1.0);
        if (on_index) {
            // c^(e0 + e1 k) with c > 0 is c^e0 / (c^-e1)^k; in the denominator c^-e0 / (c^e1)^k.
            if (n.op != Op::Pow || !g_.is_const(n.args[0]) || !(g_[n.args[0]].value.lo > 0))
                throw Unproven{
                    "the index may enter the term only as c^(e0 + e1 k) with a positive constant c"};
            const Interval c = g_[n.args[0]].value;
            const auto [e0, e1] = index_affine(n.args[1]);
            f0 = power(c, numerator ? e0 : num::neg(e0));
            g = power(c, numerator ? num::neg(e1) : e1); // exact for 3^k: growth 3, not 1 / (1/3)
        } else if (g_.is_const(id) && g_[id].value.lo > 0) {
            f0 = numerator ? g_[id].value : num::div(Interval(1.0), g_[id].value);
        } else {
            throw Unproven{
                "a factor of the term is neither a positive constant nor a function of the orbit point "
                "or of the index"};
        }
        s.scale0 = num::mul(s.scale0, f0);
        s.growth = num::mul(s.growth, g);
    }

    // c * x or x / c for a constant c: |c| Lip(x); inf otherwise.
    template <class Lip>
    double scaled_lipschitz(const ir::Node& n, Lip lip) {
        const bool div = n.op == Op::Div;
        const NodeId c = div ? n.args[1] : (g_.is_const(n.args[0]) ? n.args[0] : n.args[1]);
        if (!g_.is_const(c)) return inf;
        const NodeId x = c == n.args[0] ? n.args[1] : n.args[0];
        const Interval k = num::abs(div ? num::div(Interval(1.0), g_[c].value) : g_[c].value);
        return num::mul(k, Interval(lip(x))).hi;
    }
    // The atan2(|q_i|, +-q_j) (i != j, 2D) node that f depends on: the angle in [0, pi] of a reflection
    // of q, continuous away from the origin. no_node when f reads the point otherwise.
    NodeId reflected_angle(NodeId f) {
        const ir::Node& n = g_[f];
        if (n.op == Op::Atan2) {
            const ir::Node& y = g_[n.args[0]];
            NodeId x = n.args[1];
            if (g_[x].op == Op::Neg) x = g_[x].args[0];
            const int i = y.op == Op::Abs ? state_component(y.args[0]) : -1, j = state_component(x);
            return i >= 0 && j >= 0 && i != j && dims_ == 2 ? f : no_node;
        }
        NodeId found = no_node;
        for (NodeId a : n.args) {
            if (a == no_node || !reads_state(a)) continue;
            const NodeId t = reflected_angle(a);
            if (t == no_node || (found != no_node && found != t)) return no_node;
            found = t;
        }
        return found;
    }
    // A Lipschitz constant of f as a function of the node `angle`, through continuous operations; inf
    // otherwise.
    double angle_lipschitz(NodeId f, NodeId angle) {
        if (f == angle) return 1.0;
        const ir::Node& n = g_[f];
        if (!reads_state(f)) return n.op == Op::Const ? 0.0 : inf;
        switch (n.op) {
        case Op::Add:
        case Op::Sub:
            return num::add(Interval(angle_lipschitz(n.args[0], angle)),
                            Interval(angle_lipschitz(n.args[1], angle)))
                .hi;
        case Op::Neg:
        case Op::Abs:
        case Op::Dz: return angle_lipschitz(n.args[0], angle);
        case Op::Mul:
        case Op::Div: return scaled_lipschitz(n, [&](NodeId x) { return angle_lipschitz(x, angle); });
        default: return inf;
        }
    }

    double l_max_ = 0.0, u_lipschitz_ = inf;
    Graph& g_;
    int level_, dims_;
    std::unordered_map<NodeId, bool> state_memo_, index_memo_;
    std::unordered_map<NodeId, Interval> enclose_memo_;
    std::unordered_map<NodeId, Radial> radial_memo_;
};

std::string num_text(double v) {
    return fmt::format("{:.6g}", v);
}

// Two numbers with as many digits as it takes to tell them apart (a radius that fails by rounding).
std::pair<std::string, std::string> distinct_texts(double x, double y) {
    for (int digits = 6; digits < 17; ++digits) {
        std::string a = fmt::format("{:.{}g}", x, digits), b = fmt::format("{:.{}g}", y, digits);
        if (a != b) return {a, b};
    }
    return {fmt::format("{:.17g}", x), fmt::format("{:.17g}", y)};
}

} // namespace

std::optional<ir::OrbitEscape> prove_orbit_escape(Graph& g, NodeId term, const std::vector<NodeId>& map,
                                                  int level, Op kind, Interval radius, std::string& why) {
    try {
        if (kind == Op::SeriesSum)
            throw Unproven{"an escaping orbit makes a sum diverge; escape applies to min and max"};
        Prover p(g, level, static_cast<int>(map.size()));
        const auto split = p.split_term(term);
        // A max series: the certificate is for -t = (-D) S.
        const Radial d = p.radial(split.d);
        const Affine lower = kind == Op::SeriesMax ? Affine{-d.upper.a, -d.upper.b} : d.lower;
        if (!bounded(lower) || !(lower.a >= 0))
            throw Unproven{
                fmt::format("the term's factor on the orbit point is not bounded {} by s |q| + d with s >= 0",
                            kind == Op::SeriesMax ? "above (negated)" : "below")};
        if (!(split.growth.lo >= 1)) throw Unproven{"the term's scale does not decrease with the index"};
        const auto [a, b] = p.map_growth(map);
        const double r = radius.hi;
        if (!(a > 1))
            throw Unproven{fmt::format("the map only gives |M(q)| >= {} |q| - {}, which does not grow",
                                       num_text(a), num_text(b))};
        if (!(a >= split.growth.hi))
            throw Unproven{
                fmt::format("the map gives |M(q)| >= {} |q| - {}, slower than the term's scale shrinks "
                            "(by {} per step)",
                            num_text(a), num_text(b), num_text(split.growth.hi))};
        const double reach = num::mul(num::sub(Interval(a), Interval(1.0)), Interval(r)).lo;
        const double escape_radius = num::div(Interval(b), num::sub(Interval(a), Interval(1.0))).hi;
        if (!(reach >= b))
            throw Unproven{
                fmt::format("the map gives |M(q)| >= {} |q| - {}: orbits provably escape only outside "
                            "radius {} / ({} - 1) = {}, above the claimed {}",
                            num_text(a), num_text(b), num_text(b), num_text(a),
                            distinct_texts(escape_radius, r).first, distinct_texts(escape_radius, r).second)};
        ir::OrbitEscape e;
        e.present = true;
        e.radius = r;
        e.slope = lower.a;
        e.offset = std::min(0.0, num::add(num::mul(Interval(lower.a), Interval(r)), Interval(lower.b)).lo);
        e.scale0 = split.scale0;
        e.growth = split.growth;
        // Lipschitz bounds in the initial point: the term of index k is lipschitz * (map_lipschitz /
        // growth)^k - Lipschitz (Lip(D) S0 Lip(M)^k / g^k), and so is the bound above (slope <= Lip(D)).
        const double lip_map = p.map_lipschitz(), lip_d = p.lipschitz(split.d);
        if (std::isfinite(lip_map) && std::isfinite(lip_d)) {
            e.lipschitz = num::mul(Interval(std::max(lip_d, e.slope)), split.scale0).hi;
            e.map_lipschitz = lip_map;
        }
        return e;
    } catch (const Unproven& f) {
        why = f.why;
        return std::nullopt;
    }
}

} // namespace frac::front
