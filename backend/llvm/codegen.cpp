// The point evaluator (plain IEEE operations in round to nearest, as ir::apply_point and the
// interpreter's series_point) and the entry point that emits both functions of a tape.
#include "backend/llvm/codegen.hpp"

#include "backend/llvm/box_codegen.hpp"
#include "backend/llvm/skeleton.hpp"
#include "ir/graph.hpp"
#include "ir/series_tail.hpp"

#include <llvm/IR/Intrinsics.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace frac::jit {
namespace {

using ir::Instr;
using ir::Op;
using ir::Tape;
using llvm::BasicBlock;
using llvm::Function;
using llvm::Value;

// Point code: plain IEEE operations in round to nearest, as ir::apply_point.
class PointGen : public Skeleton<PointGen, Value*> {
    friend class Skeleton<PointGen, Value*>;

public:
    PointGen(const Tape& t, const ir::EvalOptions& o, const Tables& tab, llvm::Module& m,
             const std::string& name)
        : Skeleton(t, o, tab, m, name, 1) {}

private:
    // ---- the skeleton's hooks ----
    void prepare(Function*) {}
    void allocate() {
        escape_state_ =
            b_.CreateAlloca(llvm::ArrayType::get(dbl_, ir::max_state_components), nullptr, "escape.state");
    }
    void load_inputs(Value* in, Value*, Value* k) {
        const auto d = static_cast<std::uint64_t>(t_.inputs);
        Value* base = b_.CreateMul(k, b_.getInt64(d));
        for (std::size_t j = 0; j < t_.input_slots.size(); ++j)
            if (t_.input_slots[j] != ir::no_slot)
                vals_[t_.input_slots[j]] =
                    b_.CreateLoad(dbl_, b_.CreateInBoundsGEP(dbl_, in, b_.CreateAdd(base, b_.getInt64(j))));
    }
    void store_result(Value* out, Value*, Value* k) {
        b_.CreateStore(vals_[t_.result], b_.CreateInBoundsGEP(dbl_, out, k));
    }
    Value* constant(const ir::TapeConst& c) { return cst(c.point); }
    Value* indexed(const IndexTable& it, Value* idx) {
        return b_.CreateLoad(dbl_,
                             b_.CreateInBoundsGEP(dbl_, table(&it.point, it.point, "index_point"), idx));
    }
    Value* carry(Value* init, BasicBlock* pre, ir::Slot) {
        llvm::PHINode* p = b_.CreatePHI(dbl_, 2, "state");
        p->addIncoming(init, pre);
        return p;
    }
    void carry_next(Value* phi, Value* next, BasicBlock* latch) {
        llvm::cast<llvm::PHINode>(phi)->addIncoming(next, latch);
    }
    Value* index_value(const SeriesLoop& L) { return b_.CreateSIToFP(L.i, dbl_); }

    // ---- operations ----
    Value* cst(double x) { return llvm::ConstantFP::get(dbl_, x); }
    Value* sel(Value* c, Value* x, Value* y) { return b_.CreateSelect(c, x, y); }
    Value* bool_to_double(Value* c) { return sel(c, cst(1.0), cst(0.0)); }
    Value* c_fmin(Value* x, Value* y) {
        return sel(b_.CreateFCmpOLE(x, y), x, sel(b_.CreateFCmpUNO(y, y), x, y));
    }
    Value* c_fmax(Value* x, Value* y) {
        return sel(b_.CreateFCmpOGE(x, y), x, sel(b_.CreateFCmpUNO(y, y), x, y));
    }
    Value* std_min(Value* x, Value* y) { return sel(b_.CreateFCmpOLT(y, x), y, x); }
    Value* intrinsic(llvm::Intrinsic::ID id, Value* x) { return b_.CreateUnaryIntrinsic(id, x); }
    Value* call(const char* helper, std::vector<Value*> args) {
        return b_.CreateCall(declare(helper, dbl_, std::vector<llvm::Type*>(args.size(), dbl_)), args);
    }
    Value* half_true(Value* x) { return b_.CreateFCmpOGT(x, cst(0.5)); }
    // ir::point_magnitude: max(|lo|, |hi|), +inf when either is NaN.
    Value* magnitude(Value* lo, Value* hi) {
        Value* m = c_fmax(intrinsic(llvm::Intrinsic::fabs, lo), intrinsic(llvm::Intrinsic::fabs, hi));
        return sel(b_.CreateFCmpUNO(lo, hi), cst(std::numeric_limits<double>::infinity()), m);
    }

    Value* operation(const Instr& ins) {
        auto in = [&](int k) { return vals_[ins.in[static_cast<std::size_t>(k)]]; };
        switch (ins.op) {
        case Op::Add: return b_.CreateFAdd(in(0), in(1));
        case Op::Sub: return b_.CreateFSub(in(0), in(1));
        case Op::Mul: return b_.CreateFMul(in(0), in(1));
        case Op::Div: return b_.CreateFDiv(in(0), in(1));
        case Op::Neg: return b_.CreateFNeg(in(0));
        case Op::Sqr: return b_.CreateFMul(in(0), in(0));
        case Op::PowI: return call("frac_jit_pow_point", {in(0), cst(static_cast<double>(ins.imm))});
        case Op::Pow: return call("frac_jit_pow_point", {in(0), in(1)});
        case Op::Sqrt: return intrinsic(llvm::Intrinsic::sqrt, in(0));
        case Op::Abs: return intrinsic(llvm::Intrinsic::fabs, in(0));
        case Op::Min: return c_fmin(in(0), in(1));
        case Op::Max: return c_fmax(in(0), in(1));
        case Op::Floor: return intrinsic(llvm::Intrinsic::floor, in(0));
        case Op::Ceil: return intrinsic(llvm::Intrinsic::ceil, in(0));
        case Op::Mod1: return b_.CreateFSub(in(0), intrinsic(llvm::Intrinsic::floor, in(0)));
        case Op::Dz: {
            Value* x = in(0);
            return std_min(b_.CreateFSub(x, intrinsic(llvm::Intrinsic::floor, x)),
                           b_.CreateFSub(intrinsic(llvm::Intrinsic::ceil, x), x));
        }
        case Op::Sin: return call("frac_jit_sin_point", {in(0)});
        case Op::Cos: return call("frac_jit_cos_point", {in(0)});
        case Op::Tan: return call("frac_jit_tan_point", {in(0)});
        case Op::Exp: return call("frac_jit_exp_point", {in(0)});
        case Op::Log: return call("frac_jit_log_point", {in(0)});
        case Op::Atan2: return call("frac_jit_atan2_point", {in(0), in(1)});
        case Op::External:
            return b_.CreateCall(declare("frac_jit_external_point", dbl_, {ptr_, dbl_, dbl_, dbl_}),
                                 {external_function(ins.imm), in(0), in(1), in(2)});
        case Op::Lt: return bool_to_double(b_.CreateFCmpOLT(in(0), in(1)));
        case Op::Le: return bool_to_double(b_.CreateFCmpOLE(in(0), in(1)));
        case Op::Gt: return bool_to_double(b_.CreateFCmpOGT(in(0), in(1)));
        case Op::Ge: return bool_to_double(b_.CreateFCmpOGE(in(0), in(1)));
        case Op::Eq: return bool_to_double(b_.CreateFCmpOEQ(in(0), in(1)));
        case Op::Ne: return bool_to_double(b_.CreateFCmpUNE(in(0), in(1)));
        case Op::And: return bool_to_double(b_.CreateAnd(half_true(in(0)), half_true(in(1))));
        case Op::Or: return bool_to_double(b_.CreateOr(half_true(in(0)), half_true(in(1))));
        case Op::Not: return bool_to_double(b_.CreateNot(half_true(in(0))));
        case Op::Select: return sel(half_true(in(0)), in(1), in(2));
#include "ir/non_operation_cases.def"
            break;
        }
        throw std::logic_error(std::string("jit: not an operation: ") + ir::op_name(ins.op));
    }

    Value* combine(Op kind, Value* acc, Value* term) {
        switch (kind) {
        case Op::SeriesSum: return b_.CreateFAdd(acc, term);
        case Op::SeriesMin: return c_fmin(acc, term);
        case Op::SeriesMax: return c_fmax(acc, term);
        default: break;
        }
        throw std::logic_error("jit: not a series");
    }

    Value* series(const Instr& ins) {
        SeriesLoop L = series_loop(ins);
        const ir::TapeSeries& s = L.s;
        if (s.point_block != ir::no_block) emit_block(s.point_block);
        // Bounds of A and B at this point (not their point values: those are no bounds).
        auto bound = [&](std::size_t k) {
            return s.point_tail[k] == ir::no_slot ? cst(std::nan("")) : vals_[s.point_tail[k]];
        };
        Value* a = L.infinite ? magnitude(bound(0), bound(1)) : cst(0.0);
        Value* bc = L.has_b ? magnitude(bound(2), bound(3)) : cst(0.0);

        std::vector<Value*> init;
        for (ir::Slot c : s.init_slots) init.push_back(vals_[c]);
        open_series(L, init);
        llvm::PHINode* acc = b_.CreatePHI(dbl_, 2, "acc");
        llvm::PHINode* comp = b_.CreatePHI(dbl_, 2, "comp"); // sums: ir::compensated_add's error term
        llvm::PHINode* gnext = b_.CreatePHI(dbl_, 2, "gamma.next");
        acc->addIncoming(cst(0.0), L.pre);
        comp->addIncoming(cst(0.0), L.pre);
        gnext->addIncoming(cst(L.infinite ? L.st.point_gamma_next : 0.0), L.pre);
        series_body(L);

        Value* term = L.term;
        Value* nacc = sel(L.first, term, combine(s.kind, acc, term));
        Value* ncomp = cst(0.0);
        if (s.kind == Op::SeriesSum) {
            // ir::compensated_add, operation for operation.
            Value* err = sel(b_.CreateFCmpOGE(intrinsic(llvm::Intrinsic::fabs, acc),
                                              intrinsic(llvm::Intrinsic::fabs, term)),
                             b_.CreateFAdd(b_.CreateFSub(acc, nacc), term),
                             b_.CreateFAdd(b_.CreateFSub(term, nacc), acc));
            Value* finite = b_.CreateFCmpOLT(intrinsic(llvm::Intrinsic::fabs, nacc),
                                             cst(std::numeric_limits<double>::infinity()));
            ncomp = sel(L.first, cst(0.0), sel(finite, b_.CreateFAdd(comp, err), comp));
        }
        bump(terms_, b_.getInt64(1));
        Value* gnext2 = gnext;
        if (!L.infinite || (s.data.one_sided && !s.data.escape.present)) {
            b_.CreateCondBr(L.is_last, L.exit, L.latch); // a one-sided bound gives no tail estimate
        } else if (s.data.escape.present) {
            // The escape certificate bounds every later term from the orbit point q_{i+1}.
            BasicBlock* check = BasicBlock::Create(ctx_, "series.escape", fn_);
            b_.CreateCondBr(L.is_last, L.exit, check);
            b_.SetInsertPoint(check);
            for (std::size_t c = 0; c < L.next_state.size(); ++c)
                b_.CreateStore(L.next_state[c], b_.CreateConstInBoundsGEP1_64(dbl_, escape_state_, c));
            const ir::OrbitEscape& e = s.data.escape;
            auto done_fn = declare("frac_jit_escape_point_done", i32_,
                                   {i32_, dbl_, ptr_, i32_, i64_, dbl_, dbl_, dbl_, dbl_, dbl_, dbl_, dbl_});
            Value* done = b_.CreateCall(
                done_fn, {b_.getInt32(static_cast<std::uint32_t>(s.kind)), nacc, escape_state_,
                          b_.getInt32(static_cast<std::uint32_t>(L.next_state.size())),
                          b_.CreateAdd(L.i, b_.getInt64(1)), cst(e.radius), cst(e.slope), cst(e.offset),
                          cst(e.scale0.lo), cst(e.scale0.hi), cst(e.growth.lo), cst(e.growth.hi)});
            b_.CreateCondBr(b_.CreateICmpNE(done, b_.getInt32(0)), L.exit, L.latch);
        } else {
            BasicBlock* check = BasicBlock::Create(ctx_, "series.check", fn_);
            b_.CreateCondBr(L.is_last, L.exit, check);
            b_.SetInsertPoint(check);
            // (a + b n1) gamma_next (n1 + 1) / (1 - gamma)^2, in the interpreter's order.
            Value* n1 = b_.CreateSIToFP(b_.CreateAdd(L.i, b_.getInt64(1)), dbl_);
            Value* tail = b_.CreateFAdd(a, b_.CreateFMul(bc, n1));
            tail = b_.CreateFMul(tail, gnext);
            tail = b_.CreateFMul(tail, b_.CreateFAdd(n1, cst(1.0)));
            tail = b_.CreateFDiv(tail, cst(L.st.point_denominator));
            Value* small =
                b_.CreateOr(b_.CreateFCmpOLE(tail, b_.CreateFMul(cst(ir::point_stop_ratio),
                                                                 intrinsic(llvm::Intrinsic::fabs, nacc))),
                            b_.CreateFCmpOEQ(tail, cst(0.0)));
            gnext2 = b_.CreateFMul(gnext, cst(s.data.gamma.hi));
            b_.CreateCondBr(small, L.exit, L.latch);
        }
        acc->addIncoming(nacc, L.latch);
        comp->addIncoming(ncomp, L.latch);
        gnext->addIncoming(gnext2, L.latch);
        close_series(L);

        Value* total = b_.CreateFAdd(nacc, ncomp);
        if (!L.infinite) return total;
        bump(capped_, b_.CreateZExt(L.is_last, i64_));
        // No tail estimate from a one-sided bound (min and max series: comp is 0).
        if (s.data.escape.present || s.data.one_sided) return total;
        // The tail's midpoint (ir::series_point_end, as the interpreter).
        auto end_fn = declare("frac_jit_point_series_end", dbl_,
                              {i32_, dbl_, dbl_, dbl_, dbl_, dbl_, dbl_, i32_, dbl_, dbl_, i64_});
        return b_.CreateCall(end_fn,
                             {b_.getInt32(static_cast<std::uint32_t>(s.kind)), nacc, ncomp, bound(0),
                              bound(1), L.has_b ? bound(2) : cst(0.0), L.has_b ? bound(3) : cst(0.0),
                              b_.getInt32(L.has_b ? 1 : 0), cst(s.data.gamma.lo), cst(s.data.gamma.hi), L.i});
    }

    Value* escape_state_ = nullptr; // the orbit point for the escape helper
};

} // namespace

std::string external_getter(const std::string& name, std::int64_t k) {
    return name + ".external." + std::to_string(k);
}

GeneratedNames generate(const Tape& tape, const ir::EvalOptions& options, const Tables& tables,
                        llvm::Module& module, const std::string& name, Rounding rounding, int lanes) {
    GeneratedNames names;
    generate_box_functions(tape, options, tables, module, name, rounding, lanes, names);
    names.point = PointGen(tape, options, tables, module, name).run("_point", "point");
    return names;
}

} // namespace frac::jit
