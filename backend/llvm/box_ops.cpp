// The interval operations of box code: numeric/interval.cpp step by step (see box_gen.hpp).
#include "backend/llvm/box_gen.hpp"

#include <map>
#include <stdexcept>

namespace frac::jit::box {

// ---- interval operations: numeric/interval.cpp, step by step ----
// A finite operand rules out inf - inf, the only NaN of a sum of non-empty intervals.
IV BoxGen::widen_nan_unless(bool cannot_be_nan, Value* lo, Value* hi) {
    return cannot_be_nan ? IV{lo, hi} : widen_nan(lo, hi);
}

SlotState BoxGen::op_add(const SlotState& a, const SlotState& b) {
    Value* e = lor(empty_of(a), empty_of(b));
    return result(
        guard(e, widen_nan_unless(a.f.finite || b.f.finite, add_down(a.v.lo, b.v.lo), add(a.v.hi, b.v.hi)),
              empty()),
        a.f.maybe_empty || b.f.maybe_empty);
}

SlotState BoxGen::op_sub(const SlotState& a, const SlotState& b) {
    Value* e = lor(empty_of(a), empty_of(b));
    return result(
        guard(e, widen_nan_unless(a.f.finite || b.f.finite, sub_down(a.v.lo, b.v.hi), sub(a.v.hi, b.v.lo)),
              empty()),
        a.f.maybe_empty || b.f.maybe_empty);
}

SlotState BoxGen::op_mul(const SlotState& a, const SlotState& b) {
    Value* e = lor(empty_of(a), empty_of(b));
    // A factor positive in every lane (a constant, a table of 3^i, thin or not): each bound of the
    // product is one corner, the lower one at y.lo and the upper one at y.hi, with the factor's end
    // chosen by that bound's sign. The corners' minimum never ties at a signed zero; their maximum is
    // 0 only when y.hi <= 0, and then interval.cpp keeps the first zero corner, the one at (y.lo, p.lo)
    // when it is zero: so that corner is computed too and wins ties. Three products instead of eight,
    // bit for bit the corners' result (a thin factor is interval.cpp's thin path).
    const SlotState* pos = b.f.lo_positive ? &b : a.f.lo_positive ? &a : nullptr;
    if (pos) {
        const SlotState& y = pos == &b ? a : b;
        const bool thin = pos->f.thin;
        Value* p_lo = pos->v.lo;
        Value* p_hi = thin ? p_lo : pos->v.hi;
        Value* zl = is_zero(y, false);
        Value* lo = sel(zl, cst(0.0), mul_down(y.v.lo, thin ? p_lo : sel(ge(y.v.lo, cst(0.0)), p_lo, p_hi)));
        Value* up_lo = sel(zl, cst(0.0), mul(y.v.lo, p_lo));
        Value* up_hi =
            sel(is_zero(y, true), cst(0.0), mul(y.v.hi, thin ? p_lo : sel(ge(y.v.hi, cst(0.0)), p_hi, p_lo)));
        Value* hi = sel(lt(up_lo, up_hi), up_hi, up_lo);
        return result(guard(e, {lo, hi}, empty()), a.f.maybe_empty || b.f.maybe_empty);
    }
    Value* za[2] = {is_zero(a, false), is_zero(a, true)};
    Value* zb[2] = {is_zero(b, false), is_zero(b, true)};
    Value* xa[2] = {a.v.lo, a.v.hi};
    Value* xb[2] = {b.v.lo, b.v.hi};
    Value* lo = nullptr;
    Value* hi = nullptr;
    // Corners in the order of interval.cpp: (lo,lo), (lo,hi), (hi,lo), (hi,hi); min/max_element
    // keep the first of equal values. 0 * anything is 0.
    std::map<std::pair<Value*, Value*>, std::pair<Value*, Value*>> memo;
    for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) {
            auto key = std::make_pair(xa[i], xb[j]);
            auto it = memo.find(key);
            if (it == memo.end()) {
                Value* z = b_.CreateOr(za[i], zb[j]);
                Value* dn = sel(z, cst(0.0), mul_down(xa[i], xb[j]));
                Value* up = sel(z, cst(0.0), mul(xa[i], xb[j]));
                it = memo.emplace(key, std::make_pair(dn, up)).first;
            }
            Value* dn = it->second.first;
            Value* up = it->second.second;
            lo = lo ? (dn == lo ? lo : sel(lt(dn, lo), dn, lo)) : dn;
            hi = hi ? (up == hi ? hi : sel(lt(hi, up), up, hi)) : up;
        }
    return result(guard(e, {lo, hi}, empty()), a.f.maybe_empty || b.f.maybe_empty);
}

// a / b for b not containing 0 and nothing empty; `pos`: b.lo > 0 (else b.hi < 0).
IV BoxGen::div_nonzero(const SlotState& a, const SlotState& b, Value* pos) {
    Value* alo_nonneg = ge(a.v.lo, cst(0.0));
    Value* ahi_nonpos = le(a.v.hi, cst(0.0));
    Value* lo_num = sel(pos, a.v.lo, a.v.hi);
    Value* lo_den =
        sel(pos, sel(alo_nonneg, b.v.hi, b.v.lo), sel(land(lnot(alo_nonneg), ahi_nonpos), b.v.lo, b.v.hi));
    Value* hi_num = sel(pos, a.v.hi, a.v.lo);
    Value* hi_den =
        sel(pos, sel(alo_nonneg, b.v.lo, sel(ahi_nonpos, b.v.hi, b.v.lo)), sel(alo_nonneg, b.v.lo, b.v.hi));
    // A finite divisor not containing 0: no 0 / 0 or inf / inf.
    return widen_nan_unless(b.f.finite, div_down(lo_num, lo_den), div(hi_num, hi_den));
}

SlotState BoxGen::op_div(const SlotState& a, const SlotState& b) {
    // A divisor of statically known sign: the branch the interpreter takes.
    if (b.f.lo_positive || b.f.hi_negative)
        return result(guard(empty_of(a), div_nonzero(a, b, i1(b.f.lo_positive)), empty()), a.f.maybe_empty);
    Value* pos = gt(b.v.lo, cst(0.0));
    Value* fast = b_.CreateOr(pos, lt(b.v.hi, cst(0.0)));
    if (Value* e = lor(empty_of(a), empty_of(b))) fast = land(fast, lnot(e));
    const IV rf = div_nonzero(a, b, pos); // garbage in the other lanes, replaced by the core's results
    return result(with_fallback(fast, rf, Op::Div, {&a, &b}), true);
}

SlotState BoxGen::op_neg(const SlotState& a) {
    return result({neg(a.v.hi), neg(a.v.lo)}, a.f.maybe_empty);
}

IV BoxGen::abs_nonempty(IV a) {
    Value* lo_nonneg = ge(a.lo, cst(0.0));
    Value* hi_nonpos = le(a.hi, cst(0.0));
    Value* nlo = neg(a.lo);
    Value* lo = sel(lo_nonneg, a.lo, sel(hi_nonpos, neg(a.hi), cst(0.0)));
    Value* hi = sel(lo_nonneg, a.hi, sel(hi_nonpos, nlo, std_max(nlo, a.hi)));
    return {lo, hi};
}

SlotState BoxGen::op_abs(const SlotState& a) {
    return result(guard(empty_of(a), abs_nonempty(a.v), a.v), a.f.maybe_empty);
}

Value* BoxGen::pow_up(Value* x, std::uint64_t n) {
    Value* r = cst(1.0);
    for (Value* p = x;; p = mul(p, p)) {
        if (n & 1) r = mul(r, p);
        if ((n >>= 1) == 0) return r;
    }
}

Value* BoxGen::pow_down(Value* x, std::uint64_t n) {
    Value* r = cst(1.0);
    for (Value* p = x;; p = mul_down(p, p)) {
        if (n & 1) r = mul_down(r, p);
        if ((n >>= 1) == 0) return r;
    }
}

IV BoxGen::pow_positive(IV a, std::uint64_t n) {
    if (n % 2 == 0) {
        const IV m = abs_nonempty(a);
        return {pow_down(m.lo, n), pow_up(m.hi, n)};
    }
    Value* lo = sel(ge(a.lo, cst(0.0)), pow_down(a.lo, n), neg(pow_up(neg(a.lo), n)));
    Value* hi = sel(ge(a.hi, cst(0.0)), pow_up(a.hi, n), neg(pow_down(neg(a.hi), n)));
    return {lo, hi};
}

SlotState BoxGen::op_sqr(const SlotState& a) {
    return result(guard(empty_of(a), pow_positive(a.v, 2), a.v), a.f.maybe_empty);
}

SlotState BoxGen::op_powi(const SlotState& a, std::int64_t n) {
    if (n == 0) return result(guard(empty_of(a), {cst(1.0), cst(1.0)}, a.v), a.f.maybe_empty);
    // Negative powers divide; huge ones would unroll for nothing: the core does both.
    if (n < 0 || n > 1024) return call_core(Op::PowI, n, {&a}, true);
    return result(guard(empty_of(a), pow_positive(a.v, static_cast<std::uint64_t>(n)), a.v), a.f.maybe_empty);
}

SlotState BoxGen::op_minmax(const SlotState& a, const SlotState& b, bool is_min) {
    Value* e = lor(empty_of(a), empty_of(b));
    const IV r = is_min ? IV{std_min(a.v.lo, b.v.lo), std_min(a.v.hi, b.v.hi)}
                        : IV{std_max(a.v.lo, b.v.lo), std_max(a.v.hi, b.v.hi)};
    return result(guard(e, r, empty()), a.f.maybe_empty || b.f.maybe_empty);
}

SlotState BoxGen::op_round(const SlotState& a, bool up) {
    const IV r = up ? IV{ceil(a.v.lo), ceil(a.v.hi)} : IV{floor(a.v.lo), floor(a.v.hi)};
    return result(guard(empty_of(a), r, a.v), a.f.maybe_empty);
}

Value* BoxGen::is_finite(Value* x) {
    return lt(fabs(x), cst(inf));
}

SlotState BoxGen::op_mod1(const SlotState& a) {
    Value* f = floor(a.v.lo);
    // The core's test (an end infinite, or floor hi != floor lo) with one rounding: !(hi < RU(f + 1)).
    // f + 1 is exact below 2^53 and the next double above f beyond it; an infinite end makes the
    // comparison false.
    Value* whole = lnot(lt(a.v.hi, add(f, cst(1.0))));
    const IV r{sel(whole, cst(0.0), sub_down(a.v.lo, f)), sel(whole, cst(1.0), sub(a.v.hi, f))};
    return result(guard(empty_of(a), r, a.v), a.f.maybe_empty);
}

SlotState BoxGen::op_dz(const SlotState& a) {
    Value* lo = a.v.lo;
    Value* hi = a.v.hi;
    // Two roundings instead of four and no test for a whole period, the interpreter's bits
    // (numeric::dz) all the same: when hi - lo >= 1 (rounded upward) the bounds below are 0 (an integer
    // lies in the box) and 1/2 (hi - k >= 1/2); where an end is infinite ceil lo <= hi holds and a
    // difference is infinite or NaN, and the comparison in std_min(1/2, NaN) is false: 1/2.
    Value* cl = ceil(lo);
    Value* k = round_even(lo);
    // dz_down(x) = min(sub_down(x, floor x), sub_down(ceil x, x)). The lower bound min(dz_down(lo),
    // dz_down(hi)) counts only when no integer lies in [lo, hi]: then lo is not an integer, floor lo =
    // ceil lo - 1 (exact below 2^53, where every double is an integer), ceil hi = ceil lo, and of the
    // four differences, all positive, the least is at lo - floor lo or ceil hi - hi (RD is monotone;
    // equal positive doubles have equal bits).
    Value* rlo = std_min(sub_down(lo, sub(cl, cst(1.0))), sub_down(cl, hi));
    rlo = sel(le(cl, hi), cst(0.0), rlo);
    // The upper bound max(dz_up(lo), dz_up(hi)) counts only when no half-integer lies in [lo, hi]: then
    // both ends are nearer to one integer k than to any other (neither is a half-integer), dz_up(x) is
    // RU(|x - k|) (the nearer difference; RU is monotone), and the larger of the two is RU(k - lo) or
    // RU(hi - k), whichever is not negative (both +0 when lo = hi = k, as dz_up gives). With k nearest
    // to lo and hi - lo < 1, a half-integer lies in [lo, hi] exactly when lo = k - 1/2 or hi >= k + 1/2,
    // and both differences, within 3/2 of an integer, are exact: then one of them is at least 1/2 and
    // the bound is 1/2, otherwise both are below it.
    Value* rhi = std_min(cst(0.5), std_max(sub(k, lo), sub(hi, k)));
    return result(guard(empty_of(a), IV{rlo, rhi}, a.v), a.f.maybe_empty);
}

SlotState BoxGen::op_not(const SlotState& a) {
    const IV r{sub(cst(1.0), a.v.hi), sub(cst(1.0), a.v.lo)};
    return result(guard(empty_of(a), r, empty()), a.f.maybe_empty);
}

SlotState BoxGen::op_andor(const SlotState& a, const SlotState& b, bool is_and) {
    Value* e = lor(empty_of(a), empty_of(b));
    const IV r = is_and ? IV{c_fmin(a.v.lo, b.v.lo), c_fmin(a.v.hi, b.v.hi)}
                        : IV{c_fmax(a.v.lo, b.v.lo), c_fmax(a.v.hi, b.v.hi)};
    return result(guard(e, r, empty()), a.f.maybe_empty || b.f.maybe_empty);
}

IV BoxGen::truth(Value* t, Value* f) {
    return {sel(t, cst(1.0), cst(0.0)), sel(b_.CreateOr(t, lnot(f)), cst(1.0), cst(0.0))};
}

SlotState BoxGen::op_compare(Op op, const SlotState& a, const SlotState& b) {
    Value* e = lor(empty_of(a), empty_of(b));
    const IV& x = a.v;
    const IV& y = b.v;
    IV r;
    switch (op) {
    case Op::Lt: r = truth(lt(x.hi, y.lo), ge(x.lo, y.hi)); break;
    case Op::Le: r = truth(le(x.hi, y.lo), gt(x.lo, y.hi)); break;
    case Op::Gt: r = truth(gt(x.lo, y.hi), le(x.hi, y.lo)); break;
    case Op::Ge: r = truth(ge(x.lo, y.hi), lt(x.hi, y.lo)); break;
    case Op::Eq:
    case Op::Ne: {
        Value* same = land(eq(x.lo, x.hi), land(eq(x.lo, y.lo), eq(x.hi, y.hi)));
        Value* apart = b_.CreateOr(lt(x.hi, y.lo), lt(y.hi, x.lo));
        r = op == Op::Eq ? truth(same, apart) : truth(apart, same);
        break;
    }
    default: throw std::logic_error("jit: op_compare");
    }
    return result(guard(e, r, empty()), a.f.maybe_empty || b.f.maybe_empty);
}

SlotState BoxGen::op_select(const SlotState& c, const SlotState& x, const SlotState& y) {
    IV h{std_min(x.v.lo, y.v.lo), std_max(x.v.hi, y.v.hi)}; // hull: an empty side gives the other
    if (Value* ey = empty_of(y)) h = guard(ey, h, x.v);
    if (Value* ex = empty_of(x)) h = guard(ex, h, y.v);
    Value* is_true = land(eq(c.v.lo, cst(1.0)), eq(c.v.hi, cst(1.0)));
    Value* is_false = land(eq(c.v.lo, cst(0.0)), eq(c.v.hi, cst(0.0)));
    IV r = guard(is_false, h, y.v);
    r = guard(is_true, r, x.v);
    r = guard(empty_of(c), r, empty());
    return result(r, c.f.maybe_empty || x.f.maybe_empty || y.f.maybe_empty);
}

SlotState BoxGen::emit_op(const Instr& ins) {
    auto in = [&](int k) -> const SlotState& { return vals_[ins.in[static_cast<std::size_t>(k)]]; };
    switch (ins.op) {
    case Op::Add: return op_add(in(0), in(1));
    case Op::Sub: return op_sub(in(0), in(1));
    case Op::Mul: return op_mul(in(0), in(1));
    case Op::Div: return op_div(in(0), in(1));
    case Op::Neg: return op_neg(in(0));
    case Op::Sqr: return op_sqr(in(0));
    case Op::PowI: return op_powi(in(0), ins.imm);
    case Op::Abs: return op_abs(in(0));
    case Op::Min: return op_minmax(in(0), in(1), true);
    case Op::Max: return op_minmax(in(0), in(1), false);
    case Op::Floor: return op_round(in(0), false);
    case Op::Ceil: return op_round(in(0), true);
    case Op::Mod1: return op_mod1(in(0));
    case Op::Dz: return op_dz(in(0));
    case Op::Sqrt: return fast_kernels_ ? op_sqrt(in(0)) : call_core(ins.op, 0, {&in(0)}, true);
    case Op::Sin:
    case Op::Cos:
        if (fast_kernels_) return op_sincos(in(0), ins.op == Op::Cos);
        return call_core(ins.op, 0, {&in(0)}, in(0).f.maybe_empty);
    case Op::Log:
        if (fast_kernels_ && ir::arity(ins.op) == 1) return op_log(in(0));
        return call_core(ins.op, 0, {&in(0), &in(ir::arity(ins.op) > 1 ? 1 : 0)}, true);
    case Op::Pow:
        if (fast_kernels_) return op_pow(in(0), in(1));
        return call_core(ins.op, 0, {&in(0), &in(1)}, true);
    case Op::Exp:
        if (fast_kernels_) return op_exp(in(0));
        return call_core(ins.op, 0, {&in(0)}, in(0).f.maybe_empty);
    case Op::Tan:
        if (fast_kernels_) return op_tan(in(0));
        return call_core(ins.op, 0, {&in(0)}, in(0).f.maybe_empty);
    case Op::Atan2:
        if (fast_kernels_) return op_atan2(in(0), in(1));
        return call_core(ins.op, 0, {&in(0), &in(1)}, in(0).f.maybe_empty || in(1).f.maybe_empty);
    case Op::External: return call_external(ins.imm, in(0), in(1), in(2));
    case Op::Lt:
    case Op::Le:
    case Op::Gt:
    case Op::Ge:
    case Op::Eq:
    case Op::Ne: return op_compare(ins.op, in(0), in(1));
    case Op::And: return op_andor(in(0), in(1), true);
    case Op::Or: return op_andor(in(0), in(1), false);
    case Op::Not: return op_not(in(0));
    case Op::Select: return op_select(in(0), in(1), in(2));
#include "ir/non_operation_cases.def"
        break;
    }
    throw std::logic_error(std::string("jit: not an operation: ") + ir::op_name(ins.op));
}

} // namespace frac::jit::box
