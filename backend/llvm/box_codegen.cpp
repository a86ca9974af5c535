// The interval evaluator: W boxes at a time (one per vector lane; W = 1 is plain scalar code).
//
// Every operation mirrors numeric/interval.cpp step by step: the same IEEE operations on the
// same operands, the same comparisons deciding between equal values of different sign, so the bits
// are the interpreter's. Upward rounding comes either from LLVM's constrained intrinsics
// ("round.upward", "fpexcept.ignore"; the caller holds MXCSR upward) or, on AVX-512 hosts, from
// instructions with embedded rounding ({ru-sae}), which the optimiser treats as opaque pure
// functions. Lower bounds are -RU(-x op y). Comparisons, selects, negation, fabs, floor and ceil are
// exact in every mode and are plain IR. Operations that are not inlined call the numeric core.
//
// Series run as loops over the index shared by all lanes; a lane stops by the interpreter's rules
// (the term no narrower than 3/4 of its bound, a negligible tail, a one-sided tail that cannot help,
// or the term limit), after which its partial result is frozen; the loop ends when no lane is active.
#include "backend/llvm/box_codegen.hpp"

#include "backend/llvm/helpers.hpp"
#include "backend/llvm/skeleton.hpp"
#include "ir/graph.hpp"
#include "ir/series_tail.hpp"

#include <llvm/IR/ConstantFold.h>
#include <llvm/IR/Constants.h>
#include <llvm/IR/DerivedTypes.h>
#include <llvm/IR/FPEnv.h>
#include <llvm/IR/Function.h>
#include <llvm/IR/GlobalVariable.h>
#include <llvm/IR/IRBuilder.h>
#include <llvm/IR/Intrinsics.h>
#include <llvm/IR/IntrinsicsX86.h>
#include <llvm/IR/Module.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <tuple>

namespace frac::jit {
namespace {

using ir::Instr;
using ir::Op;
using ir::Slot;
using ir::Tape;
using ir::TapeSeries;
using llvm::BasicBlock;
using llvm::Function;
using llvm::Type;
using llvm::Value;

constexpr double inf = std::numeric_limits<double>::infinity();

struct IV {
    Value* lo = nullptr;
    Value* hi = nullptr;
};

struct SlotState {
    IV v;
    Facts f;            // emptiness and signs, for every lane
    bool known = false; // a constant: k is its value
    Interval k;
};

class BoxGen : public Skeleton<BoxGen, SlotState> {
    friend class Skeleton<BoxGen, SlotState>;

public:
    BoxGen(const Tape& t, const ir::EvalOptions& o, const Tables& tab, llvm::Module& m, std::string name,
           Rounding rounding, int lanes)
        : Skeleton(t, o, tab, m, std::move(name), lanes), avx512_(rounding == Rounding::avx512) {
        if (avx512_ && w_ != 1 && w_ != 8) throw std::logic_error("jit: AVX-512 rounding needs 1 or 8 lanes");
        vt_ =
            w_ == 1 ? dbl_ : static_cast<Type*>(llvm::FixedVectorType::get(dbl_, static_cast<unsigned>(w_)));
        mt_ = w_ == 1 ? Type::getInt1Ty(ctx_)
                      : static_cast<Type*>(
                            llvm::FixedVectorType::get(Type::getInt1Ty(ctx_), static_cast<unsigned>(w_)));
        vi64_ =
            w_ == 1 ? i64_ : static_cast<Type*>(llvm::FixedVectorType::get(i64_, static_cast<unsigned>(w_)));
        if (!avx512_) {
            b_.setIsFPConstrained(true);
            b_.setDefaultConstrainedRounding(llvm::RoundingMode::TowardPositive);
            b_.setDefaultConstrainedExcept(llvm::fp::ebIgnore);
        }
    }

private:
    // ---- the skeleton's hooks ----
    void prepare(Function* f) {
        if (!avx512_) f->addFnAttr(llvm::Attribute::StrictFP);
    }
    void allocate() {
        // Scratch memory of the helpers, aligned for whole-vector loads and stores.
        auto aligned = [&](Type* t, const char* what) {
            llvm::AllocaInst* a = b_.CreateAlloca(t, nullptr, what);
            a->setAlignment(llvm::Align(64));
            return a;
        };
        if (w_ > 1) {
            // The vector helpers: up to three interval operands in, one out.
            scratch_in_ = aligned(llvm::ArrayType::get(dbl_, static_cast<std::uint64_t>(6 * w_)), "vin");
            scratch_n_ = aligned(llvm::ArrayType::get(i64_, static_cast<std::uint64_t>(w_)), "vn");
            scratch_out_ = aligned(llvm::ArrayType::get(dbl_, static_cast<std::uint64_t>(2 * w_)), "vout");
            sink_ = aligned(llvm::ArrayType::get(dbl_, 2), "sink");
        }
        if (std::any_of(t_.series.begin(), t_.series.end(),
                        [](const TapeSeries& s) { return s.data.escape.present; })) {
            // The escape helper: up to max_state_components orbit components in, one bound per lane out.
            esc_in_ = aligned(
                llvm::ArrayType::get(dbl_, static_cast<std::uint64_t>(2 * ir::max_state_components * w_)),
                "ein");
            esc_n_ = aligned(llvm::ArrayType::get(i64_, static_cast<std::uint64_t>(w_)), "en");
            esc_out_ = aligned(llvm::ArrayType::get(dbl_, static_cast<std::uint64_t>(4 * w_)), "eout");
            esc_h_ = aligned(llvm::ArrayType::get(dbl_, static_cast<std::uint64_t>(w_)), "eh");
        }
    }
    // One iteration per group of W boxes; lanes past the end repeat the last box and are not stored.
    void load_inputs(Value* in, Value* n, Value* k) {
        first_box_ = b_.CreateMul(k, b_.getInt64(static_cast<std::uint64_t>(w_)));
        Value* last_box = b_.CreateSub(n, b_.getInt64(1));
        std::vector<Value*> box_of_lane(static_cast<std::size_t>(w_));
        for (int j = 0; j < w_; ++j) {
            Value* bj = b_.CreateAdd(first_box_, b_.getInt64(static_cast<std::uint64_t>(j)));
            box_of_lane[static_cast<std::size_t>(j)] =
                j == 0 ? bj : b_.CreateSelect(b_.CreateICmpULT(bj, n), bj, last_box);
        }
        if (w_ == 1) {
            ctx_mask_ = b_.getTrue();
        } else {
            Value* lanes =
                b_.CreateAdd(b_.CreateVectorSplat(static_cast<unsigned>(w_), first_box_), lane_numbers());
            ctx_mask_ = b_.CreateICmpULT(lanes, b_.CreateVectorSplat(static_cast<unsigned>(w_), n));
        }
        const auto d = static_cast<std::uint64_t>(t_.inputs);
        for (std::size_t j = 0; j < t_.input_slots.size(); ++j) {
            const Slot s = t_.input_slots[j];
            if (s == ir::no_slot) continue;
            SlotState& st = vals_[s];
            for (int half = 0; half < 2; ++half) {
                Value* v = w_ == 1 ? nullptr : static_cast<Value*>(llvm::PoisonValue::get(vt_));
                for (int l = 0; l < w_; ++l) {
                    Value* at = b_.CreateAdd(
                        b_.CreateMul(box_of_lane[static_cast<std::size_t>(l)], b_.getInt64(2 * d)),
                        b_.getInt64(2 * j + static_cast<std::uint64_t>(half)));
                    Value* x = b_.CreateLoad(dbl_, b_.CreateInBoundsGEP(dbl_, in, at));
                    v = w_ == 1 ? x
                                : b_.CreateInsertElement(v, x, b_.getInt64(static_cast<std::uint64_t>(l)));
                }
                (half ? st.v.hi : st.v.lo) = v;
            }
            st.f = tab_.slot_facts[s]; // not empty: boxes with an empty coordinate go to the interpreter
        }
    }
    void store_result(Value* out, Value* n, Value*) {
        const IV r = vals_[t_.result].v;
        for (int l = 0; l < w_; ++l) {
            Value* bj = b_.CreateAdd(first_box_, b_.getInt64(static_cast<std::uint64_t>(l)));
            Value* at = b_.CreateInBoundsGEP(dbl_, out, b_.CreateMul(bj, b_.getInt64(2)));
            if (l > 0) at = b_.CreateSelect(b_.CreateICmpULT(bj, n), at, sink_);
            b_.CreateStore(lane(r.lo, l), at);
            b_.CreateStore(lane(r.hi, l), b_.CreateInBoundsGEP(dbl_, at, b_.getInt64(1)));
        }
    }
    SlotState constant(const ir::TapeConst& c) {
        SlotState s;
        s.known = true;
        s.k = c.value;
        s.v = {cst(c.value.lo), cst(c.value.hi)};
        s.f = facts_of(&c.value, 1);
        return s;
    }
    SlotState indexed(const IndexTable& it, Value* idx) {
        return from_table(load_pair(table(&it.box, it.box, "index"), idx), it.facts);
    }
    SlotState operation(const Instr& ins) {
        SlotState r = emit_op(ins);
        r.f = tab_.slot_facts[ins.out];
        return r;
    }
    SlotState series(const Instr& ins) {
        SlotState r = emit_series(ins);
        r.f = tab_.slot_facts[ins.out];
        return r;
    }
    SlotState carry(const SlotState& init, BasicBlock* pre, Slot slot) {
        llvm::PHINode* lo = b_.CreatePHI(vt_, 2, "state.lo");
        llvm::PHINode* hi = b_.CreatePHI(vt_, 2, "state.hi");
        lo->addIncoming(init.v.lo, pre);
        hi->addIncoming(init.v.hi, pre);
        SlotState sc;
        sc.v = {lo, hi};
        sc.f = tab_.slot_facts[slot];
        return sc;
    }
    void carry_next(const SlotState& phis, const SlotState& next, BasicBlock* latch) {
        llvm::cast<llvm::PHINode>(phis.v.lo)->addIncoming(next.v.lo, latch);
        llvm::cast<llvm::PHINode>(phis.v.hi)->addIncoming(next.v.hi, latch);
    }
    SlotState index_value(const SeriesLoop& L) {
        const bool exact = std::max(std::fabs(static_cast<double>(L.start)),
                                    std::fabs(static_cast<double>(L.last))) < 0x1p52;
        return thin(splat(index_to_double(L.i, exact)));
    }
    // ---- lanes, masks and constants ----
    Value* cst(double x) { return llvm::ConstantFP::get(vt_, x); }
    Value* i1(bool v) { return llvm::ConstantInt::get(mt_, v ? 1 : 0); }
    Value* splat(Value* scalar) {
        return w_ == 1 ? scalar : b_.CreateVectorSplat(static_cast<unsigned>(w_), scalar);
    }
    Value* lane(Value* v, int l) {
        return w_ == 1 ? v : b_.CreateExtractElement(v, b_.getInt64(static_cast<std::uint64_t>(l)));
    }
    Value* lane_numbers() {
        std::vector<llvm::Constant*> c;
        for (int j = 0; j < w_; ++j) c.push_back(llvm::ConstantInt::get(i64_, static_cast<std::uint64_t>(j)));
        return llvm::ConstantVector::get(c);
    }
    Value* any(Value* mask) { return w_ == 1 ? mask : b_.CreateOrReduce(mask); }
    Value* count(Value* mask) {
        if (w_ == 1) return b_.CreateZExt(mask, i64_);
        Value* bits = b_.CreateBitCast(mask, b_.getIntNTy(static_cast<unsigned>(w_)));
        return b_.CreateZExt(b_.CreateUnaryIntrinsic(llvm::Intrinsic::ctpop, bits), i64_);
    }
    Value* mask_bits(Value* mask) {
        return b_.CreateZExt(b_.CreateBitCast(mask, b_.getIntNTy(static_cast<unsigned>(w_))), i32_);
    }
    // ---- floating point, rounded upward ----
    static constexpr int ru_sae = 2 | 8; // _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC
    Value* x86_round(llvm::Intrinsic::ID scalar, llvm::Intrinsic::ID packed, Value* x, Value* y) {
        if (w_ == 8) {
            Function* f = llvm::Intrinsic::getDeclaration(&m_, packed);
            return b_.CreateCall(f, {x, y, b_.getInt32(ru_sae)});
        }
        auto* v2 = llvm::FixedVectorType::get(dbl_, 2);
        Value* zero = llvm::ConstantAggregateZero::get(v2);
        Value* a = b_.CreateInsertElement(zero, x, b_.getInt64(0));
        Value* c = b_.CreateInsertElement(zero, y, b_.getInt64(0));
        Function* f = llvm::Intrinsic::getDeclaration(&m_, scalar);
        Value* r = b_.CreateCall(f, {a, c, zero, b_.getInt8(0xff), b_.getInt32(ru_sae)});
        return b_.CreateExtractElement(r, b_.getInt64(0));
    }
    Value* add(Value* x, Value* y) {
        using namespace llvm::Intrinsic;
        return avx512_ ? x86_round(x86_avx512_mask_add_sd_round, x86_avx512_add_pd_512, x, y)
                       : b_.CreateFAdd(x, y);
    }
    Value* sub(Value* x, Value* y) {
        using namespace llvm::Intrinsic;
        return avx512_ ? x86_round(x86_avx512_mask_sub_sd_round, x86_avx512_sub_pd_512, x, y)
                       : b_.CreateFSub(x, y);
    }
    Value* mul(Value* x, Value* y) {
        using namespace llvm::Intrinsic;
        return avx512_ ? x86_round(x86_avx512_mask_mul_sd_round, x86_avx512_mul_pd_512, x, y)
                       : b_.CreateFMul(x, y);
    }
    Value* div(Value* x, Value* y) {
        using namespace llvm::Intrinsic;
        return avx512_ ? x86_round(x86_avx512_mask_div_sd_round, x86_avx512_div_pd_512, x, y)
                       : b_.CreateFDiv(x, y);
    }
    Value* neg(Value* x) { return b_.CreateFNeg(x); }
    Value* add_down(Value* x, Value* y) { return neg(sub(neg(x), y)); }
    Value* sub_down(Value* x, Value* y) { return neg(add(neg(x), y)); }
    Value* mul_down(Value* x, Value* y) { return neg(mul(neg(x), y)); }
    Value* div_down(Value* x, Value* y) { return neg(div(neg(x), y)); }
    Value* rounding_intrinsic(llvm::Intrinsic::ID plain, llvm::Intrinsic::ID constrained, Value* x) {
        if (avx512_) return b_.CreateUnaryIntrinsic(plain, x);
        return b_.CreateConstrainedFPCall(llvm::Intrinsic::getDeclaration(&m_, constrained, {vt_}), {x});
    }
    Value* floor(Value* x) {
        return rounding_intrinsic(llvm::Intrinsic::floor, llvm::Intrinsic::experimental_constrained_floor, x);
    }
    Value* ceil(Value* x) {
        return rounding_intrinsic(llvm::Intrinsic::ceil, llvm::Intrinsic::experimental_constrained_ceil, x);
    }
    Value* fabs(Value* x) { return b_.CreateUnaryIntrinsic(llvm::Intrinsic::fabs, x); }
    // double(i) rounded upward, as the interpreter converts indices (exact below 2^53).
    Value* index_to_double(Value* i, bool exact) {
        if (!avx512_ || exact) return b_.CreateSIToFP(i, dbl_); // constrained (upward) or exact
        auto* v2 = llvm::FixedVectorType::get(dbl_, 2);
        Function* f = llvm::Intrinsic::getDeclaration(&m_, llvm::Intrinsic::x86_avx512_cvtsi2sd64);
        Value* r = b_.CreateCall(f, {llvm::ConstantAggregateZero::get(v2), i, b_.getInt32(ru_sae)});
        return b_.CreateExtractElement(r, b_.getInt64(0));
    }

    // Comparisons are exact in every rounding mode and raise no exception we look at, so they are
    // plain fcmp, which the optimiser may hoist, share and turn into min/max instructions. (In the
    // constrained form a constrained fcmp is an opaque call: it stays in loops and goes through the
    // flags register; that made the whole evaluator 2.4 times slower.)
    Value* cmp(llvm::CmpInst::Predicate p, Value* x, Value* y) {
        auto* cx = llvm::dyn_cast<llvm::Constant>(x);
        auto* cy = llvm::dyn_cast<llvm::Constant>(y);
        if (cx && cy) return llvm::ConstantFoldCompareInstruction(p, cx, cy);
        return b_.Insert(new llvm::FCmpInst(p, x, y));
    }
    Value* lt(Value* x, Value* y) { return cmp(llvm::CmpInst::FCMP_OLT, x, y); }
    Value* le(Value* x, Value* y) { return cmp(llvm::CmpInst::FCMP_OLE, x, y); }
    Value* gt(Value* x, Value* y) { return cmp(llvm::CmpInst::FCMP_OGT, x, y); }
    Value* ge(Value* x, Value* y) { return cmp(llvm::CmpInst::FCMP_OGE, x, y); }
    Value* eq(Value* x, Value* y) { return cmp(llvm::CmpInst::FCMP_OEQ, x, y); }
    Value* isnan(Value* x) { return cmp(llvm::CmpInst::FCMP_UNO, x, x); }
    Value* sel(Value* c, Value* x, Value* y) { return x == y ? x : b_.CreateSelect(c, x, y); }
    Value* lor(Value* x, Value* y) {
        if (!x) return y;
        if (!y) return x;
        return b_.CreateOr(x, y);
    }
    Value* land(Value* x, Value* y) { return b_.CreateAnd(x, y); }
    Value* lnot(Value* x) { return b_.CreateNot(x); }
    // std::min / std::max of libstdc++: (b < a) ? b : a and (a < b) ? b : a.
    Value* std_min(Value* x, Value* y) { return sel(lt(y, x), y, x); }
    Value* std_max(Value* x, Value* y) { return sel(lt(x, y), y, x); }
    // glibc's fmin / fmax: the first argument on ties (signed zeros), the other one for a NaN.
    Value* c_fmin(Value* x, Value* y) { return sel(le(x, y), x, sel(isnan(y), x, y)); }
    Value* c_fmax(Value* x, Value* y) { return sel(ge(x, y), x, sel(isnan(y), x, y)); }

    // ---- intervals ----
    Value* empty_of(const SlotState& s) {
        if (!s.f.maybe_empty) return nullptr;
        if (s.known) return i1(s.k.is_empty());
        return cmp(llvm::CmpInst::FCMP_UGT, s.v.lo, s.v.hi); // !(lo <= hi)
    }
    IV empty() { return {cst(inf), cst(-inf)}; }
    IV guard(Value* is_empty, IV r, IV if_empty) {
        if (!is_empty) return r;
        return {sel(is_empty, if_empty.lo, r.lo), sel(is_empty, if_empty.hi, r.hi)};
    }
    IV widen_nan(Value* lo, Value* hi) {
        return {sel(isnan(lo), cst(-inf), lo), sel(isnan(hi), cst(inf), hi)};
    }
    Value* is_zero(const SlotState& s, bool upper) {
        if (s.known) return i1((upper ? s.k.hi : s.k.lo) == 0);
        if (upper ? s.f.hi_nonzero : s.f.lo_nonzero) return i1(false);
        return eq(upper ? s.v.hi : s.v.lo, cst(0.0));
    }
    static SlotState result(IV v, bool maybe_empty) {
        SlotState s;
        s.v = v;
        s.f.maybe_empty = maybe_empty;
        return s;
    }
    SlotState thin(Value* x) {
        SlotState s;
        s.v = {x, x};
        s.f.maybe_empty = false;
        return s;
    }
    SlotState thin_known(double x) {
        SlotState s;
        s.v = {cst(x), cst(x)};
        s.known = true;
        s.k = Interval(x);
        s.f = facts_of(&s.k, 1);
        return s;
    }
    Value* width(const SlotState& s) {
        Value* w = sub(s.v.hi, s.v.lo);
        if (Value* e = empty_of(s)) w = sel(e, cst(0.0), w);
        return w;
    }
    Value* magnitude(const SlotState& s) {
        Value* m = std_max(fabs(s.v.lo), fabs(s.v.hi));
        if (Value* e = empty_of(s)) m = sel(e, cst(0.0), m);
        return m;
    }

    // ---- calls into the numeric core ----
    // Scalar code calls the helpers of helpers.hpp directly; vector code stores its lanes and calls
    // frac_jit_vop, which applies ir::apply_interval to the lanes of `mask`.
    IV call_scalar(const char* helper, std::vector<Value*> args) {
        std::vector<Type*> types;
        for (Value* v : args) types.push_back(v->getType());
        auto callee = m_.getOrInsertFunction(helper, llvm::FunctionType::get(pair_, types, false));
        llvm::cast<Function>(callee.getCallee())->setDoesNotThrow();
        Value* r = b_.CreateCall(callee, args);
        return {b_.CreateExtractValue(r, 0), b_.CreateExtractValue(r, 1)};
    }
    IV call_vector(Op op, std::int64_t imm, const std::vector<IV>& args, Value* mask) {
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
        b_.CreateCall(callee, {b_.getInt32(static_cast<std::uint32_t>(op)),
                               b_.getInt64(static_cast<std::uint64_t>(imm)), scratch_in_, scratch_out_,
                               mask_bits(mask), b_.getInt32(static_cast<std::uint32_t>(w_))});
        return {b_.CreateLoad(vt_, scratch_out_),
                b_.CreateLoad(
                    vt_, b_.CreateConstInBoundsGEP1_64(dbl_, scratch_out_, static_cast<std::uint64_t>(w_)))};
    }
    SlotState call_core(Op op, std::int64_t imm, const std::vector<const SlotState*>& args,
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
        const char* name = nullptr;
        switch (op) {
        case Op::Div: name = "frac_jit_div"; break;
        case Op::Pow: name = "frac_jit_pow"; break;
        case Op::Atan2: name = "frac_jit_atan2"; break;
        case Op::Sqrt: name = "frac_jit_sqrt"; break;
        case Op::Sin: name = "frac_jit_sin"; break;
        case Op::Cos: name = "frac_jit_cos"; break;
        case Op::Tan: name = "frac_jit_tan"; break;
        case Op::Exp: name = "frac_jit_exp"; break;
        case Op::Log: name = "frac_jit_log"; break;
        case Op::PowI:
            name = "frac_jit_powi";
            flat.push_back(b_.getInt64(static_cast<std::uint64_t>(imm)));
            break;
        default: throw std::logic_error(std::string("jit: no helper for ") + ir::op_name(op));
        }
        return result(call_scalar(name, flat), maybe_empty);
    }

    // ---- interval operations: numeric/interval.cpp, step by step ----
    SlotState op_add(const SlotState& a, const SlotState& b) {
        Value* e = lor(empty_of(a), empty_of(b));
        return result(guard(e, widen_nan(add_down(a.v.lo, b.v.lo), add(a.v.hi, b.v.hi)), empty()),
                      a.f.maybe_empty || b.f.maybe_empty);
    }
    SlotState op_sub(const SlotState& a, const SlotState& b) {
        Value* e = lor(empty_of(a), empty_of(b));
        return result(guard(e, widen_nan(sub_down(a.v.lo, b.v.hi), sub(a.v.hi, b.v.lo)), empty()),
                      a.f.maybe_empty || b.f.maybe_empty);
    }
    SlotState op_mul(const SlotState& a, const SlotState& b) {
        Value* e = lor(empty_of(a), empty_of(b));
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
    IV div_nonzero(const SlotState& a, const SlotState& b, Value* pos) {
        Value* alo_nonneg = ge(a.v.lo, cst(0.0));
        Value* ahi_nonpos = le(a.v.hi, cst(0.0));
        Value* lo_num = sel(pos, a.v.lo, a.v.hi);
        Value* lo_den = sel(pos, sel(alo_nonneg, b.v.hi, b.v.lo),
                            sel(land(lnot(alo_nonneg), ahi_nonpos), b.v.lo, b.v.hi));
        Value* hi_num = sel(pos, a.v.hi, a.v.lo);
        Value* hi_den = sel(pos, sel(alo_nonneg, b.v.lo, sel(ahi_nonpos, b.v.hi, b.v.lo)),
                            sel(alo_nonneg, b.v.lo, b.v.hi));
        return widen_nan(div_down(lo_num, lo_den), div(hi_num, hi_den));
    }
    SlotState op_div(const SlotState& a, const SlotState& b) {
        // A divisor of statically known sign: the branch the interpreter takes.
        if (b.f.lo_positive || b.f.hi_negative)
            return result(guard(empty_of(a), div_nonzero(a, b, i1(b.f.lo_positive)), empty()),
                          a.f.maybe_empty);
        Value* pos = gt(b.v.lo, cst(0.0));
        Value* fast = b_.CreateOr(pos, lt(b.v.hi, cst(0.0)));
        if (Value* e = lor(empty_of(a), empty_of(b))) fast = land(fast, lnot(e));
        const IV rf = div_nonzero(a, b, pos); // garbage in the other lanes, replaced below
        Value* slow = land(ctx_mask_, lnot(fast));
        BasicBlock* pre = b_.GetInsertBlock();
        BasicBlock* slow_bb = BasicBlock::Create(ctx_, "div.slow", fn_);
        BasicBlock* join = BasicBlock::Create(ctx_, "div.join", fn_);
        b_.CreateCondBr(any(slow), slow_bb, join);
        b_.SetInsertPoint(slow_bb);
        IV rs;
        if (w_ == 1) {
            rs = call_scalar("frac_jit_div", {a.v.lo, a.v.hi, b.v.lo, b.v.hi});
        } else {
            const IV core = call_vector(Op::Div, 0, {a.v, b.v}, slow);
            rs = {sel(slow, core.lo, rf.lo), sel(slow, core.hi, rf.hi)};
        }
        BasicBlock* slow_end = b_.GetInsertBlock();
        b_.CreateBr(join);
        b_.SetInsertPoint(join);
        llvm::PHINode* lo = b_.CreatePHI(vt_, 2);
        llvm::PHINode* hi = b_.CreatePHI(vt_, 2);
        lo->addIncoming(rf.lo, pre);
        lo->addIncoming(rs.lo, slow_end);
        hi->addIncoming(rf.hi, pre);
        hi->addIncoming(rs.hi, slow_end);
        return result({lo, hi}, true);
    }
    SlotState op_neg(const SlotState& a) { return result({neg(a.v.hi), neg(a.v.lo)}, a.f.maybe_empty); }
    IV abs_nonempty(IV a) {
        Value* lo_nonneg = ge(a.lo, cst(0.0));
        Value* hi_nonpos = le(a.hi, cst(0.0));
        Value* nlo = neg(a.lo);
        Value* lo = sel(lo_nonneg, a.lo, sel(hi_nonpos, neg(a.hi), cst(0.0)));
        Value* hi = sel(lo_nonneg, a.hi, sel(hi_nonpos, nlo, std_max(nlo, a.hi)));
        return {lo, hi};
    }
    SlotState op_abs(const SlotState& a) {
        return result(guard(empty_of(a), abs_nonempty(a.v), a.v), a.f.maybe_empty);
    }
    Value* pow_up(Value* x, std::uint64_t n) {
        Value* r = cst(1.0);
        for (Value* p = x;; p = mul(p, p)) {
            if (n & 1) r = mul(r, p);
            if ((n >>= 1) == 0) return r;
        }
    }
    Value* pow_down(Value* x, std::uint64_t n) {
        Value* r = cst(1.0);
        for (Value* p = x;; p = mul_down(p, p)) {
            if (n & 1) r = mul_down(r, p);
            if ((n >>= 1) == 0) return r;
        }
    }
    IV pow_positive(IV a, std::uint64_t n) {
        if (n % 2 == 0) {
            const IV m = abs_nonempty(a);
            return {pow_down(m.lo, n), pow_up(m.hi, n)};
        }
        Value* lo = sel(ge(a.lo, cst(0.0)), pow_down(a.lo, n), neg(pow_up(neg(a.lo), n)));
        Value* hi = sel(ge(a.hi, cst(0.0)), pow_up(a.hi, n), neg(pow_down(neg(a.hi), n)));
        return {lo, hi};
    }
    SlotState op_sqr(const SlotState& a) {
        return result(guard(empty_of(a), pow_positive(a.v, 2), a.v), a.f.maybe_empty);
    }
    SlotState op_powi(const SlotState& a, std::int64_t n) {
        if (n == 0) return result(guard(empty_of(a), {cst(1.0), cst(1.0)}, a.v), a.f.maybe_empty);
        // Negative powers divide; huge ones would unroll for nothing: the core does both.
        if (n < 0 || n > 1024) return call_core(Op::PowI, n, {&a}, true);
        return result(guard(empty_of(a), pow_positive(a.v, static_cast<std::uint64_t>(n)), a.v),
                      a.f.maybe_empty);
    }
    SlotState op_minmax(const SlotState& a, const SlotState& b, bool is_min) {
        Value* e = lor(empty_of(a), empty_of(b));
        const IV r = is_min ? IV{std_min(a.v.lo, b.v.lo), std_min(a.v.hi, b.v.hi)}
                            : IV{std_max(a.v.lo, b.v.lo), std_max(a.v.hi, b.v.hi)};
        return result(guard(e, r, empty()), a.f.maybe_empty || b.f.maybe_empty);
    }
    SlotState op_round(const SlotState& a, bool up) {
        const IV r = up ? IV{ceil(a.v.lo), ceil(a.v.hi)} : IV{floor(a.v.lo), floor(a.v.hi)};
        return result(guard(empty_of(a), r, a.v), a.f.maybe_empty);
    }
    Value* is_finite(Value* x) { return lt(fabs(x), cst(inf)); }
    SlotState op_mod1(const SlotState& a) {
        Value* f = floor(a.v.lo);
        Value* whole = b_.CreateOr(lnot(land(is_finite(a.v.lo), is_finite(a.v.hi))),
                                   cmp(llvm::CmpInst::FCMP_UNE, floor(a.v.hi), f));
        const IV r{sel(whole, cst(0.0), sub_down(a.v.lo, f)), sel(whole, cst(1.0), sub(a.v.hi, f))};
        return result(guard(empty_of(a), r, a.v), a.f.maybe_empty);
    }
    SlotState op_dz(const SlotState& a) {
        Value* lo = a.v.lo;
        Value* hi = a.v.hi;
        Value* whole = lnot(lt(sub(hi, lo), cst(1.0))); // !(hi - lo < 1): a whole period
        Value* fl = floor(lo);
        Value* cl = ceil(lo);
        Value* fh = floor(hi);
        Value* ch = ceil(hi);
        // dz_down(x) = min(sub_down(x, floor x), sub_down(ceil x, x)); dz_up(x) = min(x - floor x, ceil x -
        // x)
        Value* rlo =
            std_min(std_min(sub_down(lo, fl), sub_down(cl, lo)), std_min(sub_down(hi, fh), sub_down(ch, hi)));
        Value* rhi = std_max(std_min(sub(lo, fl), sub(cl, lo)), std_min(sub(hi, fh), sub(ch, hi)));
        rlo = sel(le(cl, hi), cst(0.0), rlo);
        Value* half = add(fl, cst(0.5));
        half = sel(lt(half, lo), add(half, cst(1.0)), half);
        rhi = sel(le(half, hi), cst(0.5), rhi);
        const IV r{sel(whole, cst(0.0), rlo), sel(whole, cst(0.5), rhi)};
        return result(guard(empty_of(a), r, a.v), a.f.maybe_empty);
    }
    SlotState op_not(const SlotState& a) {
        const IV r{sub(cst(1.0), a.v.hi), sub(cst(1.0), a.v.lo)};
        return result(guard(empty_of(a), r, empty()), a.f.maybe_empty);
    }
    SlotState op_andor(const SlotState& a, const SlotState& b, bool is_and) {
        Value* e = lor(empty_of(a), empty_of(b));
        const IV r = is_and ? IV{c_fmin(a.v.lo, b.v.lo), c_fmin(a.v.hi, b.v.hi)}
                            : IV{c_fmax(a.v.lo, b.v.lo), c_fmax(a.v.hi, b.v.hi)};
        return result(guard(e, r, empty()), a.f.maybe_empty || b.f.maybe_empty);
    }
    IV truth(Value* t, Value* f) {
        return {sel(t, cst(1.0), cst(0.0)), sel(b_.CreateOr(t, lnot(f)), cst(1.0), cst(0.0))};
    }
    SlotState op_compare(Op op, const SlotState& a, const SlotState& b) {
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
    SlotState op_select(const SlotState& c, const SlotState& x, const SlotState& y) {
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

    SlotState emit_op(const Instr& ins) {
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
        case Op::Pow:
        case Op::Sqrt:
        case Op::Log: return call_core(ins.op, 0, {&in(0), &in(ir::arity(ins.op) > 1 ? 1 : 0)}, true);
        case Op::Sin:
        case Op::Cos:
        case Op::Tan:
        case Op::Exp: return call_core(ins.op, 0, {&in(0)}, in(0).f.maybe_empty);
        case Op::Atan2:
            return call_core(ins.op, 0, {&in(0), &in(1)}, in(0).f.maybe_empty || in(1).f.maybe_empty);
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
    // Entry idx (a scalar, the same for every lane) of a table of doubles / of intervals.
    Value* load_scalar(llvm::GlobalVariable* g, Value* idx) {
        return splat(b_.CreateLoad(dbl_, b_.CreateInBoundsGEP(dbl_, g, idx)));
    }
    IV load_pair(llvm::GlobalVariable* g, Value* idx) {
        Value* i2 = b_.CreateShl(idx, 1);
        return {load_scalar(g, i2), load_scalar(g, b_.CreateOr(i2, b_.getInt64(1)))};
    }
    // Entry idx[lane] of a table of intervals, lane by lane.
    IV gather_pair(llvm::GlobalVariable* g, Value* idx) {
        if (w_ == 1) return load_pair(g, idx);
        Value* lo = llvm::PoisonValue::get(vt_);
        Value* hi = llvm::PoisonValue::get(vt_);
        for (int l = 0; l < w_; ++l) {
            Value* i2 =
                b_.CreateShl(b_.CreateExtractElement(idx, b_.getInt64(static_cast<std::uint64_t>(l))), 1);
            Value* x = b_.CreateLoad(dbl_, b_.CreateInBoundsGEP(dbl_, g, i2));
            Value* y = b_.CreateLoad(dbl_, b_.CreateInBoundsGEP(dbl_, g, b_.CreateOr(i2, b_.getInt64(1))));
            lo = b_.CreateInsertElement(lo, x, b_.getInt64(static_cast<std::uint64_t>(l)));
            hi = b_.CreateInsertElement(hi, y, b_.getInt64(static_cast<std::uint64_t>(l)));
        }
        return {lo, hi};
    }
    SlotState from_table(IV v, const Facts& f) {
        SlotState s;
        s.v = v;
        s.f = f;
        return s;
    }

    SlotState combine(Op kind, const SlotState& acc, const SlotState& term) {
        switch (kind) {
        case Op::SeriesSum: return op_add(acc, term);
        case Op::SeriesMin: return op_minmax(acc, term, true);
        case Op::SeriesMax: return op_minmax(acc, term, false);
        default: break;
        }
        throw std::logic_error("jit: not a series");
    }

    // ir::series_tail(kind, A, B, gamma, n) for box-dependent A, B; n a scalar index or one per lane.
    SlotState tail_core(const TapeSeries& s, const SlotState& a, const SlotState& bc, bool has_b, Value* n,
                        Value* mask) {
        if (w_ == 1) {
            return result(
                call_scalar("frac_jit_series_tail", {b_.getInt32(static_cast<std::uint32_t>(s.kind)), a.v.lo,
                                                     a.v.hi, bc.v.lo, bc.v.hi, b_.getInt32(has_b ? 1 : 0),
                                                     llvm::ConstantFP::get(dbl_, s.data.gamma.lo),
                                                     llvm::ConstantFP::get(dbl_, s.data.gamma.hi), n}),
                true);
        }
        b_.CreateStore(a.v.lo, b_.CreateConstInBoundsGEP1_64(dbl_, scratch_in_, 0));
        b_.CreateStore(a.v.hi,
                       b_.CreateConstInBoundsGEP1_64(dbl_, scratch_in_, static_cast<std::uint64_t>(w_)));
        b_.CreateStore(bc.v.lo,
                       b_.CreateConstInBoundsGEP1_64(dbl_, scratch_in_, 2 * static_cast<std::uint64_t>(w_)));
        b_.CreateStore(bc.v.hi,
                       b_.CreateConstInBoundsGEP1_64(dbl_, scratch_in_, 3 * static_cast<std::uint64_t>(w_)));
        b_.CreateStore(n->getType()->isVectorTy() ? n : b_.CreateVectorSplat(static_cast<unsigned>(w_), n),
                       scratch_n_);
        auto callee = m_.getOrInsertFunction(
            "frac_jit_vtail",
            llvm::FunctionType::get(Type::getVoidTy(ctx_),
                                    {i32_, ptr_, ptr_, ptr_, i32_, dbl_, dbl_, i32_, i32_}, false));
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

    void store_state(const std::vector<IV>& state) {
        const auto w = static_cast<std::uint64_t>(w_);
        for (std::size_t c = 0; c < state.size(); ++c) {
            b_.CreateStore(state[c].lo, b_.CreateConstInBoundsGEP1_64(dbl_, esc_in_, 2 * c * w));
            b_.CreateStore(state[c].hi, b_.CreateConstInBoundsGEP1_64(dbl_, esc_in_, (2 * c + 1) * w));
        }
    }
    std::vector<Value*> escape_params(const ir::OrbitEscape& e) {
        auto d = [&](double x) { return llvm::ConstantFP::get(dbl_, x); };
        return {d(e.radius),    d(e.slope),     d(e.offset),    d(e.scale0.lo),    d(e.scale0.hi),
                d(e.growth.lo), d(e.growth.hi), d(e.lipschitz), d(e.map_lipschitz)};
    }
    Value* mask_arg(Value* mask) {
        return w_ == 1 ? b_.getInt32(1) : mask_bits(mask);
    }

    // ir::lipschitz_centre of the initial point, lane by lane: the centres (replacing `init`) and h.
    Value* centre_orbit(std::vector<IV>& init, Value* mask) {
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
    SlotState lipschitz_finish(const TapeSeries& s, const SlotState& acc, const SlotState& tail, Value* bound,
                               Value* n, Value* mask) {
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
        std::vector<Value*> args = {b_.getInt32(static_cast<std::uint32_t>(s.kind)), esc_out_, esc_in_,
                                    esc_n_, esc_h_};
        for (Value* p : escape_params(s.data.escape)) args.push_back(p);
        args.push_back(mask_arg(mask));
        args.push_back(b_.getInt32(static_cast<std::uint32_t>(w_)));
        b_.CreateCall(callee, args);
        return result({b_.CreateLoad(vt_, esc_out_),
                       b_.CreateLoad(vt_, b_.CreateConstInBoundsGEP1_64(dbl_, esc_out_, w))},
                      true);
    }

    // ir::escape_bound of the orbit point `state` (index n, scalar) for the lanes in `mask`, and
    // ir::escape_bound_around with each lane's radius h (the same without a Lipschitz bound).
    std::pair<Value*, Value*> escape_bound(const TapeSeries& s, const std::vector<IV>& state, Value* n,
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
        std::vector<Value*> args = {b_.getInt32(static_cast<std::uint32_t>(s.kind)), esc_in_, esc_n_,
                                    esc_out_, b_.getInt32(static_cast<std::uint32_t>(state.size()))};
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
    SlotState escape_tighten(Op kind, const SlotState& tail, Value* bound) {
        if (kind == Op::SeriesMax) {
            Value* hi = sel(lt(bound, tail.v.hi), bound, tail.v.hi);
            return result({sel(lt(hi, tail.v.lo), hi, tail.v.lo), hi}, true);
        }
        Value* lo = sel(gt(bound, tail.v.lo), bound, tail.v.lo);
        return result({lo, sel(gt(lo, tail.v.hi), lo, tail.v.hi)}, true);
    }

    SlotState emit_series(const Instr& ins) {
        SeriesLoop L = series_loop(ins);
        const TapeSeries& s = L.s;
        const SeriesTables& st = L.st;
        const bool infinite = L.infinite;
        const bool has_b = L.has_b;
        const SlotState a = infinite ? vals_[s.tail_a] : thin_known(0.0);
        const SlotState bc = has_b ? vals_[s.tail_b] : thin_known(0.0);
        Value* outer_mask = ctx_mask_;

        // A proven Lipschitz bound: the orbit runs from the centre of the initial box (ir::lipschitz_centre).
        std::vector<IV> centre;
        for (Slot c : s.init_slots) centre.push_back(vals_[c].v);
        const bool lipschitz = infinite && s.data.escape.present && s.data.escape.lipschitz > 0;
        if (lipschitz) centre_orbit(centre, outer_mask);
        std::vector<SlotState> init;
        for (const IV& c : centre) init.push_back(result(c, false));
        open_series(L, init);
        Value* i = L.i;
        BasicBlock* pre = L.pre;
        llvm::PHINode* acc_lo = b_.CreatePHI(vt_, 2, "acc.lo");
        llvm::PHINode* acc_hi = b_.CreatePHI(vt_, 2, "acc.hi");
        llvm::PHINode* active = b_.CreatePHI(mt_, 2, "active");
        llvm::PHINode* stop_at = b_.CreatePHI(vi64_, 2, "stop.at"); // the index after which a lane stopped
        acc_lo->addIncoming(cst(0.0), pre);
        acc_hi->addIncoming(cst(0.0), pre);
        active->addIncoming(outer_mask, pre);
        stop_at->addIncoming(splat(L.start_v), pre);
        const bool escape = infinite && s.data.escape.present;
        // Escape certificate: each lane's bound (around the centre) where it stopped, and the previous
        // term's bound of the orbit box (for the stalling rule).
        llvm::PHINode* esc_frozen = nullptr;
        llvm::PHINode* esc_prev = nullptr;
        if (escape) {
            esc_frozen = b_.CreatePHI(vt_, 2, "esc.frozen");
            esc_frozen->addIncoming(cst(s.kind == Op::SeriesMax ? inf : -inf), pre);
            esc_prev = b_.CreatePHI(vt_, 2, "esc.prev");
            esc_prev->addIncoming(cst(s.kind == Op::SeriesMax ? inf : -inf), pre);
        }
        ctx_mask_ = active;
        series_body(L);
        Value* idx = L.idx;

        std::vector<IV> next_state;
        for (const SlotState& c : L.next_state) next_state.push_back(c.v);
        const SlotState term = L.term;
        // Escape certificate: the bound of the terms after i from the next orbit point.
        Value* esc_now = nullptr; // the bound from the orbit box
        Value* esc_far = nullptr; // the same for every orbit within the Lipschitz spread of it
        if (escape)
            std::tie(esc_now, esc_far) = escape_bound(s, next_state, b_.CreateAdd(i, b_.getInt64(1)), active);
        const SlotState acc = result({acc_lo, acc_hi}, term.f.maybe_empty);
        const SlotState comb = combine(s.kind, acc, term);
        Value* first = splat(L.first);
        // Lanes that stopped keep their partial result.
        SlotState nacc =
            result({sel(first, term.v.lo, comb.v.lo), sel(first, term.v.hi, comb.v.hi)}, term.f.maybe_empty);
        if (w_ > 1) nacc.v = {sel(active, nacc.v.lo, acc_lo), sel(active, nacc.v.hi, acc_hi)};
        bump(terms_, count(active));
        Value* is_last = L.is_last;
        // At the last index every active lane stops, capped by the term limit (infinite series).
        Value* splat_i = splat(i);
        Value* last_at = w_ == 1 ? i : b_.CreateSelect(active, splat_i, stop_at);
        Value* esc_last = escape ? (w_ == 1 ? esc_far : sel(active, esc_far, esc_frozen)) : nullptr;
        Value* esc_next = esc_frozen;
        BasicBlock* from_last = b_.GetInsertBlock();
        Value* still = active; // lanes that go on to the next term
        Value* stop_at_next = stop_at;
        BasicBlock* decided = nullptr; // the block that leaves when every lane stopped by a rule
        if (!infinite) {
            b_.CreateCondBr(is_last, L.exit, L.latch);
        } else {
            BasicBlock* check = BasicBlock::Create(ctx_, "series.check", fn_);
            b_.CreateCondBr(is_last, L.exit, check);
            b_.SetInsertPoint(check);
            // 1. The term told little more than its static bound (ir::term_resolution).
            Value* stop1 = i1(false);
            if (o_.adaptive_terms) {
                Value* threshold;
                if (st.const_tail) {
                    threshold = load_scalar(table(&st.threshold, st.threshold, "threshold"), idx);
                } else {
                    // series_term_bound(a, b, has_b, gamma_i, i) = (a [+ b * i]) * gamma_i
                    const SlotState gi = from_table(load_pair(table(&st.gamma_n, st.gamma_n, "gamma"), idx),
                                                    facts_of(st.gamma_n.data(), st.gamma_n.size()));
                    SlotState coeff = a;
                    if (has_b) coeff = op_add(a, op_mul(bc, vals_[s.index_slot]));
                    threshold = mul(cst(ir::term_resolution), width(op_mul(coeff, gi)));
                }
                stop1 = land(active, ge(width(term), threshold));
            }
            // 2. The tail is below the resolution of the partial result; 3. a one-sided tail that
            // cannot move the bound it knows while this term did not improve the other one. Both
            // look at the tail, which (for box-dependent A, B) only the lanes still going compute.
            Value* rest = land(active, lnot(stop1));
            BasicBlock* check1_end = b_.GetInsertBlock();
            BasicBlock* check2 = BasicBlock::Create(ctx_, "series.tail", fn_);
            BasicBlock* decide = BasicBlock::Create(ctx_, "series.decide", fn_);
            b_.CreateCondBr(any(rest), check2, decide);
            b_.SetInsertPoint(check2);
            SlotState tail;
            Value* tail_width;
            if (st.const_tail) {
                tail = from_table(load_pair(table(&st.tail, st.tail, "tail"), idx),
                                  facts_of(st.tail.data(), st.tail.size()));
                tail_width = load_scalar(table(&st.tail_width, st.tail_width, "tail_width"), idx);
            } else {
                tail = tail_core(s, a, bc, has_b, i, rest);
                tail_width = width(tail);
            }
            if (escape) {
                tail = escape_tighten(s.kind, tail, esc_now);
                tail_width = width(tail);
            }
            Value* small = b_.CreateOr(le(tail_width, mul(cst(ir::box_stop_ratio), magnitude(nacc))),
                                       eq(tail_width, cst(0.0)));
            if (s.kind == Op::SeriesMin) {
                Value* one_sided = eq(fabs(tail.v.hi), cst(inf));
                Value* no_gain = land(ge(tail.v.lo, nacc.v.lo), ge(term.v.hi, nacc.v.hi));
                small = b_.CreateOr(small, land(one_sided, no_gain));
            } else if (s.kind == Op::SeriesMax) {
                Value* one_sided = eq(fabs(tail.v.lo), cst(inf));
                Value* no_gain = land(le(tail.v.hi, nacc.v.hi), le(term.v.lo, nacc.v.lo));
                small = b_.CreateOr(small, land(one_sided, no_gain));
            }
            if (escape) {
                // ir::escape_stalls
                Value* slack = mul(cst(ir::escape_stall_slack), fabs(esc_prev));
                Value* stalls = s.kind == Op::SeriesMax
                                    ? land(lt(esc_now, cst(inf)),
                                           lor(le(esc_now, nacc.v.hi), gt(esc_now, add(esc_prev, slack))))
                                    : land(gt(esc_now, cst(-inf)),
                                           lor(ge(esc_now, nacc.v.lo), lt(esc_now, sub(esc_prev, slack))));
                small = b_.CreateOr(small, stalls);
            }
            Value* stop2 = b_.CreateOr(stop1, land(rest, small));
            BasicBlock* check2_end = b_.GetInsertBlock();
            b_.CreateBr(decide);
            b_.SetInsertPoint(decide);
            llvm::PHINode* stop = b_.CreatePHI(mt_, 2, "stop");
            stop->addIncoming(stop1, check1_end);
            stop->addIncoming(stop2, check2_end);
            still = land(active, lnot(stop));
            stop_at_next = b_.CreateSelect(stop, splat_i, stop_at);
            if (escape) esc_next = sel(stop, esc_far, esc_frozen);
            decided = b_.GetInsertBlock();
            b_.CreateCondBr(any(still), L.latch, L.exit);
        }
        acc_lo->addIncoming(nacc.v.lo, L.latch);
        acc_hi->addIncoming(nacc.v.hi, L.latch);
        active->addIncoming(still, L.latch);
        stop_at->addIncoming(stop_at_next, L.latch);
        if (escape) {
            esc_frozen->addIncoming(esc_next, L.latch);
            esc_prev->addIncoming(esc_now, L.latch);
        }
        close_series(L);

        // Exit: at the last index (the active lanes are capped) or when every lane stopped by a rule.
        ctx_mask_ = outer_mask;
        if (!infinite) return nacc;
        if (!infinite) return nacc;
        llvm::PHINode* capped_lanes = b_.CreatePHI(mt_, 2, "capped.lanes");
        llvm::PHINode* final_at = b_.CreatePHI(vi64_, 2, "final.at");
        capped_lanes->addIncoming(active, from_last);
        final_at->addIncoming(last_at, from_last);
        capped_lanes->addIncoming(i1(false), decided);
        final_at->addIncoming(stop_at_next, decided);
        llvm::PHINode* esc_final = nullptr;
        if (escape) {
            esc_final = b_.CreatePHI(vt_, 2, "esc.final");
            esc_final->addIncoming(esc_last, from_last);
            esc_final->addIncoming(esc_next, decided);
        }
        bump(capped_, count(capped_lanes));
        Value* final_idx = b_.CreateSub(final_at, splat(L.start_v));
        SlotState tail;
        if (st.const_tail)
            tail = from_table(gather_pair(table(&st.tail, st.tail, "tail"), final_idx),
                              facts_of(st.tail.data(), st.tail.size()));
        else
            tail = tail_core(s, a, bc, has_b, final_at, outer_mask);
        if (lipschitz) return lipschitz_finish(s, nacc, tail, esc_final, final_at, outer_mask);
        if (escape) tail = escape_tighten(s.kind, tail, esc_final);
        return combine(s.kind, nacc, tail);
    }

    bool avx512_;
    Type *vt_, *mt_, *vi64_;
    Value* scratch_in_ = nullptr;
    Value* scratch_n_ = nullptr;
    Value* scratch_out_ = nullptr;
    Value* esc_in_ = nullptr; // escape helper scratch (series with an escape certificate only)
    Value* esc_n_ = nullptr;
    Value* esc_out_ = nullptr;
    Value* esc_h_ = nullptr;
    Value* sink_ = nullptr;
    Value* first_box_ = nullptr; // the iteration's first box
    Value* ctx_mask_ = nullptr;  // lanes the current code computes for
};

} // namespace

std::string generate_box_function(const Tape& tape, const ir::EvalOptions& options, const Tables& tables,
                                  llvm::Module& module, const std::string& name, Rounding rounding,
                                  int lanes) {
    return BoxGen(tape, options, tables, module, name, rounding, lanes).run("_box", "boxes");
}

} // namespace frac::jit
