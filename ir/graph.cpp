#include "ir/graph.hpp"

#include "ir/point_bounds.hpp"
#include "ir/semantics.hpp"
#include "numeric/rational.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <optional>
#include <stdexcept>

namespace frac::ir {

namespace {

std::uint64_t bits(double v) {
    return std::bit_cast<std::uint64_t>(v);
}

bool same_escape(const OrbitEscape& a, const OrbitEscape& b) {
    return a.present == b.present && bits(a.radius) == bits(b.radius) && bits(a.slope) == bits(b.slope) &&
           bits(a.offset) == bits(b.offset) && bits(a.scale0.lo) == bits(b.scale0.lo) &&
           bits(a.scale0.hi) == bits(b.scale0.hi) && bits(a.growth.lo) == bits(b.growth.lo) &&
           bits(a.growth.hi) == bits(b.growth.hi) && bits(a.lipschitz) == bits(b.lipschitz) &&
           bits(a.map_lipschitz) == bits(b.map_lipschitz);
}

void mix(std::size_t& h, std::uint64_t v) {
    h ^= std::hash<std::uint64_t>{}(v) + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
}

// Equal rationals are equal in lowest terms: their limbs hash alike.
void mix_integer(std::size_t& h, mpz_srcptr z) {
    mix(h, static_cast<std::uint64_t>(mpz_sgn(z) + 1));
    for (std::size_t k = 0; k < mpz_size(z); ++k) mix(h, static_cast<std::uint64_t>(mpz_getlimbn(z, k)));
}

} // namespace

std::uint32_t Graph::key_hash(const Node& n) {
    std::size_t h = static_cast<std::size_t>(n.op);
    for (NodeId a : n.args) mix(h, a);
    mix(h, bits(n.value.lo));
    mix(h, bits(n.value.hi));
    mix(h, bits(n.point));
    mix(h, static_cast<std::uint64_t>(n.imm));
    mix(h, static_cast<std::uint64_t>(n.series.level));
    mix(h, static_cast<std::uint64_t>(n.series.start));
    mix(h, static_cast<std::uint64_t>(n.series.end));
    for (NodeId o : n.orbit) mix(h, o);
    mix(h, bits(n.series.escape.radius));
    if (n.exact) {
        mix_integer(h, n.exact->value().get_num_mpz_t());
        mix_integer(h, n.exact->value().get_den_mpz_t());
    }
    // The table takes the low bits: spread the high ones into them.
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdULL;
    h ^= h >> 33;
    return static_cast<std::uint32_t>(h);
}

bool Graph::same_key(const Node& a, const Node& b) {
    // Bitwise comparison of doubles, so that -0 and 0 (and NaN payloads) stay distinct constants.
    return a.op == b.op && a.args == b.args && bits(a.value.lo) == bits(b.value.lo) &&
           bits(a.value.hi) == bits(b.value.hi) && bits(a.point) == bits(b.point) && a.imm == b.imm &&
           a.series.level == b.series.level && a.series.start == b.series.start &&
           a.series.end == b.series.end && bits(a.series.gamma.lo) == bits(b.series.gamma.lo) &&
           bits(a.series.gamma.hi) == bits(b.series.gamma.hi) &&
           a.series.state_count == b.series.state_count && a.orbit == b.orbit &&
           a.series.one_sided == b.series.one_sided && same_escape(a.series.escape, b.series.escape) &&
           (a.exact == b.exact || (a.exact && b.exact && *a.exact == *b.exact));
}

void Graph::grow_index() {
    std::vector<Slot> larger(std::max<std::size_t>(64, 2 * index_.size()));
    const std::size_t mask = larger.size() - 1;
    for (const Slot& s : index_) {
        if (s.id == no_node) continue;
        std::size_t at = s.hash & mask;
        while (larger[at].id != no_node) at = (at + 1) & mask;
        larger[at] = s;
    }
    index_ = std::move(larger);
}

NodeId Graph::intern(const Node& n) {
    if (2 * (size_ + 1) > index_.size()) grow_index();
    const std::uint32_t hash = key_hash(n);
    const std::size_t mask = index_.size() - 1;
    std::size_t at = hash & mask;
    for (; index_[at].id != no_node; at = (at + 1) & mask)
        if (index_[at].hash == hash && same_key((*this)[index_[at].id], n)) return index_[at].id;
    Node stored = n;
    stored.index_mask = 0;
    for (NodeId a : n.args)
        if (a != no_node) stored.index_mask |= (*this)[a].index_mask;
    for (NodeId a : n.orbit) stored.index_mask |= (*this)[a].index_mask;
    for (NodeId a : n.point_tail)
        if (a != no_node) stored.index_mask |= (*this)[a].index_mask;
    if (n.op == Op::Index) stored.index_mask = std::uint64_t{1} << n.imm;
    if (n.op == Op::State) stored.index_mask = std::uint64_t{1} << state_level(n.imm);
    if (is_series(n.op)) stored.index_mask &= ~(std::uint64_t{1} << n.series.level);
    if (chunks_.empty() || chunks_.back().size() == chunk_size) {
        chunks_.emplace_back();
        if (chunks_.size() > 1) chunks_.back().reserve(chunk_size);
    }
    chunks_.back().push_back(std::move(stored));
    const auto id = static_cast<NodeId>(size_++);
    index_[at] = {id, hash};
    return id;
}

NodeId Graph::constant(Interval value, double point) {
    // A thin enclosure [v, v] is the exact value v: one node, whichever way it was computed (an
    // enclosure [-0, 0] is the value 0 too; a point value -0 keeps its sign, for 1 / x).
    if (value.is_thin() && point == value.lo && std::isfinite(point) && !(point == 0 && std::signbit(point)))
        return constant(num::Rational::from_double(point));
    Node n;
    n.op = Op::Const;
    n.value = value;
    n.point = point;
    return intern(n);
}

NodeId Graph::constant(double exact) {
    return constant(Interval{exact, exact}, exact); // exact unless -0, inf or NaN (see above)
}

NodeId Graph::constant(const num::Rational& exact) {
    Node n;
    n.op = Op::Const;
    n.value = num::enclose(exact);
    n.point = exact.to_double();
    n.exact = std::make_shared<const num::Rational>(exact);
    return intern(n);
}

namespace {

// Rationals kept exact up to this size (bits of numerator and denominator): 3^20 and the like, not
// the 2^100000 a careless power could make.
constexpr std::size_t max_exact_bits = 4096;

bool small(const num::Rational& r) {
    return mpz_sizeinbase(r.value().get_num_mpz_t(), 2) <= max_exact_bits &&
           mpz_sizeinbase(r.value().get_den_mpz_t(), 2) <= max_exact_bits;
}

num::Rational floor_of(const num::Rational& r) {
    mpz_class q;
    mpz_fdiv_q(q.get_mpz_t(), r.numerator().get_mpz_t(), r.denominator().get_mpz_t());
    return num::Rational(mpq_class(q));
}

// The exact result of op on exact arguments, when it is rational and small; nullopt otherwise.
std::optional<num::Rational> fold_exact(Op op, const num::Rational* const* a, std::int64_t imm) {
    using num::Rational;
    auto truth = [](bool t) { return Rational(t ? 1 : 0); };
    auto integer_power = [&](const Rational& base, const Rational& e) -> std::optional<Rational> {
        if (!e.is_integer() || abs(e) > Rational(64) || (base.is_zero() && e.sign() < 0)) return std::nullopt;
        return pow(base, e.numerator().get_si());
    };
    std::optional<Rational> r;
    switch (op) {
    case Op::Add: r = *a[0] + *a[1]; break;
    case Op::Sub: r = *a[0] - *a[1]; break;
    case Op::Mul: r = *a[0] * *a[1]; break;
    case Op::Div:
        if (a[1]->is_zero()) return std::nullopt;
        r = *a[0] / *a[1];
        break;
    case Op::Neg: r = -*a[0]; break;
    case Op::Sqr: r = *a[0] * *a[0]; break;
    case Op::PowI: r = integer_power(*a[0], Rational(static_cast<long>(imm))); break;
    case Op::Pow: r = integer_power(*a[0], *a[1]); break;
    case Op::Abs: r = abs(*a[0]); break;
    case Op::Min: r = std::min(*a[0], *a[1]); break;
    case Op::Max: r = std::max(*a[0], *a[1]); break;
    case Op::Floor: r = floor_of(*a[0]); break;
    case Op::Ceil: r = -floor_of(-*a[0]); break;
    case Op::Mod1: r = *a[0] - floor_of(*a[0]); break;
    case Op::Dz: r = std::min(*a[0] - floor_of(*a[0]), -floor_of(-*a[0]) - *a[0]); break;
    case Op::Lt: r = truth(*a[0] < *a[1]); break;
    case Op::Le: r = truth(*a[0] <= *a[1]); break;
    case Op::Gt: r = truth(*a[0] > *a[1]); break;
    case Op::Ge: r = truth(*a[0] >= *a[1]); break;
    case Op::Eq: r = truth(*a[0] == *a[1]); break;
    case Op::Ne: r = truth(*a[0] != *a[1]); break;
    default: return std::nullopt; // transcendental, or logic on truth values (folded by intervals)
    }
    if (r && !small(*r)) return std::nullopt;
    return r;
}

} // namespace

NodeId Graph::var(int index) {
    Node n;
    n.op = Op::Var;
    n.imm = index;
    return intern(n);
}

NodeId Graph::index(int level) {
    if (level < 1 || level > max_series_level)
        throw std::invalid_argument("series nesting level out of range");
    Node n;
    n.op = Op::Index;
    n.imm = level;
    return intern(n);
}

NodeId Graph::state(int level, int component) {
    if (level < 1 || level > max_series_level || component < 0 || component >= max_state_components)
        throw std::invalid_argument("orbit state out of range");
    Node n;
    n.op = Op::State;
    n.imm = state_imm(level, component);
    return intern(n);
}

NodeId Graph::fold(const Node& n) {
    const int k = arity(n.op);
    // Exact arguments fold exactly where the result is rational; the enclosure is then the tightest.
    const num::Rational* exact[3] = {nullptr, nullptr, nullptr};
    bool all_exact = true;
    for (int i = 0; i < k; ++i)
        all_exact = all_exact && (exact[i] = (*this)[n.args[i]].exact.get()) != nullptr;
    if (all_exact)
        if (std::optional<num::Rational> r = fold_exact(n.op, exact, n.imm)) return constant(*r);
    Interval iv[3];
    double pt[3];
    for (int i = 0; i < k; ++i) {
        iv[i] = (*this)[n.args[i]].value;
        pt[i] = (*this)[n.args[i]].point;
    }
    Interval value;
    {
        num::UpwardRounding up;
        value = apply_interval(n.op, iv, n.imm);
    }
    return constant(value, apply_point(n.op, pt, n.imm));
}

NodeId Graph::op(Op op, NodeId a, NodeId b, NodeId c, std::int64_t imm) {
    if (op_class(op) == OpClass::leaf || is_series(op))
        throw std::logic_error(std::string("Graph::op: use the dedicated constructor for ") + op_name(op));
    const NodeId args[3] = {a, b, c};
    Node n;
    n.op = op;
    n.imm = imm;
    bool all_const = true;
    for (int i = 0; i < 3; ++i) {
        const bool wanted = i < arity(op);
        if (wanted != (args[i] != no_node) || (wanted && args[i] >= size_))
            throw std::logic_error(std::string("Graph::op: bad arguments for ") + op_name(op));
        n.args[static_cast<std::size_t>(i)] = args[i];
        if (wanted) all_const = all_const && is_const(args[i]);
    }
    if (all_const && op != Op::External) return fold(n);
    // A value compared with itself (the same node: the same real number) needs no interval.
    if (a == b && op_class(op) == OpClass::logic && arity(op) == 2 && op != Op::And && op != Op::Or) {
        const bool holds = op == Op::Le || op == Op::Ge || op == Op::Eq;
        return constant(holds ? tv_true : tv_false, holds ? 1.0 : 0.0);
    }
    // A product of a value with itself is its square: [0, ...] where the factor straddles 0, where a
    // product of independent factors would be [-a*b, ...]. Exported models write squares this way.
    if (op == Op::Mul && a == b) return this->op(Op::Sqr, a);
    // A select on a decided condition is its branch.
    if (op == Op::Select && is_const(a)) {
        const Interval cond = (*this)[a].value;
        if (cond == tv_true) return b;
        if (cond == tv_false) return c;
    }
    return intern(n);
}

NodeId Graph::series(Op kind, const SeriesData& data, NodeId body, NodeId tail_a, NodeId tail_b,
                     std::vector<NodeId> orbit) {
    if (!is_series(kind)) throw std::logic_error("Graph::series: not a series op");
    if (orbit.size() != 2 * static_cast<std::size_t>(data.state_count))
        throw std::logic_error("Graph::series: an orbit needs an initial point and a map");
    Node n;
    n.op = kind;
    n.series = data;
    n.orbit = std::move(orbit);
    n.args = {body, tail_a, tail_b};
    // Bounds for point evaluation; a function of tail_a and tail_b, so not part of the node's key.
    if (tail_a != no_node) {
        const PointBounds a = point_bounds(*this, tail_a);
        n.point_tail[0] = a.lo;
        n.point_tail[1] = a.hi;
    }
    if (tail_b != no_node) {
        const PointBounds b = point_bounds(*this, tail_b);
        n.point_tail[2] = b.lo;
        n.point_tail[3] = b.hi;
    }
    return intern(n);
}

NodeId Graph::external(std::int64_t index, NodeId a, NodeId b, NodeId c) {
    if (index < 0) throw std::logic_error("Graph::external: negative index");
    return op(Op::External, a, b, c, index);
}

bool Graph::const_integer(NodeId id, std::int64_t& value) const {
    const Node& n = (*this)[id];
    if (n.op != Op::Const || !n.value.is_thin() || std::floor(n.value.lo) != n.value.lo ||
        std::fabs(n.value.lo) > 9.0e15)
        return false;
    value = static_cast<std::int64_t>(n.value.lo);
    return true;
}

} // namespace frac::ir
