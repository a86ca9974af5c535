// The batch function of box code (the skeleton's hooks) and its series loops: a lane stops by the
// interpreter's rules (ir/series_tail.hpp), after which its partial result is frozen; the loop ends when no
// lane is active (see box_gen.hpp).
#include "backend/llvm/box_codegen.hpp"

#include "backend/llvm/box_gen.hpp"
#include "ir/series_tail.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <tuple>

namespace frac::jit::box {

// ---- the skeleton's hooks ----
void BoxGen::prepare(Function* f) {
    if (!avx512_) f->addFnAttr(llvm::Attribute::StrictFP);
}

void BoxGen::allocate() {
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
            llvm::ArrayType::get(dbl_, static_cast<std::uint64_t>(2 * ir::max_state_components * w_)), "ein");
        esc_n_ = aligned(llvm::ArrayType::get(i64_, static_cast<std::uint64_t>(w_)), "en");
        esc_out_ = aligned(llvm::ArrayType::get(dbl_, static_cast<std::uint64_t>(4 * w_)), "eout");
        esc_h_ = aligned(llvm::ArrayType::get(dbl_, static_cast<std::uint64_t>(w_)), "eh");
    }
    // The cells' parameters (CellArgs, codegen.hpp), loaded once when there are cells.
    Value* args = fn_->getArg(4);
    is_cells_ = b_.CreateICmpNE(args, llvm::ConstantPointerNull::get(llvm::cast<llvm::PointerType>(ptr_)));
    BasicBlock* from = b_.GetInsertBlock();
    BasicBlock* load = BasicBlock::Create(ctx_, "cells.args", fn_);
    BasicBlock* go = BasicBlock::Create(ctx_, "cells.go", fn_);
    b_.CreateCondBr(is_cells_, load, go);
    b_.SetInsertPoint(load);
    static_assert(offsetof(CellArgs, coords) == 3 * 8 && offsetof(CellArgs, stride) == 4 * 8 &&
                  offsetof(CellArgs, closed_inside) == 5 * 8 && sizeof(CellArgs) == 6 * 8);
    auto field = [&](Type* t, std::uint64_t k) {
        return b_.CreateLoad(t, b_.CreateInBoundsGEP(i64_, args, b_.getInt64(k)));
    };
    const auto d = static_cast<std::size_t>(std::min(t_.inputs, 3));
    std::vector<Value*> loaded;
    for (std::size_t a = 0; a < d; ++a) loaded.push_back(field(ptr_, a));
    loaded.push_back(field(ptr_, 3));
    loaded.push_back(field(i64_, 4));
    loaded.push_back(b_.CreateICmpNE(field(i64_, 5), b_.getInt64(0)));
    b_.CreateBr(go);
    b_.SetInsertPoint(go);
    auto merged = [&](Value* v) {
        llvm::PHINode* p = b_.CreatePHI(v->getType(), 2);
        p->addIncoming(llvm::Constant::getNullValue(v->getType()), from);
        p->addIncoming(v, load);
        return p;
    };
    for (std::size_t a = 0; a < d; ++a) cell_axis_[a] = merged(loaded[a]);
    cell_coords_ = merged(loaded[d]);
    cell_stride_ = merged(loaded[d + 1]);
    cell_closed_ = merged(loaded[d + 2]);
}

// One iteration per group of W boxes; lanes past the end repeat the last box and are not stored.
void BoxGen::load_inputs(Value* in, Value* n, Value* k) {
    first_box_ = b_.CreateMul(k, b_.getInt64(static_cast<std::uint64_t>(w_)));
    Value* last_box = b_.CreateSub(n, b_.getInt64(1));
    box_of_lane_.assign(static_cast<std::size_t>(w_), nullptr);
    for (int j = 0; j < w_; ++j) {
        Value* bj = b_.CreateAdd(first_box_, b_.getInt64(static_cast<std::uint64_t>(j)));
        box_of_lane_[static_cast<std::size_t>(j)] =
            j == 0 ? bj : b_.CreateSelect(b_.CreateICmpULT(bj, n), bj, last_box);
    }
    if (w_ == 1) {
        ctx_mask_ = b_.getTrue();
    } else {
        Value* lanes =
            b_.CreateAdd(b_.CreateVectorSplat(static_cast<unsigned>(w_), first_box_), lane_numbers());
        ctx_mask_ = b_.CreateICmpULT(lanes, b_.CreateVectorSplat(static_cast<unsigned>(w_), n));
    }
    lanes_mask_ = ctx_mask_;
    BasicBlock* boxes = BasicBlock::Create(ctx_, "load.boxes", fn_);
    BasicBlock* cells = BasicBlock::Create(ctx_, "load.cells", fn_);
    BasicBlock* join = BasicBlock::Create(ctx_, "load.join", fn_);
    b_.CreateCondBr(is_cells_, cells, boxes);
    const std::size_t inputs = t_.input_slots.size();
    std::vector<IV> from_boxes(inputs), from_cells(inputs);
    b_.SetInsertPoint(boxes);
    for (std::size_t j = 0; j < inputs; ++j)
        if (t_.input_slots[j] != ir::no_slot) from_boxes[j] = box_input(in, j);
    b_.CreateBr(join);
    b_.SetInsertPoint(cells);
    for (std::size_t j = 0; j < inputs; ++j)
        if (t_.input_slots[j] != ir::no_slot) from_cells[j] = cell_input(j);
    b_.CreateBr(join);
    b_.SetInsertPoint(join);
    for (std::size_t j = 0; j < inputs; ++j) {
        const Slot s = t_.input_slots[j];
        if (s == ir::no_slot) continue;
        SlotState& st = vals_[s];
        for (int half = 0; half < 2; ++half) {
            llvm::PHINode* p = b_.CreatePHI(vt_, 2, half ? "in.hi" : "in.lo");
            p->addIncoming(half ? from_boxes[j].hi : from_boxes[j].lo, boxes);
            p->addIncoming(half ? from_cells[j].hi : from_cells[j].lo, cells);
            (half ? st.v.hi : st.v.lo) = p;
        }
        st.f = tab_.slot_facts[s]; // not empty: boxes with an empty coordinate go to the interpreter
    }
}

IV BoxGen::box_input(Value* in, std::size_t j) {
    const auto d = static_cast<std::uint64_t>(t_.inputs);
    IV r;
    for (int half = 0; half < 2; ++half) {
        Value* v = w_ == 1 ? nullptr : static_cast<Value*>(llvm::PoisonValue::get(vt_));
        for (int l = 0; l < w_; ++l) {
            Value* at =
                b_.CreateAdd(b_.CreateMul(box_of_lane_[static_cast<std::size_t>(l)], b_.getInt64(2 * d)),
                             b_.getInt64(2 * j + static_cast<std::uint64_t>(half)));
            Value* x = b_.CreateLoad(dbl_, b_.CreateInBoundsGEP(dbl_, in, at));
            v = w_ == 1 ? x : b_.CreateInsertElement(v, x, b_.getInt64(static_cast<std::uint64_t>(l)));
        }
        (half ? r.hi : r.lo) = v;
    }
    return r;
}

// The cell's interval along axis j: entry coords[box * stride + j] of the axis's table. A tape of more
// than 3 inputs is never called with cells (a grid has at most 3 axes, and eval_cells checks that it
// has as many as the tape has inputs): its cell code is a placeholder.
IV BoxGen::cell_input(std::size_t j) {
    if (j >= 3) return {cst(0.0), cst(0.0)};
    IV r;
    if (w_ > 1) r = {llvm::PoisonValue::get(vt_), llvm::PoisonValue::get(vt_)};
    for (int l = 0; l < w_; ++l) {
        Value* at = b_.CreateAdd(b_.CreateMul(box_of_lane_[static_cast<std::size_t>(l)], cell_stride_),
                                 b_.getInt64(j));
        Value* c = b_.CreateZExt(b_.CreateLoad(i32_, b_.CreateInBoundsGEP(i32_, cell_coords_, at)), i64_);
        Value* entry = b_.CreateInBoundsGEP(dbl_, cell_axis_[j], b_.CreateMul(c, b_.getInt64(2)));
        Value* lo = b_.CreateLoad(dbl_, entry);
        Value* hi = b_.CreateLoad(dbl_, b_.CreateInBoundsGEP(dbl_, entry, b_.getInt64(1)));
        if (w_ == 1) return {lo, hi};
        r.lo = b_.CreateInsertElement(r.lo, lo, b_.getInt64(static_cast<std::uint64_t>(l)));
        r.hi = b_.CreateInsertElement(r.hi, hi, b_.getInt64(static_cast<std::uint64_t>(l)));
    }
    return r;
}

Value* BoxGen::verdict(const IV& r) {
    Type* bytes = w_ == 1 ? static_cast<Type*>(b_.getInt8Ty())
                          : llvm::FixedVectorType::get(b_.getInt8Ty(), static_cast<unsigned>(w_));
    auto as_byte = [&](ir::CellVerdict v) {
        return llvm::ConstantInt::get(bytes, static_cast<std::uint64_t>(v));
    };
    Value* inside = lor(lt(r.hi, cst(0.0)), land(splat(cell_closed_), le(r.hi, cst(0.0))));
    Value* v =
        sel(gt(r.lo, cst(0.0)), as_byte(ir::CellVerdict::outside), as_byte(ir::CellVerdict::undecided));
    v = sel(inside, as_byte(ir::CellVerdict::inside), v);
    v = sel(gt(r.lo, r.hi), as_byte(ir::CellVerdict::outside), v); // empty: f undefined on the box
    return sel(cmp(llvm::CmpInst::FCMP_UNO, r.lo, r.hi), as_byte(ir::CellVerdict::undecided), v);
}

void BoxGen::store_result(Value* out, Value* n, Value*) {
    const IV r = vals_[t_.result].v;
    BasicBlock* boxes = BasicBlock::Create(ctx_, "store.boxes", fn_);
    BasicBlock* cells = BasicBlock::Create(ctx_, "store.cells", fn_);
    BasicBlock* join = BasicBlock::Create(ctx_, "store.join", fn_);
    b_.CreateCondBr(is_cells_, cells, boxes);
    b_.SetInsertPoint(boxes);
    for (int l = 0; l < w_; ++l) {
        Value* bj = b_.CreateAdd(first_box_, b_.getInt64(static_cast<std::uint64_t>(l)));
        Value* at = b_.CreateInBoundsGEP(dbl_, out, b_.CreateMul(bj, b_.getInt64(2)));
        if (l > 0) at = b_.CreateSelect(b_.CreateICmpULT(bj, n), at, sink_);
        b_.CreateStore(lane(r.lo, l), at);
        b_.CreateStore(lane(r.hi, l), b_.CreateInBoundsGEP(dbl_, at, b_.getInt64(1)));
    }
    b_.CreateBr(join);
    b_.SetInsertPoint(cells);
    Value* at = b_.CreateInBoundsGEP(b_.getInt8Ty(), out, first_box_);
    if (w_ == 1)
        b_.CreateStore(verdict(r), at);
    else
        b_.CreateMaskedStore(verdict(r), at, llvm::Align(1), lanes_mask_);
    b_.CreateBr(join);
    b_.SetInsertPoint(join);
}

SlotState BoxGen::constant(const ir::TapeConst& c) {
    SlotState s;
    s.known = true;
    s.k = c.value;
    s.v = {cst(c.value.lo), cst(c.value.hi)};
    s.f = facts_of(&c.value, 1);
    return s;
}

SlotState BoxGen::indexed(const IndexTable& it, Value* idx) {
    return from_table(load_pair(table(&it.box, it.box, "index"), idx), it.facts);
}

SlotState BoxGen::operation(const Instr& ins) {
    SlotState r = emit_op(ins);
    r.f = tab_.slot_facts[ins.out];
    return r;
}

SlotState BoxGen::series(const Instr& ins) {
    SlotState r = emit_series(ins);
    r.f = tab_.slot_facts[ins.out];
    return r;
}

SlotState BoxGen::carry(const SlotState& init, BasicBlock* pre, Slot slot) {
    llvm::PHINode* lo = b_.CreatePHI(vt_, 2, "state.lo");
    llvm::PHINode* hi = b_.CreatePHI(vt_, 2, "state.hi");
    lo->addIncoming(init.v.lo, pre);
    hi->addIncoming(init.v.hi, pre);
    SlotState sc;
    sc.v = {lo, hi};
    sc.f = tab_.slot_facts[slot];
    return sc;
}

void BoxGen::carry_next(const SlotState& phis, const SlotState& next, BasicBlock* latch) {
    llvm::cast<llvm::PHINode>(phis.v.lo)->addIncoming(next.v.lo, latch);
    llvm::cast<llvm::PHINode>(phis.v.hi)->addIncoming(next.v.hi, latch);
}

SlotState BoxGen::index_value(const SeriesLoop& L) {
    const bool exact =
        std::max(std::fabs(static_cast<double>(L.start)), std::fabs(static_cast<double>(L.last))) < 0x1p52;
    return thin(splat(index_to_double(L.i, exact)));
}

SlotState BoxGen::emit_series(const Instr& ins) {
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
    // A min or max series starts from its identity, [+inf, +inf] or [-inf, -inf] (never empty, and
    // NaN is never a bound): combined with the first term it gives that term's bits, empty or not,
    // with no test for the first index in the loop. A sum starts from 0 and takes its first term as is
    // (0 + -0 would be +0).
    const bool from_identity = s.kind != Op::SeriesSum;
    const double identity = s.kind == Op::SeriesMin ? inf : -inf;
    acc_lo->addIncoming(cst(from_identity ? identity : 0.0), pre);
    acc_hi->addIncoming(cst(from_identity ? identity : 0.0), pre);
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
    SlotState nacc = comb;
    if (!from_identity) {
        Value* first = splat(L.first);
        nacc =
            result({sel(first, term.v.lo, comb.v.lo), sel(first, term.v.hi, comb.v.hi)}, term.f.maybe_empty);
    }
    // Lanes that stopped keep their partial result.
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

} // namespace frac::jit::box

namespace frac::jit {

void generate_box_functions(const ir::Tape& tape, const ir::EvalOptions& options, const Tables& tables,
                            llvm::Module& module, const std::string& name, Rounding rounding, int lanes,
                            GeneratedNames& names) {
    const std::string body_name = box::BoxGen(tape, options, tables, module, name, rounding, lanes)
                                      .run("_box.body", "boxes", true, llvm::GlobalValue::InternalLinkage);
    llvm::Function* body = module.getFunction(body_name);
    llvm::LLVMContext& ctx = module.getContext();
    auto* ptr = llvm::PointerType::get(ctx, 0);
    auto* i64 = llvm::Type::getInt64Ty(ctx);
    const std::vector<llvm::Type*> params{ptr, i64, ptr, ptr};
    auto* fty = llvm::FunctionType::get(llvm::Type::getVoidTy(ctx), params, false);
    // (in, n, out, stats) -> the body with the cells' parameters last (null for boxes).
    auto entry = [&](const char* suffix, bool cells) {
        llvm::Function* f =
            llvm::Function::Create(fty, llvm::GlobalValue::ExternalLinkage, name + suffix, module);
        f->setDoesNotThrow();
        const bool strict = rounding != Rounding::avx512; // box::BoxGen::prepare
        if (strict) f->addFnAttr(llvm::Attribute::StrictFP);
        llvm::IRBuilder<> b(llvm::BasicBlock::Create(ctx, "entry", f));
        llvm::Value* none = llvm::ConstantPointerNull::get(ptr);
        llvm::CallInst* call =
            cells ? b.CreateCall(body, {none, f->getArg(1), f->getArg(2), f->getArg(3), f->getArg(0)})
                  : b.CreateCall(body, {f->getArg(0), f->getArg(1), f->getArg(2), f->getArg(3), none});
        if (strict) call->addFnAttr(llvm::Attribute::StrictFP);
        b.CreateRetVoid();
        return f->getName().str();
    };
    names.box = entry("_box", false);
    names.cells = entry("_cells", true);
}

} // namespace frac::jit
