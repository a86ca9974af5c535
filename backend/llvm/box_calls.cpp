// Box code that calls into the numeric core (the operations not inlined, series tails, escape bounds and
// Lipschitz enclosures, scalar or lane by lane through the vector helpers of helpers.hpp) and reads the
// precomputed tables (see box_gen.hpp).
#include "backend/llvm/box_gen.hpp"
#include "ir/series_tail.hpp"

#include <stdexcept>

namespace frac::jit::box {

// ---- calls into the numeric core ----
// Scalar code calls the helpers of helpers.hpp directly; vector code stores its lanes and calls
// frac_jit_vop, which applies ir::apply_interval to the lanes of `mask`.
IV BoxGen::call_scalar(const char* helper, std::vector<Value*> args) {
    std::vector<Type*> types;
    for (Value* v : args) types.push_back(v->getType());
    auto callee = m_.getOrInsertFunction(helper, llvm::FunctionType::get(pair_, types, false));
    llvm::cast<Function>(callee.getCallee())->setDoesNotThrow();
    Value* r = b_.CreateCall(callee, args);
    return {b_.CreateExtractValue(r, 0), b_.CreateExtractValue(r, 1)};
}

IV BoxGen::call_vector(Op op, std::int64_t imm, const std::vector<IV>& args, Value* mask) {
    for (std::size_t a = 0; a < args.size(); ++a) {
        b_.CreateStore(args[a].lo, b_.CreateConstInBoundsGEP1_64(dbl_, scratch_in_,
                                                                 2 * a * static_cast<std::uint64_t>(w_)));
        b_.CreateStore(args[a].hi, b_.CreateConstInBoundsGEP1_64(
                                       dbl_, scratch_in_, (2 * a + 1) * static_cast<std::uint64_t>(w_)));
    }
    auto callee = m_.getOrInsertFunction(
        "frac_jit_vop",
        llvm::FunctionType::get(Type::getVoidTy(ctx_), {i32_, i64_, ptr_, ptr_, i32_, i32_}, false));
    llvm::cast<Function>(callee.getCallee())->setDoesNotThrow();
    b_.CreateCall(callee,
                  {b_.getInt32(static_cast<std::uint32_t>(op)), b_.getInt64(static_cast<std::uint64_t>(imm)),
                   scratch_in_, scratch_out_, mask_bits(mask), b_.getInt32(static_cast<std::uint32_t>(w_))});
    return {b_.CreateLoad(vt_, scratch_out_),
            b_.CreateLoad(vt_,
                          b_.CreateConstInBoundsGEP1_64(dbl_, scratch_out_, static_cast<std::uint64_t>(w_)))};
}

namespace {
const char* helper_name(Op op) {
    switch (op) {
    case Op::Div: return "frac_jit_div";
    case Op::Pow: return "frac_jit_pow";
    case Op::Atan2: return "frac_jit_atan2";
    case Op::Sqrt: return "frac_jit_sqrt";
    case Op::Sin: return "frac_jit_sin";
    case Op::Cos: return "frac_jit_cos";
    case Op::Tan: return "frac_jit_tan";
    case Op::Exp: return "frac_jit_exp";
    case Op::Log: return "frac_jit_log";
    case Op::PowI: return "frac_jit_powi";
    default: break;
    }
    throw std::logic_error(std::string("jit: no helper for ") + ir::op_name(op));
}
} // namespace

SlotState BoxGen::call_core(Op op, std::int64_t imm, const std::vector<const SlotState*>& args,
                            bool maybe_empty) {
    if (w_ > 1) {
        std::vector<IV> v;
        for (const SlotState* a : args) v.push_back(a->v);
        return result(call_vector(op, imm, v, ctx_mask_), maybe_empty);
    }
    std::vector<Value*> flat;
    for (const SlotState* a : args) {
        flat.push_back(a->v.lo);
        flat.push_back(a->v.hi);
    }
    if (op == Op::PowI) flat.push_back(b_.getInt64(static_cast<std::uint64_t>(imm)));
    return result(call_scalar(helper_name(op), flat), maybe_empty);
}

IV BoxGen::with_fallback(Value* fast_lanes, IV fast, Op op, const std::vector<const SlotState*>& args) {
    Value* slow = land(ctx_mask_, lnot(fast_lanes));
    BasicBlock* pre = b_.GetInsertBlock();
    BasicBlock* slow_bb = BasicBlock::Create(ctx_, "core.call", fn_);
    BasicBlock* join = BasicBlock::Create(ctx_, "core.join", fn_);
    b_.CreateCondBr(any(slow), slow_bb, join);
    b_.SetInsertPoint(slow_bb);
    IV rs;
    if (w_ == 1) {
        rs = call_core(op, 0, args, true).v;
    } else {
        std::vector<IV> v;
        for (const SlotState* a : args) v.push_back(a->v);
        const IV core = call_vector(op, 0, v, slow);
        rs = {sel(slow, core.lo, fast.lo), sel(slow, core.hi, fast.hi)};
    }
    BasicBlock* slow_end = b_.GetInsertBlock();
    b_.CreateBr(join);
    b_.SetInsertPoint(join);
    llvm::PHINode* lo = b_.CreatePHI(vt_, 2);
    llvm::PHINode* hi = b_.CreatePHI(vt_, 2);
    lo->addIncoming(fast.lo, pre);
    lo->addIncoming(rs.lo, slow_end);
    hi->addIncoming(fast.hi, pre);
    hi->addIncoming(rs.hi, slow_end);
    return {lo, hi};
}

SlotState BoxGen::call_external(std::int64_t k, const SlotState& a, const SlotState& b, const SlotState& c) {
    Value* f = external_function(k);
    const bool maybe_empty = a.f.maybe_empty || b.f.maybe_empty || c.f.maybe_empty;
    const SlotState* args[3] = {&a, &b, &c};
    if (w_ == 1) {
        std::vector<Value*> flat = {f};
        for (const SlotState* s : args) {
            flat.push_back(s->v.lo);
            flat.push_back(s->v.hi);
        }
        return result(call_scalar("frac_jit_external", flat), maybe_empty);
    }
    for (std::size_t i = 0; i < 3; ++i) {
        b_.CreateStore(args[i]->v.lo, b_.CreateConstInBoundsGEP1_64(dbl_, scratch_in_,
                                                                    2 * i * static_cast<std::uint64_t>(w_)));
        b_.CreateStore(args[i]->v.hi, b_.CreateConstInBoundsGEP1_64(
                                          dbl_, scratch_in_, (2 * i + 1) * static_cast<std::uint64_t>(w_)));
    }
    auto callee = m_.getOrInsertFunction(
        "frac_jit_vexternal",
        llvm::FunctionType::get(Type::getVoidTy(ctx_), {ptr_, ptr_, ptr_, i32_, i32_}, false));
    llvm::cast<Function>(callee.getCallee())->setDoesNotThrow();
    b_.CreateCall(callee, {f, scratch_in_, scratch_out_, mask_bits(ctx_mask_),
                           b_.getInt32(static_cast<std::uint32_t>(w_))});
    return result({b_.CreateLoad(vt_, scratch_out_),
                   b_.CreateLoad(vt_, b_.CreateConstInBoundsGEP1_64(dbl_, scratch_out_,
                                                                    static_cast<std::uint64_t>(w_)))},
                  maybe_empty);
}

// Entry idx (a scalar, the same for every lane) of a table of doubles / of intervals.
Value* BoxGen::load_scalar(llvm::GlobalVariable* g, Value* idx) {
    return splat(b_.CreateLoad(dbl_, b_.CreateInBoundsGEP(dbl_, g, idx)));
}

IV BoxGen::load_pair(llvm::GlobalVariable* g, Value* idx) {
    Value* i2 = b_.CreateShl(idx, 1);
    return {load_scalar(g, i2), load_scalar(g, b_.CreateOr(i2, b_.getInt64(1)))};
}

// Entry idx[lane] of a table of intervals, lane by lane.
IV BoxGen::gather_pair(llvm::GlobalVariable* g, Value* idx) {
    if (w_ == 1) return load_pair(g, idx);
    Value* lo = llvm::PoisonValue::get(vt_);
    Value* hi = llvm::PoisonValue::get(vt_);
    for (int l = 0; l < w_; ++l) {
        Value* i2 = b_.CreateShl(b_.CreateExtractElement(idx, b_.getInt64(static_cast<std::uint64_t>(l))), 1);
        Value* x = b_.CreateLoad(dbl_, b_.CreateInBoundsGEP(dbl_, g, i2));
        Value* y = b_.CreateLoad(dbl_, b_.CreateInBoundsGEP(dbl_, g, b_.CreateOr(i2, b_.getInt64(1))));
        lo = b_.CreateInsertElement(lo, x, b_.getInt64(static_cast<std::uint64_t>(l)));
        hi = b_.CreateInsertElement(hi, y, b_.getInt64(static_cast<std::uint64_t>(l)));
    }
    return {lo, hi};
}

SlotState BoxGen::from_table(IV v, const Facts& f) {
    SlotState s;
    s.v = v;
    s.f = f;
    return s;
}

SlotState BoxGen::combine(Op kind, const SlotState& acc, const SlotState& term) {
    switch (kind) {
    case Op::SeriesSum: return op_add(acc, term);
    case Op::SeriesMin: return op_minmax(acc, term, true);
    case Op::SeriesMax: return op_minmax(acc, term, false);
    default: break;
    }
    throw std::logic_error("jit: not a series");
}

// ir::series_tail(kind, A, B, gamma, n) for box-dependent A, B; n a scalar index or one per lane.
SlotState BoxGen::tail_core(const TapeSeries& s, const SlotState& a, const SlotState& bc, bool has_b,
                            Value* n, Value* mask) {
    if (w_ == 1) {
        return result(
            call_scalar("frac_jit_series_tail",
                        {b_.getInt32(static_cast<std::uint32_t>(s.kind)), a.v.lo, a.v.hi, bc.v.lo, bc.v.hi,
                         b_.getInt32(has_b ? 1 : 0), llvm::ConstantFP::get(dbl_, s.data.gamma.lo),
                         llvm::ConstantFP::get(dbl_, s.data.gamma.hi), n}),
            true);
    }
    b_.CreateStore(a.v.lo, b_.CreateConstInBoundsGEP1_64(dbl_, scratch_in_, 0));
    b_.CreateStore(a.v.hi, b_.CreateConstInBoundsGEP1_64(dbl_, scratch_in_, static_cast<std::uint64_t>(w_)));
    b_.CreateStore(bc.v.lo,
                   b_.CreateConstInBoundsGEP1_64(dbl_, scratch_in_, 2 * static_cast<std::uint64_t>(w_)));
    b_.CreateStore(bc.v.hi,
                   b_.CreateConstInBoundsGEP1_64(dbl_, scratch_in_, 3 * static_cast<std::uint64_t>(w_)));
    b_.CreateStore(n->getType()->isVectorTy() ? n : b_.CreateVectorSplat(static_cast<unsigned>(w_), n),
                   scratch_n_);
    auto callee = m_.getOrInsertFunction(
        "frac_jit_vtail",
        llvm::FunctionType::get(Type::getVoidTy(ctx_), {i32_, ptr_, ptr_, ptr_, i32_, dbl_, dbl_, i32_, i32_},
                                false));
    llvm::cast<Function>(callee.getCallee())->setDoesNotThrow();
    b_.CreateCall(callee,
                  {b_.getInt32(static_cast<std::uint32_t>(s.kind)), scratch_in_, scratch_n_, scratch_out_,
                   b_.getInt32(has_b ? 1 : 0), llvm::ConstantFP::get(dbl_, s.data.gamma.lo),
                   llvm::ConstantFP::get(dbl_, s.data.gamma.hi), mask_bits(mask),
                   b_.getInt32(static_cast<std::uint32_t>(w_))});
    return result({b_.CreateLoad(vt_, scratch_out_),
                   b_.CreateLoad(vt_, b_.CreateConstInBoundsGEP1_64(dbl_, scratch_out_,
                                                                    static_cast<std::uint64_t>(w_)))},
                  true);
}

void BoxGen::store_state(const std::vector<IV>& state) {
    const auto w = static_cast<std::uint64_t>(w_);
    for (std::size_t c = 0; c < state.size(); ++c) {
        b_.CreateStore(state[c].lo, b_.CreateConstInBoundsGEP1_64(dbl_, esc_in_, 2 * c * w));
        b_.CreateStore(state[c].hi, b_.CreateConstInBoundsGEP1_64(dbl_, esc_in_, (2 * c + 1) * w));
    }
}

std::vector<Value*> BoxGen::escape_params(const ir::OrbitEscape& e) {
    auto d = [&](double x) { return llvm::ConstantFP::get(dbl_, x); };
    return {d(e.radius),    d(e.slope),     d(e.offset),    d(e.scale0.lo),    d(e.scale0.hi),
            d(e.growth.lo), d(e.growth.hi), d(e.lipschitz), d(e.map_lipschitz)};
}

Value* BoxGen::mask_arg(Value* mask) {
    return w_ == 1 ? b_.getInt32(1) : mask_bits(mask);
}

// ir::lipschitz_centre of the initial point, lane by lane: the centres (replacing `init`) and h.
Value* BoxGen::centre_orbit(std::vector<IV>& init, Value* mask) {
    store_state(init);
    auto callee = m_.getOrInsertFunction(
        "frac_jit_vcentre",
        llvm::FunctionType::get(Type::getVoidTy(ctx_), {ptr_, i32_, ptr_, i32_, i32_}, false));
    llvm::cast<Function>(callee.getCallee())->setDoesNotThrow();
    b_.CreateCall(callee, {esc_in_, b_.getInt32(static_cast<std::uint32_t>(init.size())), esc_h_,
                           mask_arg(mask), b_.getInt32(static_cast<std::uint32_t>(w_))});
    const auto w = static_cast<std::uint64_t>(w_);
    for (std::size_t c = 0; c < init.size(); ++c)
        init[c] = {b_.CreateLoad(vt_, b_.CreateConstInBoundsGEP1_64(dbl_, esc_in_, 2 * c * w)),
                   b_.CreateLoad(vt_, b_.CreateConstInBoundsGEP1_64(dbl_, esc_in_, (2 * c + 1) * w))};
    return b_.CreateLoad(vt_, esc_h_);
}

// ir::lipschitz_finish lane by lane.
SlotState BoxGen::lipschitz_finish(const TapeSeries& s, const SlotState& acc, const SlotState& tail,
                                   Value* bound, Value* n, Value* mask) {
    const auto w = static_cast<std::uint64_t>(w_);
    b_.CreateStore(acc.v.lo, b_.CreateConstInBoundsGEP1_64(dbl_, esc_out_, 0));
    b_.CreateStore(acc.v.hi, b_.CreateConstInBoundsGEP1_64(dbl_, esc_out_, w));
    b_.CreateStore(tail.v.lo, b_.CreateConstInBoundsGEP1_64(dbl_, esc_out_, 2 * w));
    b_.CreateStore(tail.v.hi, b_.CreateConstInBoundsGEP1_64(dbl_, esc_out_, 3 * w));
    b_.CreateStore(bound, esc_in_);
    b_.CreateStore(n->getType()->isVectorTy() ? n : splat(n), esc_n_);
    std::vector<Type*> types = {i32_, ptr_, ptr_, ptr_, ptr_};
    for (int k = 0; k < 9; ++k) types.push_back(dbl_);
    types.push_back(i32_);
    types.push_back(i32_);
    auto callee = m_.getOrInsertFunction("frac_jit_vfinish",
                                         llvm::FunctionType::get(Type::getVoidTy(ctx_), types, false));
    llvm::cast<Function>(callee.getCallee())->setDoesNotThrow();
    std::vector<Value*> args = {b_.getInt32(static_cast<std::uint32_t>(s.kind)), esc_out_, esc_in_, esc_n_,
                                esc_h_};
    for (Value* p : escape_params(s.data.escape)) args.push_back(p);
    args.push_back(mask_arg(mask));
    args.push_back(b_.getInt32(static_cast<std::uint32_t>(w_)));
    b_.CreateCall(callee, args);
    return result(
        {b_.CreateLoad(vt_, esc_out_), b_.CreateLoad(vt_, b_.CreateConstInBoundsGEP1_64(dbl_, esc_out_, w))},
        true);
}

// ir::escape_bound of the orbit point `state` (index n, scalar) for the lanes in `mask`, and
// ir::escape_bound_around with each lane's radius h (the same without a Lipschitz bound).
std::pair<Value*, Value*> BoxGen::escape_bound(const TapeSeries& s, const std::vector<IV>& state, Value* n,
                                               Value* mask) {
    const auto w = static_cast<std::uint64_t>(w_);
    store_state(state);
    b_.CreateStore(splat(n), esc_n_);
    auto callee = m_.getOrInsertFunction(
        "frac_jit_vescape", llvm::FunctionType::get(Type::getVoidTy(ctx_),
                                                    {i32_, ptr_, ptr_, ptr_, i32_, dbl_, dbl_, dbl_, dbl_,
                                                     dbl_, dbl_, dbl_, dbl_, dbl_, ptr_, i32_, i32_},
                                                    false));
    llvm::cast<Function>(callee.getCallee())->setDoesNotThrow();
    std::vector<Value*> args = {b_.getInt32(static_cast<std::uint32_t>(s.kind)), esc_in_, esc_n_, esc_out_,
                                b_.getInt32(static_cast<std::uint32_t>(state.size()))};
    for (Value* p : escape_params(s.data.escape)) args.push_back(p);
    args.push_back(s.data.escape.lipschitz > 0
                       ? esc_h_
                       : llvm::ConstantPointerNull::get(llvm::PointerType::get(ctx_, 0)));
    args.push_back(mask_arg(mask));
    args.push_back(b_.getInt32(static_cast<std::uint32_t>(w_)));
    b_.CreateCall(callee, args);
    return {b_.CreateLoad(vt_, esc_out_),
            b_.CreateLoad(vt_, b_.CreateConstInBoundsGEP1_64(dbl_, esc_out_, w))};
}

// ir::escape_tighten: the tail intersected with the escape bound; its signs are no longer known.
SlotState BoxGen::escape_tighten(Op kind, const SlotState& tail, Value* bound) {
    if (kind == Op::SeriesMax) {
        Value* hi = sel(lt(bound, tail.v.hi), bound, tail.v.hi);
        return result({sel(lt(hi, tail.v.lo), hi, tail.v.lo), hi}, true);
    }
    Value* lo = sel(gt(bound, tail.v.lo), bound, tail.v.lo);
    return result({lo, sel(gt(lo, tail.v.hi), lo, tail.v.hi)}, true);
}

} // namespace frac::jit::box
