// The code-generator skeleton that point code (codegen.cpp) and box code (box/) share: the batch
// function and its loop over points or groups of boxes, the dispatch of a block's instructions, and
// the frame of a series loop (its blocks, its index, the orbit point carried from term to term).
// Private to backend/llvm.
//
// `Gen` (CRTP) says what a slot holds (`V`: one double, or an interval per lane) and supplies:
//   void prepare(Function*)                   attributes of the batch function
//   void allocate()                           scratch memory, in the entry block
//   void load_inputs(Value* in, Value* n, Value* k), void store_result(Value* out, Value* n, Value* k)
//   V constant(const ir::TapeConst&), V indexed(const IndexTable&, Value* idx), V operation(const Instr&)
//   V series(const Instr&)                    built on open_series / body / close_series
//   V carry(const V& init, BasicBlock* pre, Slot), void carry_next(const V& phis, const V& next, BasicBlock*)
//                                             the loop-carried orbit point: phis and their latch values
//   V index_value(const SeriesLoop&)          the index slot's value from the index i
#pragma once

#include "backend/llvm/codegen.hpp"
#include "backend/llvm/tables.hpp"
#include "ir/evaluator.hpp"
#include "ir/graph.hpp"
#include "ir/tape.hpp"

#include <llvm/IR/Constants.h>
#include <llvm/IR/DerivedTypes.h>
#include <llvm/IR/Function.h>
#include <llvm/IR/GlobalVariable.h>
#include <llvm/IR/IRBuilder.h>
#include <llvm/IR/Module.h>

#include <map>
#include <string>
#include <vector>

namespace frac::jit {

template <class Gen, class V>
class Skeleton {
public:
    Skeleton(const ir::Tape& t, const ir::EvalOptions& o, const Tables& tab, llvm::Module& m,
             std::string name, int lanes)
        : t_(t), o_(o), tab_(tab), m_(m), ctx_(m.getContext()), name_(std::move(name)), b_(m.getContext()),
          w_(lanes) {
        dbl_ = llvm::Type::getDoubleTy(ctx_);
        i64_ = llvm::Type::getInt64Ty(ctx_);
        i32_ = llvm::Type::getInt32Ty(ctx_);
        ptr_ = llvm::PointerType::get(ctx_, 0);
        pair_ = llvm::StructType::get(ctx_, {dbl_, dbl_});
    }

    // void <name><suffix>(const double* in, i64 n, double* out, u64* stats): a loop over the batch,
    // w_ points or boxes an iteration; stats gets n, the terms and the capped series. With `args`, a
    // fifth parameter, a read-only pointer the generator reads (fn_->getArg(4)).
    std::string run(const char* suffix, const char* loop_name, bool args = false,
                    llvm::GlobalValue::LinkageTypes linkage = llvm::GlobalValue::ExternalLinkage) {
        const std::string fname = name_ + suffix;
        std::vector<llvm::Type*> params{ptr_, i64_, ptr_, ptr_};
        if (args) params.push_back(ptr_);
        auto* fty = llvm::FunctionType::get(llvm::Type::getVoidTy(ctx_), params, false);
        llvm::Function* f = llvm::Function::Create(fty, linkage, fname, m_);
        f->setDoesNotThrow();
        for (unsigned k : {0u, 2u, 3u, 4u}) {
            if (k >= params.size()) continue;
            f->addParamAttr(k, llvm::Attribute::NoAlias);
            f->addParamAttr(k, llvm::Attribute::NoCapture);
        }
        f->addParamAttr(0, llvm::Attribute::ReadOnly);
        if (args) f->addParamAttr(4, llvm::Attribute::ReadOnly);
        gen().prepare(f);
        fn_ = f;
        llvm::Value* in = f->getArg(0);
        llvm::Value* n = f->getArg(1);
        llvm::Value* out = f->getArg(2);
        llvm::Value* stats = f->getArg(3);

        llvm::BasicBlock* entry = llvm::BasicBlock::Create(ctx_, "entry", f);
        llvm::BasicBlock* loop = llvm::BasicBlock::Create(ctx_, loop_name, f);
        llvm::BasicBlock* done = llvm::BasicBlock::Create(ctx_, "done", f);
        b_.SetInsertPoint(entry);
        terms_ = b_.CreateAlloca(i64_, nullptr, "terms");
        capped_ = b_.CreateAlloca(i64_, nullptr, "capped");
        b_.CreateStore(b_.getInt64(0), terms_);
        b_.CreateStore(b_.getInt64(0), capped_);
        gen().allocate(); // may end in another block than the entry
        llvm::BasicBlock* pre = b_.GetInsertBlock();
        b_.CreateCondBr(b_.CreateICmpEQ(n, b_.getInt64(0)), done, loop);

        b_.SetInsertPoint(loop);
        llvm::PHINode* k = b_.CreatePHI(i64_, 2, "k");
        k->addIncoming(b_.getInt64(0), pre);
        vals_.assign(t_.num_slots, V{});
        idx_.assign(t_.series.size(), nullptr);
        for (const ir::TapeConst& c : t_.constants) vals_[c.slot] = gen().constant(c);
        gen().load_inputs(in, n, k);
        emit_block(0);
        gen().store_result(out, n, k);
        llvm::Value* k1 = b_.CreateAdd(k, b_.getInt64(1));
        k->addIncoming(k1, b_.GetInsertBlock());
        llvm::Value* end =
            w_ == 1 ? b_.CreateICmpEQ(k1, n)
                    : b_.CreateICmpUGE(b_.CreateMul(k1, b_.getInt64(static_cast<std::uint64_t>(w_))), n);
        b_.CreateCondBr(end, done, loop);

        b_.SetInsertPoint(done);
        add_stat(stats, 0, n);
        add_stat(stats, 1, b_.CreateLoad(i64_, terms_));
        add_stat(stats, 2, b_.CreateLoad(i64_, capped_));
        b_.CreateRetVoid();
        return fname;
    }

protected:
    Gen& gen() { return static_cast<Gen&>(*this); }

    void emit_block(std::uint32_t block) {
        for (const ir::Instr& ins : t_.blocks[block]) {
            if (ir::is_series(ins.op)) {
                vals_[ins.out] = gen().series(ins);
                continue;
            }
            const int tix = tab_.slot_table[ins.out];
            if (tix >= 0) {
                const IndexTable& it = tab_.index_tables[static_cast<std::size_t>(tix)];
                vals_[ins.out] = gen().indexed(it, idx_[it.series]);
                continue;
            }
            vals_[ins.out] = gen().operation(ins);
        }
    }

    // ---- the frame of a series loop ----
    // pre -> header (phis: i, the orbit point, the generator's own) -> the body and the stopping rules,
    // which branch to latch (next term) or exit.
    struct SeriesLoop {
        SeriesLoop(const ir::Instr& in, const ir::TapeSeries& se, const SeriesTables& sta,
                   llvm::Value* start_value)
            : ins(in), s(se), st(sta), infinite(se.data.end == ir::infinite_end),
              has_b(se.tail_b != ir::no_slot), start(se.data.start), last(sta.last), start_v(start_value) {}
        const ir::Instr& ins;
        const ir::TapeSeries& s;
        const SeriesTables& st;
        bool infinite, has_b;
        std::int64_t start, last;
        llvm::Value* start_v;
        llvm::BasicBlock *pre = nullptr, *header = nullptr, *latch = nullptr, *exit = nullptr;
        llvm::PHINode* i = nullptr;
        std::vector<V> state;      // the orbit point of this term (phis)
        std::vector<V> next_state; // and of the next one, all components from this term's point
        V term{};
        llvm::Value* idx = nullptr;     // i - start
        llvm::Value* first = nullptr;   // i == start
        llvm::Value* is_last = nullptr; // i == last
    };
    SeriesLoop series_loop(const ir::Instr& ins) {
        const ir::TapeSeries& s = t_.series[ins.series];
        return SeriesLoop(ins, s, tab_.series[ins.series],
                          b_.getInt64(static_cast<std::uint64_t>(s.data.start)));
    }
    // Enters the loop header: the phis of i and of the orbit point from `init` (one value per component).
    void open_series(SeriesLoop& L, const std::vector<V>& init) {
        L.pre = b_.GetInsertBlock();
        L.header = llvm::BasicBlock::Create(ctx_, "series", fn_);
        L.latch = llvm::BasicBlock::Create(ctx_, "series.next", fn_);
        L.exit = llvm::BasicBlock::Create(ctx_, "series.exit", fn_);
        b_.CreateBr(L.header);
        b_.SetInsertPoint(L.header);
        L.i = b_.CreatePHI(i64_, 2, "i");
        L.i->addIncoming(L.start_v, L.pre);
        for (std::size_t c = 0; c < L.s.state_slots.size(); ++c) {
            L.state.push_back(gen().carry(init[c], L.pre, L.s.state_slots[c]));
            vals_[L.s.state_slots[c]] = L.state.back();
        }
    }
    // After the generator's own phis: the index slot, the term's block, then the next orbit point, the
    // term and the tests on i.
    void series_body(SeriesLoop& L) {
        L.idx = b_.CreateSub(L.i, L.start_v, "idx");
        idx_[L.ins.series] = L.idx;
        vals_[L.s.index_slot] = gen().index_value(L);
        emit_block(L.s.block);
        for (std::size_t c = 0; c < L.s.state_slots.size(); ++c)
            L.next_state.push_back(vals_[L.s.update_slots[c]]);
        L.term = vals_[L.s.body_slot];
        L.first = b_.CreateICmpEQ(L.i, L.start_v);
        L.is_last = b_.CreateICmpEQ(L.i, b_.getInt64(static_cast<std::uint64_t>(L.last)));
    }
    // The latch (i + 1, the next orbit point) back to the header; continues at the exit.
    void close_series(SeriesLoop& L) {
        b_.SetInsertPoint(L.latch);
        L.i->addIncoming(b_.CreateAdd(L.i, b_.getInt64(1)), L.latch);
        for (std::size_t c = 0; c < L.state.size(); ++c)
            gen().carry_next(L.state[c], L.next_state[c], L.latch);
        b_.CreateBr(L.header);
        b_.SetInsertPoint(L.exit);
    }

    // ---- helpers ----
    // A private constant array of doubles (intervals are stored as lo, hi pairs), one per key.
    llvm::GlobalVariable* table(const void* key, const std::vector<double>& v, const char* what) {
        if (auto it = globals_.find(key); it != globals_.end()) return it->second;
        auto* init = llvm::ConstantDataArray::get(ctx_, llvm::ArrayRef<double>(v));
        auto* g = new llvm::GlobalVariable(m_, init->getType(), true, llvm::GlobalValue::PrivateLinkage, init,
                                           name_ + "." + what);
        g->setUnnamedAddr(llvm::GlobalValue::UnnamedAddr::Global);
        g->setAlignment(llvm::Align(16));
        return globals_[key] = g;
    }
    llvm::GlobalVariable* table(const void* key, const std::vector<Interval>& v, const char* what) {
        if (auto it = globals_.find(key); it != globals_.end()) return it->second;
        std::vector<double> flat;
        flat.reserve(2 * v.size());
        for (const Interval& x : v) {
            flat.push_back(x.lo);
            flat.push_back(x.hi);
        }
        llvm::GlobalVariable* g = table(&flat, flat, what); // a fresh key: the temporary's address
        globals_.erase(&flat);
        return globals_[key] = g;
    }
    // A function of the helpers (helpers.hpp), which throw nothing.
    // The address of the tape's external function k: from the module's getter where there is one
    // (compiled models, codegen.hpp), else as a constant: the JIT runs in the process that owns it (the
    // compiled code keeps the tape, hence the function, alive).
    llvm::Value* external_function(std::int64_t k) {
        if (llvm::Function* getter = m_.getFunction(external_getter(name_, k))) return b_.CreateCall(getter);
        const auto i = static_cast<std::size_t>(k);
        if (k < 0 || i >= t_.externals.size() || !t_.externals[i])
            throw std::logic_error("jit: external function #" + std::to_string(k) + " is not bound");
        return llvm::ConstantExpr::getIntToPtr(
            b_.getInt64(static_cast<std::uint64_t>(reinterpret_cast<std::uintptr_t>(t_.externals[i].get()))),
            ptr_);
    }
    llvm::FunctionCallee declare(const char* name, llvm::Type* ret, const std::vector<llvm::Type*>& args) {
        auto callee = m_.getOrInsertFunction(name, llvm::FunctionType::get(ret, args, false));
        llvm::cast<llvm::Function>(callee.getCallee())->setDoesNotThrow();
        return callee;
    }
    void add_stat(llvm::Value* stats, int field, llvm::Value* v) {
        llvm::Value* p = b_.CreateInBoundsGEP(i64_, stats, b_.getInt64(static_cast<std::uint64_t>(field)));
        b_.CreateStore(b_.CreateAdd(b_.CreateLoad(i64_, p), v), p);
    }
    void bump(llvm::Value* counter, llvm::Value* by) {
        b_.CreateStore(b_.CreateAdd(b_.CreateLoad(i64_, counter), by), counter);
    }

    const ir::Tape& t_;
    const ir::EvalOptions& o_;
    const Tables& tab_;
    llvm::Module& m_;
    llvm::LLVMContext& ctx_;
    std::string name_;
    llvm::IRBuilder<> b_;
    int w_; // points or boxes an iteration (lanes)
    llvm::Type *dbl_, *i64_, *i32_, *ptr_;
    llvm::StructType* pair_;
    llvm::Function* fn_ = nullptr;
    llvm::Value* terms_ = nullptr; // counters of ir::EvalStats
    llvm::Value* capped_ = nullptr;
    std::vector<V> vals_;           // by slot
    std::vector<llvm::Value*> idx_; // by series: i - start of the loop being emitted
    std::map<const void*, llvm::GlobalVariable*> globals_;
};

} // namespace frac::jit
