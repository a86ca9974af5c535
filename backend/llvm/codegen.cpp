// The point evaluator (plain IEEE operations in round to nearest, as ir::apply_point and the
// interpreter's series_point) and the entry point that emits both functions of a tape.
#include "backend/llvm/codegen.hpp"

#include "backend/llvm/box_codegen.hpp"
#include "ir/graph.hpp"
#include "ir/series_tail.hpp"

#include <llvm/IR/Constants.h>
#include <llvm/IR/DerivedTypes.h>
#include <llvm/IR/Function.h>
#include <llvm/IR/GlobalVariable.h>
#include <llvm/IR/IRBuilder.h>
#include <llvm/IR/Intrinsics.h>
#include <llvm/IR/Module.h>

#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

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

// Types, table globals and helper declarations of the point generator.
class Common {
public:
    Common(const Tape& t, const ir::EvalOptions& o, const Tables& tab, llvm::Module& m, std::string name)
        : t_(t), o_(o), tab_(tab), m_(m), ctx_(m.getContext()), name_(std::move(name)) {
        dbl_ = Type::getDoubleTy(ctx_);
        i64_ = Type::getInt64Ty(ctx_);
        i32_ = Type::getInt32Ty(ctx_);
        ptr_ = llvm::PointerType::get(ctx_, 0);
        pair_ = llvm::StructType::get(ctx_, {dbl_, dbl_});
    }

    // A private constant array of doubles (intervals are stored as lo, hi pairs).
    llvm::GlobalVariable* table(const std::vector<double>& v, const std::string& what) {
        auto* init = llvm::ConstantDataArray::get(ctx_, llvm::ArrayRef<double>(v));
        auto* g = new llvm::GlobalVariable(m_, init->getType(), true, llvm::GlobalValue::PrivateLinkage, init,
                                           name_ + "." + what);
        g->setUnnamedAddr(llvm::GlobalValue::UnnamedAddr::Global);
        g->setAlignment(llvm::Align(16));
        return g;
    }
    llvm::GlobalVariable* table(const std::vector<Interval>& v, const std::string& what) {
        std::vector<double> flat;
        flat.reserve(2 * v.size());
        for (const Interval& x : v) {
            flat.push_back(x.lo);
            flat.push_back(x.hi);
        }
        return table(flat, what);
    }

    Function* declare(const char* name, Type* ret, std::vector<Type*> args) {
        auto* fty = llvm::FunctionType::get(ret, args, false);
        auto callee = m_.getOrInsertFunction(name, fty);
        auto* f = llvm::cast<Function>(callee.getCallee());
        f->setDoesNotThrow();
        return f;
    }

    Function* make_batch_function(const std::string& name) {
        auto* fty = llvm::FunctionType::get(Type::getVoidTy(ctx_), {ptr_, i64_, ptr_, ptr_}, false);
        Function* f = Function::Create(fty, llvm::GlobalValue::ExternalLinkage, name, m_);
        f->setDoesNotThrow();
        for (unsigned k : {0u, 2u, 3u}) {
            f->addParamAttr(k, llvm::Attribute::NoAlias);
            f->addParamAttr(k, llvm::Attribute::NoCapture);
        }
        f->addParamAttr(0, llvm::Attribute::ReadOnly);
        return f;
    }

    std::int64_t last_index(const TapeSeries& s) const {
        return s.data.end == ir::infinite_end ? s.data.start + o_.max_terms - 1 : s.data.end;
    }

protected:
    const Tape& t_;
    const ir::EvalOptions& o_;
    const Tables& tab_;
    llvm::Module& m_;
    llvm::LLVMContext& ctx_;
    std::string name_;
    Type *dbl_, *i64_, *i32_, *ptr_;
    llvm::StructType* pair_;
};

// ---------------------------------------------------------------------------------------------------
// Point code: plain IEEE operations in round to nearest, as ir::apply_point.

class PointGen : Common {
public:
    PointGen(const Tape& t, const ir::EvalOptions& o, const Tables& tab, llvm::Module& m,
             const std::string& name)
        : Common(t, o, tab, m, name), b_(m.getContext()) {}

    std::string run() {
        const std::string fname = name_ + "_point";
        Function* f = make_batch_function(fname);
        fn_ = f;
        Value* in = f->getArg(0);
        Value* n = f->getArg(1);
        Value* out = f->getArg(2);
        Value* stats = f->getArg(3);
        BasicBlock* entry = BasicBlock::Create(ctx_, "entry", f);
        BasicBlock* loop = BasicBlock::Create(ctx_, "point", f);
        BasicBlock* done = BasicBlock::Create(ctx_, "done", f);
        b_.SetInsertPoint(entry);
        terms_ = b_.CreateAlloca(i64_, nullptr, "terms");
        capped_ = b_.CreateAlloca(i64_, nullptr, "capped");
        b_.CreateStore(b_.getInt64(0), terms_);
        b_.CreateStore(b_.getInt64(0), capped_);
        escape_state_ = b_.CreateAlloca(llvm::ArrayType::get(dbl_, 8), nullptr, "escape.state");
        b_.CreateCondBr(b_.CreateICmpEQ(n, b_.getInt64(0)), done, loop);
        b_.SetInsertPoint(loop);
        llvm::PHINode* k = b_.CreatePHI(i64_, 2, "k");
        k->addIncoming(b_.getInt64(0), entry);
        vals_.assign(t_.num_slots, nullptr);
        idx_.assign(t_.series.size(), nullptr);
        for (const ir::TapeConst& c : t_.constants) vals_[c.slot] = cst(c.point);
        const auto d = static_cast<std::uint64_t>(t_.inputs);
        Value* base = b_.CreateMul(k, b_.getInt64(d));
        for (std::size_t j = 0; j < t_.input_slots.size(); ++j)
            if (t_.input_slots[j] != ir::no_slot)
                vals_[t_.input_slots[j]] =
                    b_.CreateLoad(dbl_, b_.CreateInBoundsGEP(dbl_, in, b_.CreateAdd(base, b_.getInt64(j))));
        emit_block(0);
        b_.CreateStore(vals_[t_.result], b_.CreateInBoundsGEP(dbl_, out, k));
        Value* k1 = b_.CreateAdd(k, b_.getInt64(1));
        k->addIncoming(k1, b_.GetInsertBlock());
        b_.CreateCondBr(b_.CreateICmpEQ(k1, n), done, loop);
        b_.SetInsertPoint(done);
        add_stat(stats, 0, n);
        add_stat(stats, 1, b_.CreateLoad(i64_, terms_));
        add_stat(stats, 2, b_.CreateLoad(i64_, capped_));
        b_.CreateRetVoid();
        return fname;
    }

private:
    Value* cst(double x) { return llvm::ConstantFP::get(dbl_, x); }
    void add_stat(Value* stats, int field, Value* v) {
        Value* p = b_.CreateInBoundsGEP(i64_, stats, b_.getInt64(static_cast<std::uint64_t>(field)));
        b_.CreateStore(b_.CreateAdd(b_.CreateLoad(i64_, p), v), p);
    }
    void bump(Value* counter, Value* by) {
        b_.CreateStore(b_.CreateAdd(b_.CreateLoad(i64_, counter), by), counter);
    }
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
        std::vector<Type*> types(args.size(), dbl_);
        Function* f = declare(helper, dbl_, types);
        auto* c = b_.CreateCall(f, args);
        return c;
    }
    Value* half_true(Value* x) { return b_.CreateFCmpOGT(x, cst(0.5)); }
    // ir::point_magnitude: max(|lo|, |hi|), +inf when either is NaN.
    Value* magnitude(Value* lo, Value* hi) {
        Value* m = c_fmax(intrinsic(llvm::Intrinsic::fabs, lo), intrinsic(llvm::Intrinsic::fabs, hi));
        return sel(b_.CreateFCmpUNO(lo, hi), cst(std::numeric_limits<double>::infinity()), m);
    }

    Value* emit_op(const Instr& ins) {
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
        case Op::Const:
        case Op::Var:
        case Op::Index:
        case Op::State:
        case Op::SeriesSum:
        case Op::SeriesMin:
        case Op::SeriesMax: break;
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

    Value* emit_series(const Instr& ins) {
        const TapeSeries& s = t_.series[ins.series];
        const SeriesTables& st = tab_.series[ins.series];
        const bool infinite = s.data.end == ir::infinite_end;
        const bool has_b = s.tail_b != ir::no_slot;
        const std::int64_t start = s.data.start;
        const std::int64_t last = last_index(s);
        if (s.point_block != ir::no_block) emit_block(s.point_block);
        // Bounds of A and B at this point (not their point values: those are no bounds).
        auto bound = [&](std::size_t k) {
            return s.point_tail[k] == ir::no_slot ? cst(std::nan("")) : vals_[s.point_tail[k]];
        };
        Value* a = infinite ? magnitude(bound(0), bound(1)) : cst(0.0);
        Value* bc = has_b ? magnitude(bound(2), bound(3)) : cst(0.0);
        const double gamma = s.data.gamma.hi;

        BasicBlock* pre = b_.GetInsertBlock();
        BasicBlock* header = BasicBlock::Create(ctx_, "series", fn_);
        BasicBlock* latch = BasicBlock::Create(ctx_, "series.next", fn_);
        BasicBlock* exit = BasicBlock::Create(ctx_, "series.exit", fn_);
        b_.CreateBr(header);
        b_.SetInsertPoint(header);
        llvm::PHINode* i = b_.CreatePHI(i64_, 2, "i");
        llvm::PHINode* acc = b_.CreatePHI(dbl_, 2, "acc");
        llvm::PHINode* comp = b_.CreatePHI(dbl_, 2, "comp"); // sums: ir::compensated_add's error term
        llvm::PHINode* gnext = b_.CreatePHI(dbl_, 2, "gamma.next");
        i->addIncoming(b_.getInt64(static_cast<std::uint64_t>(start)), pre);
        acc->addIncoming(cst(0.0), pre);
        comp->addIncoming(cst(0.0), pre);
        gnext->addIncoming(cst(infinite ? st.point_gamma_next : 0.0), pre);
        std::vector<llvm::PHINode*> state_phis;
        for (std::size_t c = 0; c < s.state_slots.size(); ++c) {
            llvm::PHINode* p = b_.CreatePHI(dbl_, 2, "state");
            p->addIncoming(vals_[s.init_slots[c]], pre);
            state_phis.push_back(p);
            vals_[s.state_slots[c]] = p;
        }
        idx_[ins.series] = b_.CreateSub(i, b_.getInt64(static_cast<std::uint64_t>(start)), "idx");
        vals_[s.index_slot] = b_.CreateSIToFP(i, dbl_);

        emit_block(s.block);

        std::vector<Value*> next_state(s.state_slots.size());
        for (std::size_t c = 0; c < s.state_slots.size(); ++c) next_state[c] = vals_[s.update_slots[c]];
        Value* term = vals_[s.body_slot];
        Value* first = b_.CreateICmpEQ(i, b_.getInt64(static_cast<std::uint64_t>(start)));
        Value* nacc = sel(first, term, combine(s.kind, acc, term));
        Value* ncomp = cst(0.0);
        if (s.kind == Op::SeriesSum) {
            // ir::compensated_add, operation for operation.
            Value* err = sel(b_.CreateFCmpOGE(intrinsic(llvm::Intrinsic::fabs, acc),
                                              intrinsic(llvm::Intrinsic::fabs, term)),
                             b_.CreateFAdd(b_.CreateFSub(acc, nacc), term),
                             b_.CreateFAdd(b_.CreateFSub(term, nacc), acc));
            Value* finite = b_.CreateFCmpOLT(intrinsic(llvm::Intrinsic::fabs, nacc),
                                             cst(std::numeric_limits<double>::infinity()));
            ncomp = sel(first, cst(0.0), sel(finite, b_.CreateFAdd(comp, err), comp));
        }
        bump(terms_, b_.getInt64(1));
        Value* is_last = b_.CreateICmpEQ(i, b_.getInt64(static_cast<std::uint64_t>(last)));
        Value* gnext2 = gnext;
        if (!infinite || (s.data.one_sided && !s.data.escape.present)) {
            b_.CreateCondBr(is_last, exit, latch); // a one-sided bound gives no tail estimate
        } else if (s.data.escape.present) {
            // The escape certificate bounds every later term from the orbit point q_{i+1}.
            BasicBlock* check = BasicBlock::Create(ctx_, "series.escape", fn_);
            b_.CreateCondBr(is_last, exit, check);
            b_.SetInsertPoint(check);
            for (std::size_t c = 0; c < next_state.size(); ++c)
                b_.CreateStore(next_state[c], b_.CreateConstInBoundsGEP1_64(dbl_, escape_state_, c));
            const ir::OrbitEscape& e = s.data.escape;
            Function* done_fn =
                declare("frac_jit_escape_point_done", i32_,
                        {i32_, dbl_, ptr_, i32_, i64_, dbl_, dbl_, dbl_, dbl_, dbl_, dbl_, dbl_});
            Value* done = b_.CreateCall(
                done_fn, {b_.getInt32(static_cast<std::uint32_t>(s.kind)), nacc, escape_state_,
                          b_.getInt32(static_cast<std::uint32_t>(next_state.size())),
                          b_.CreateAdd(i, b_.getInt64(1)), cst(e.radius), cst(e.slope), cst(e.offset),
                          cst(e.scale0.lo), cst(e.scale0.hi), cst(e.growth.lo), cst(e.growth.hi)});
            b_.CreateCondBr(b_.CreateICmpNE(done, b_.getInt32(0)), exit, latch);
        } else {
            BasicBlock* check = BasicBlock::Create(ctx_, "series.check", fn_);
            b_.CreateCondBr(is_last, exit, check);
            b_.SetInsertPoint(check);
            // (a + b n1) gamma_next (n1 + 1) / (1 - gamma)^2, in the interpreter's order.
            Value* n1 = b_.CreateSIToFP(b_.CreateAdd(i, b_.getInt64(1)), dbl_);
            Value* tail = b_.CreateFAdd(a, b_.CreateFMul(bc, n1));
            tail = b_.CreateFMul(tail, gnext);
            tail = b_.CreateFMul(tail, b_.CreateFAdd(n1, cst(1.0)));
            tail = b_.CreateFDiv(tail, cst(st.point_denominator));
            Value* small =
                b_.CreateOr(b_.CreateFCmpOLE(tail, b_.CreateFMul(cst(ir::point_stop_ratio),
                                                                 intrinsic(llvm::Intrinsic::fabs, nacc))),
                            b_.CreateFCmpOEQ(tail, cst(0.0)));
            gnext2 = b_.CreateFMul(gnext, cst(gamma));
            b_.CreateCondBr(small, exit, latch);
        }
        b_.SetInsertPoint(latch);
        i->addIncoming(b_.CreateAdd(i, b_.getInt64(1)), latch);
        acc->addIncoming(nacc, latch);
        comp->addIncoming(ncomp, latch);
        gnext->addIncoming(gnext2, latch);
        for (std::size_t c = 0; c < state_phis.size(); ++c) state_phis[c]->addIncoming(next_state[c], latch);
        b_.CreateBr(header);

        b_.SetInsertPoint(exit);
        Value* total = b_.CreateFAdd(nacc, ncomp);
        if (!infinite) return total;
        bump(capped_, b_.CreateZExt(is_last, i64_));
        // No tail estimate from a one-sided bound (min and max series: comp is 0).
        if (s.data.escape.present || s.data.one_sided) return total;
        // The tail's midpoint (ir::series_point_end, as the interpreter).
        Function* end_fn = declare("frac_jit_point_series_end", dbl_,
                                   {i32_, dbl_, dbl_, dbl_, dbl_, dbl_, dbl_, i32_, dbl_, dbl_, i64_});
        return b_.CreateCall(end_fn,
                             {b_.getInt32(static_cast<std::uint32_t>(s.kind)), nacc, ncomp, bound(0),
                              bound(1), has_b ? bound(2) : cst(0.0), has_b ? bound(3) : cst(0.0),
                              b_.getInt32(has_b ? 1 : 0), cst(s.data.gamma.lo), cst(s.data.gamma.hi), i});
    }

    void emit_block(std::uint32_t block) {
        for (const Instr& ins : t_.blocks[block]) {
            if (ir::is_series(ins.op)) {
                vals_[ins.out] = emit_series(ins);
                continue;
            }
            const int tix = tab_.slot_table[ins.out];
            if (tix >= 0) {
                const IndexTable& it = tab_.index_tables[static_cast<std::size_t>(tix)];
                llvm::GlobalVariable* g;
                if (auto f = globals_.find(&it.point); f != globals_.end()) {
                    g = f->second;
                } else {
                    g = globals_[&it.point] = table(it.point, "index_point");
                }
                vals_[ins.out] = b_.CreateLoad(dbl_, b_.CreateInBoundsGEP(dbl_, g, idx_[it.series]));
                continue;
            }
            vals_[ins.out] = emit_op(ins);
        }
    }

    llvm::IRBuilder<> b_;
    Function* fn_ = nullptr;
    Value* terms_ = nullptr;
    Value* capped_ = nullptr;
    Value* escape_state_ = nullptr; // the orbit point for the escape helper
    std::vector<Value*> vals_;
    std::vector<Value*> idx_;
    std::map<const void*, llvm::GlobalVariable*> globals_;
};

} // namespace

GeneratedNames generate(const Tape& tape, const ir::EvalOptions& options, const Tables& tables,
                        llvm::Module& module, const std::string& name, Rounding rounding, int lanes) {
    GeneratedNames names;
    names.box = generate_box_function(tape, options, tables, module, name, rounding, lanes);
    names.point = PointGen(tape, options, tables, module, name).run();
    return names;
}

} // namespace frac::jit
