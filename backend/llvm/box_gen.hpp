// BoxGen, the interval evaluator of a tape: W boxes at a time (one per vector lane; W = 1 is plain scalar
// code). Private to backend/llvm; defined in box_codegen.cpp (the batch function and the series loops),
// box_ops.cpp (the interval operations) and box_calls.cpp (calls into the numeric core, tables, tails and
// escape bounds).
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
#pragma once

#include "backend/llvm/codegen.hpp"
#include "backend/llvm/skeleton.hpp"
#include "ir/graph.hpp"

#include <llvm/IR/ConstantFold.h>
#include <llvm/IR/Constants.h>
#include <llvm/IR/DerivedTypes.h>
#include <llvm/IR/FPEnv.h>
#include <llvm/IR/Function.h>
#include <llvm/IR/IRBuilder.h>
#include <llvm/IR/Intrinsics.h>
#include <llvm/IR/IntrinsicsX86.h>
#include <llvm/IR/Module.h>

#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace frac::jit::box {

using ir::Instr;
using ir::Op;
using ir::Slot;
using ir::Tape;
using ir::TapeSeries;
using llvm::BasicBlock;
using llvm::Function;
using llvm::Type;
using llvm::Value;

inline constexpr double inf = std::numeric_limits<double>::infinity();

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
        : Skeleton(t, o, tab, m, std::move(name), lanes), avx512_(rounding == Rounding::avx512),
          fast_kernels_(!exact_calls_requested()) {
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

    // FRAC_JIT_EXACT_CALLS=1 in the environment: sqrt, sin, cos, exp, tan, log, pow and atan2 call the
    // numeric core (correctly rounded, bit for bit the interpreter's) instead of the inline kernels; for
    // benchmarks and tests.
    static bool exact_calls_requested() {
        const char* v = std::getenv("FRAC_JIT_EXACT_CALLS");
        return v && std::string(v) == "1";
    }

private:
    // ---- the skeleton's hooks ----
    void prepare(Function* f);
    void allocate();
    // One iteration per group of W boxes; lanes past the end repeat the last box and are not stored.
    // The boxes come from `in`, or, when the fifth parameter (CellArgs) is not null, from the cells'
    // coordinates and the grid's tables; the results go to `out` as intervals, or as the cells'
    // verdicts (ir::classify).
    void load_inputs(Value* in, Value* n, Value* k);
    void store_result(Value* out, Value* n, Value*);
    // Input j of the iteration's boxes, from `in` / from the cells.
    IV box_input(Value* in, std::size_t j);
    IV cell_input(std::size_t j);
    // ir::classify of each lane's enclosure: ir::CellVerdict as a byte.
    Value* verdict(const IV& r);
    SlotState constant(const ir::TapeConst& c);
    SlotState indexed(const IndexTable& it, Value* idx);
    SlotState operation(const Instr& ins);
    SlotState series(const Instr& ins);
    SlotState carry(const SlotState& init, BasicBlock* pre, Slot slot);
    void carry_next(const SlotState& phis, const SlotState& next, BasicBlock* latch);
    SlotState index_value(const SeriesLoop& L);
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
    static constexpr int rd_sae = 1 | 8; // _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC
    Value* x86_round(llvm::Intrinsic::ID scalar, llvm::Intrinsic::ID packed, Value* x, Value* y,
                     int rounding = ru_sae) {
        const auto mode = static_cast<std::uint32_t>(rounding);
        if (w_ == 8) {
            Function* f = llvm::Intrinsic::getDeclaration(&m_, packed);
            return b_.CreateCall(f, {x, y, b_.getInt32(mode)});
        }
        auto* v2 = llvm::FixedVectorType::get(dbl_, 2);
        Value* zero = llvm::ConstantAggregateZero::get(v2);
        Value* a = b_.CreateInsertElement(zero, x, b_.getInt64(0));
        Value* c = b_.CreateInsertElement(zero, y, b_.getInt64(0));
        Function* f = llvm::Intrinsic::getDeclaration(&m_, scalar);
        Value* r = b_.CreateCall(f, {a, c, zero, b_.getInt8(0xff), b_.getInt32(mode)});
        return b_.CreateExtractElement(r, b_.getInt64(0));
    }
    // The AVX-512 instruction of an operation with embedded rounding (ru_sae / rd_sae).
    enum class Arith { add, sub, mul, div };
    Value* x86_arith(Arith op, Value* x, Value* y, int rounding) {
        using namespace llvm::Intrinsic;
        static constexpr llvm::Intrinsic::ID scalar[] = {
            x86_avx512_mask_add_sd_round, x86_avx512_mask_sub_sd_round, x86_avx512_mask_mul_sd_round,
            x86_avx512_mask_div_sd_round};
        static constexpr llvm::Intrinsic::ID packed[] = {x86_avx512_add_pd_512, x86_avx512_sub_pd_512,
                                                         x86_avx512_mul_pd_512, x86_avx512_div_pd_512};
        const auto k = static_cast<std::size_t>(op);
        return x86_round(scalar[k], packed[k], x, y, rounding);
    }
    Value* add(Value* x, Value* y) {
        return avx512_ ? x86_arith(Arith::add, x, y, ru_sae) : b_.CreateFAdd(x, y);
    }
    Value* sub(Value* x, Value* y) {
        return avx512_ ? x86_arith(Arith::sub, x, y, ru_sae) : b_.CreateFSub(x, y);
    }
    Value* mul(Value* x, Value* y) {
        return avx512_ ? x86_arith(Arith::mul, x, y, ru_sae) : b_.CreateFMul(x, y);
    }
    Value* div(Value* x, Value* y) {
        return avx512_ ? x86_arith(Arith::div, x, y, ru_sae) : b_.CreateFDiv(x, y);
    }
    // x * y + z with one rounding (upward).
    Value* fma(Value* x, Value* y, Value* z) {
        using namespace llvm::Intrinsic;
        if (!avx512_)
            return b_.CreateConstrainedFPCall(
                llvm::Intrinsic::getDeclaration(&m_, experimental_constrained_fma, {vt_}), {x, y, z});
        Function* f =
            llvm::Intrinsic::getDeclaration(&m_, w_ == 8 ? x86_avx512_vfmadd_pd_512 : x86_avx512_vfmadd_f64);
        return b_.CreateCall(f, {x, y, z, b_.getInt32(ru_sae)});
    }
    // The square root rounded up / down. IEEE sqrt is correctly rounded, so both are the exact bounds
    // the interpreter computes (numeric/interval.cpp: RU(sqrt x), and one double below it when
    // RU(sqrt x)^2 > x, which the fma decides exactly).
    Value* sqrt_up(Value* x) {
        if (avx512_) return x86_sqrt(x, ru_sae);
        return b_.CreateConstrainedFPCall(
            llvm::Intrinsic::getDeclaration(&m_, llvm::Intrinsic::experimental_constrained_sqrt, {vt_}), {x});
    }
    Value* sqrt_down(Value* x) {
        if (avx512_) return x86_sqrt(x, rd_sae);
        Value* r = sqrt_up(x);
        return sel(gt(fma(r, r, neg(x)), cst(0.0)), next_down_positive(r), r);
    }
    Value* x86_sqrt(Value* x, int rounding) {
        if (w_ == 8)
            return b_.CreateCall(
                llvm::Intrinsic::getDeclaration(&m_, llvm::Intrinsic::x86_avx512_sqrt_pd_512),
                {x, b_.getInt32(static_cast<std::uint32_t>(rounding))});
        auto* v2 = llvm::FixedVectorType::get(dbl_, 2);
        Value* a = b_.CreateInsertElement(llvm::ConstantAggregateZero::get(v2), x, b_.getInt64(0));
        Function* f = llvm::Intrinsic::getDeclaration(&m_, llvm::Intrinsic::x86_avx512_mask_sqrt_sd);
        Value* r =
            b_.CreateCall(f, {a, a, a, b_.getInt8(0xff), b_.getInt32(static_cast<std::uint32_t>(rounding))});
        return b_.CreateExtractElement(r, b_.getInt64(0));
    }
    // The double below a positive finite x (its bits minus one).
    Value* next_down_positive(Value* x) {
        return b_.CreateBitCast(b_.CreateSub(b_.CreateBitCast(x, vi64_), llvm::ConstantInt::get(vi64_, 1)),
                                vt_);
    }
    Value* neg(Value* x) { return b_.CreateFNeg(x); }
    // Lower bounds: RD(x op y) = -RU(-x op' y), signed zeros included (IEEE's rules for exact zeros are
    // symmetric). AVX-512 rounds down in the instruction; elsewhere two negations around the upward
    // operation.
    Value* add_down(Value* x, Value* y) {
        return avx512_ ? x86_arith(Arith::add, x, y, rd_sae) : neg(sub(neg(x), y));
    }
    Value* sub_down(Value* x, Value* y) {
        return avx512_ ? x86_arith(Arith::sub, x, y, rd_sae) : neg(add(neg(x), y));
    }
    Value* mul_down(Value* x, Value* y) {
        return avx512_ ? x86_arith(Arith::mul, x, y, rd_sae) : neg(mul(neg(x), y));
    }
    Value* div_down(Value* x, Value* y) {
        return avx512_ ? x86_arith(Arith::div, x, y, rd_sae) : neg(div(neg(x), y));
    }
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
    // The nearest integer, ties to even (exact in every mode).
    Value* round_even(Value* x) {
        return rounding_intrinsic(llvm::Intrinsic::roundeven,
                                  llvm::Intrinsic::experimental_constrained_roundeven, x);
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
    IV widen_nan_unless(bool cannot_be_nan, Value* lo, Value* hi);
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
    IV call_scalar(const char* helper, std::vector<Value*> args);
    IV call_vector(Op op, std::int64_t imm, const std::vector<IV>& args, Value* mask);
    SlotState call_core(Op op, std::int64_t imm, const std::vector<const SlotState*>& args, bool maybe_empty);
    // `fast` computed inline where the lane's bit in `fast_lanes` is set; the other lanes of the context
    // call the numeric core (the branch is skipped when no lane needs it).
    IV with_fallback(Value* fast_lanes, IV fast, Op op, const std::vector<const SlotState*>& args);
    // Op::External: the tape's function k, out of line (frac_jit_external, lane by lane in vector code).
    SlotState call_external(std::int64_t k, const SlotState& a, const SlotState& b, const SlotState& c);

    // ---- interval operations: numeric/interval.cpp, step by step ----
    SlotState op_add(const SlotState& a, const SlotState& b);
    SlotState op_sub(const SlotState& a, const SlotState& b);
    SlotState op_mul(const SlotState& a, const SlotState& b);
    // a / b for b not containing 0 and nothing empty; `pos`: b.lo > 0 (else b.hi < 0).
    IV div_nonzero(const SlotState& a, const SlotState& b, Value* pos);
    SlotState op_div(const SlotState& a, const SlotState& b);
    SlotState op_neg(const SlotState& a);
    IV abs_nonempty(IV a);
    SlotState op_abs(const SlotState& a);
    Value* pow_up(Value* x, std::uint64_t n);
    Value* pow_down(Value* x, std::uint64_t n);
    IV pow_positive(IV a, std::uint64_t n);
    SlotState op_sqr(const SlotState& a);
    SlotState op_sqrt(const SlotState& a);
    // sin or cos of a lane's interval: vector range reduction and polynomials (box_kernels.cpp).
    SlotState op_sincos(const SlotState& a, bool is_cos);
    // Enclosure of sin(x) (shift 0) or cos(x) (shift 1) at a point x with |x| <= trig_fast_limit.
    IV sincos_point(Value* x, int shift);
    SlotState op_exp(const SlotState& a);
    // An approximation of exp(x) for |x| <= 700, relative error below 2^-46.
    Value* exp_value(Value* x);
    // tan from the enclosures of sin and cos at the ends, between poles (box_kernels.cpp).
    SlotState op_tan(const SlotState& a);
    SlotState op_log(const SlotState& a);
    // An approximation of log(x) for a positive normal x, error below 2^-47 |log x| (0 at x = 1).
    Value* log_value(Value* x);
    // Enclosures of log over [lo, hi] (positive normal ends) and exp over [lo, hi] (|ends| <= 700), from
    // the endpoint values and their bounds; no checks of the lanes.
    IV log_bounds(const IV& x);
    Value* positive_normal(const IV& x);
    IV exp_bounds(const IV& x);
    // pow(x, y) = exp(y log x) for a positive base and an exponent that is not a thin integer (those take
    // powi's exact path in the core).
    SlotState op_pow(const SlotState& a, const SlotState& b);
    // atan2(y, x) over a box: the core's cases for the origin and the cut, elsewhere the angles at the two
    // extreme corners with a proven error bound (box_kernels.cpp).
    SlotState op_atan2(const SlotState& a, const SlotState& b);
    // An approximation of atan2(y, x) for finite (y, x) != (0, 0), error below 2^-47 |v| + 2^-1060.
    Value* atan2_value(Value* y, Value* x);
    SlotState op_powi(const SlotState& a, std::int64_t n);
    SlotState op_minmax(const SlotState& a, const SlotState& b, bool is_min);
    SlotState op_round(const SlotState& a, bool up);
    Value* is_finite(Value* x);
    SlotState op_mod1(const SlotState& a);
    SlotState op_dz(const SlotState& a);
    SlotState op_not(const SlotState& a);
    SlotState op_andor(const SlotState& a, const SlotState& b, bool is_and);
    IV truth(Value* t, Value* f);
    SlotState op_compare(Op op, const SlotState& a, const SlotState& b);
    SlotState op_select(const SlotState& c, const SlotState& x, const SlotState& y);

    SlotState emit_op(const Instr& ins);
    // Entry idx (a scalar, the same for every lane) of a table of doubles / of intervals.
    Value* load_scalar(llvm::GlobalVariable* g, Value* idx);
    IV load_pair(llvm::GlobalVariable* g, Value* idx);
    // Entry idx[lane] of a table of intervals, lane by lane.
    IV gather_pair(llvm::GlobalVariable* g, Value* idx);
    SlotState from_table(IV v, const Facts& f);

    SlotState combine(Op kind, const SlotState& acc, const SlotState& term);

    // ir::series_tail(kind, A, B, gamma, n) for box-dependent A, B; n a scalar index or one per lane.
    SlotState tail_core(const TapeSeries& s, const SlotState& a, const SlotState& bc, bool has_b, Value* n,
                        Value* mask);

    void store_state(const std::vector<IV>& state);
    std::vector<Value*> escape_params(const ir::OrbitEscape& e);
    Value* mask_arg(Value* mask);

    // ir::lipschitz_centre of the initial point, lane by lane: the centres (replacing `init`) and h.
    Value* centre_orbit(std::vector<IV>& init, Value* mask);

    // ir::lipschitz_finish lane by lane.
    SlotState lipschitz_finish(const TapeSeries& s, const SlotState& acc, const SlotState& tail, Value* bound,
                               Value* n, Value* mask);

    // ir::escape_bound of the orbit point `state` (index n, scalar) for the lanes in `mask`, and
    // ir::escape_bound_around with each lane's radius h (the same without a Lipschitz bound).
    std::pair<Value*, Value*> escape_bound(const TapeSeries& s, const std::vector<IV>& state, Value* n,
                                           Value* mask);
    // ir::escape_tighten: the tail intersected with the escape bound; its signs are no longer known.
    SlotState escape_tighten(Op kind, const SlotState& tail, Value* bound);

    SlotState emit_series(const Instr& ins);

    bool avx512_;
    bool fast_kernels_; // inline sqrt, sin, cos, exp, tan, log, pow, atan2 (FRAC_JIT_EXACT_CALLS=1: the
                        // numeric core's calls)
    Type *vt_, *mt_, *vi64_;
    Value* scratch_in_ = nullptr;
    Value* scratch_n_ = nullptr;
    Value* scratch_out_ = nullptr;
    Value* esc_in_ = nullptr; // escape helper scratch (series with an escape certificate only)
    Value* esc_n_ = nullptr;
    Value* esc_out_ = nullptr;
    Value* esc_h_ = nullptr;
    Value* sink_ = nullptr;
    Value* first_box_ = nullptr;      // the iteration's first box
    std::vector<Value*> box_of_lane_; // ... and each lane's (lanes past the end: the last one)
    Value* lanes_mask_ = nullptr;     // the lanes holding boxes of the batch
    // Cells (CellArgs, loaded once in the entry block): whether there are, the tables per axis, the
    // coordinates, their stride, the closed-inside rule (i1).
    Value* is_cells_ = nullptr;
    Value* cell_axis_[3] = {nullptr, nullptr, nullptr};
    Value* cell_coords_ = nullptr;
    Value* cell_stride_ = nullptr;
    Value* cell_closed_ = nullptr;
    Value* ctx_mask_ = nullptr; // lanes the current code computes for
};

} // namespace frac::jit::box
