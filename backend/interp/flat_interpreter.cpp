#include "backend/interp/flat_interpreter.hpp"

#include "backend/interp/interpreter.hpp"
#include "ir/semantics.hpp"
#include "ir/specialize.hpp"

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <limits>
#include <stdexcept>

namespace frac::interp {

using ir::Interval;
using ir::Op;
using ir::Slot;

namespace {

struct FlatInstr {
    Slot out;
    std::array<Slot, 3> in; // operands; powi: in[1] holds the exponent
    Op op;
};

// What every tape pushed from one root shares: the slot numbering, constants and inputs.
struct FlatRoot {
    std::uint64_t id; // unique per root in the process: names the constants a register file holds
    int inputs;
    Slot num_slots;
    std::vector<ir::TapeConst> constants;
    std::vector<Slot> input_slots;
};

struct FlatCode {
    std::shared_ptr<const FlatRoot> root;
    std::vector<FlatInstr> code;
    Slot result = ir::no_slot;
    std::vector<std::uint32_t> partial; // instructions that may be undefined (div, sqrt, log, pow, powi)
    bool has_choices = false;
};

std::uint64_t next_id() {
    static std::atomic<std::uint64_t> counter{0};
    return ++counter;
}

bool is_partial(Op op) {
    return op == Op::Div || op == Op::Sqrt || op == Op::Log || op == Op::Pow || op == Op::PowI;
}

std::int64_t immediate(const FlatInstr& ins) {
    return ins.op == Op::PowI ? static_cast<std::int32_t>(ins.in[1]) : 0;
}

// A thread's registers and push scratch, shared by every flat evaluator that runs on the thread (one
// register file per root is enough: pushed tapes keep their root's slots).
struct ThreadFile {
    std::uint64_t box_root = 0, point_root = 0; // the roots whose constants the files hold
    std::vector<Interval> boxes;
    std::vector<double> points;
    std::uint64_t last_eval = 0; // the evaluator whose last eval_box values `boxes` holds
    // Push scratch: liveness by generation, slot aliases (the identity between pushes), emptiness
    // flags by slot (zero on constants: cleared per root), the choice taken per instruction.
    std::vector<std::uint32_t> live;
    std::uint32_t generation = 0;
    std::vector<Slot> remap;
    std::vector<std::uint8_t> may_empty;
    std::vector<std::uint8_t> pick;
    std::vector<Slot> aliased;

    Interval* boxes_of(const FlatRoot& root) {
        if (box_root != root.id) {
            if (boxes.size() < root.num_slots) boxes.resize(root.num_slots);
            for (const ir::TapeConst& c : root.constants) boxes[c.slot] = c.value;
            box_root = root.id;
            last_eval = 0;
            may_empty.assign(root.num_slots, 0);
        }
        return boxes.data();
    }
    double* points_of(const FlatRoot& root) {
        if (point_root != root.id) {
            if (points.size() < root.num_slots) points.resize(root.num_slots);
            for (const ir::TapeConst& c : root.constants) points[c.slot] = c.point;
            point_root = root.id;
        }
        return points.data();
    }
    std::uint32_t next_generation(Slot num_slots) {
        if (live.size() < num_slots) live.resize(num_slots, 0);
        if (++generation == 0) { // wrapped: forget every mark
            std::fill(live.begin(), live.end(), 0);
            generation = 1;
        }
        if (remap.size() < num_slots) {
            const std::size_t from = remap.size();
            remap.resize(num_slots);
            for (std::size_t s = from; s < num_slots; ++s) remap[s] = static_cast<Slot>(s);
        }
        return generation;
    }
};

ThreadFile& thread_file() {
    thread_local ThreadFile file;
    return file;
}

double elapsed_ms(std::chrono::steady_clock::time_point since) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since).count();
}

class FlatInterpreter final : public ir::Evaluator {
public:
    FlatInterpreter(std::shared_ptr<const FlatCode> code, const ir::EvalOptions& options)
        : code_(std::move(code)), options_(options), id_(next_id()) {}

    int dimension() const override { return code_->root->inputs; }
    std::string engine() const override { return "interp"; }
    std::unique_ptr<ir::Evaluator> clone() const override {
        return std::make_unique<FlatInterpreter>(code_, options_);
    }
    std::size_t instruction_count() const override { return code_->code.size(); }

    double eval_point(const double* coords) override {
        ++stats.calls;
        double* r = thread_file().points_of(*code_->root);
        load(r, coords);
        for (const FlatInstr& ins : code_->code) {
            double args[3];
            for (int i = 0; i < ir::arity(ins.op); ++i) args[i] = r[ins.in[static_cast<std::size_t>(i)]];
            r[ins.out] = ir::apply_point(ins.op, args, immediate(ins));
        }
        return r[code_->result];
    }

    Interval eval_box(const Interval* box) override {
        num::UpwardRounding up;
        return run_box(box);
    }

    void eval_boxes(const Interval* boxes, std::size_t n, Interval* out) override {
        num::UpwardRounding up; // once per batch
        const auto d = static_cast<std::size_t>(code_->root->inputs);
        for (std::size_t i = 0; i < n; ++i) out[i] = run_box(boxes + i * d);
    }

    bool may_specialize() const override { return options_.prune && code_->has_choices; }
    bool specializes_independently() const override { return true; } // a tape push, no cache
    std::shared_ptr<ir::Evaluator> specialize(const Interval* box, double expected_evaluations) override {
        return push(box, expected_evaluations, false);
    }
    std::shared_ptr<ir::Evaluator> specialize_after_eval(const Interval* box,
                                                         double expected_evaluations) override {
        return push(box, expected_evaluations, true);
    }

private:
    template <class V>
    void load(V* r, const V* inputs) const {
        const std::vector<Slot>& slots = code_->root->input_slots;
        for (std::size_t k = 0; k < slots.size(); ++k)
            if (slots[k] != ir::no_slot) r[slots[k]] = inputs[k];
    }

    // One box, upward rounding already set.
    Interval run_box(const Interval* box) {
        ++stats.calls;
        ThreadFile& file = thread_file();
        Interval* r = file.boxes_of(*code_->root);
        load(r, box);
        for (const FlatInstr& ins : code_->code) {
            const Interval a = r[ins.in[0]];
            Interval& out = r[ins.out];
            switch (ins.op) {
            case Op::Add: out = num::add(a, r[ins.in[1]]); break;
            case Op::Sub: out = num::sub(a, r[ins.in[1]]); break;
            case Op::Mul: out = num::mul(a, r[ins.in[1]]); break;
            case Op::Neg: out = num::neg(a); break;
            case Op::Sqr: out = num::sqr(a); break;
            case Op::Sqrt: out = num::sqrt(a); break;
            case Op::Abs: out = num::abs(a); break;
            case Op::Min: out = num::min(a, r[ins.in[1]]); break;
            case Op::Max: out = num::max(a, r[ins.in[1]]); break;
            case Op::PowI: out = num::powi(a, immediate(ins)); break;
            default: {
                Interval args[3];
                for (int i = 0; i < ir::arity(ins.op); ++i) args[i] = r[ins.in[static_cast<std::size_t>(i)]];
                out = ir::apply_interval(ins.op, args, 0);
            }
            }
        }
        file.last_eval = id_;
        return r[code_->result];
    }

    static bool defined(const FlatInstr& ins, const Interval* r) {
        const Interval a = r[ins.in[0]];
        return ir::defined_over_box(ins.op, a, ir::arity(ins.op) > 1 ? r[ins.in[1]] : a, immediate(ins));
    }

    // Marks in file.may_empty the slots whose enclosure can become empty on a sub-box (the
    // reference's emptiness analysis, on values alone: every slot of a flat tape has one). False,
    // without a pass, when none can: every partial operation is defined over the box.
    bool mark_may_empty(ThreadFile& file, const Interval* r) const {
        const FlatCode& c = *code_;
        bool any = false;
        for (Slot s : c.root->input_slots) any |= s != ir::no_slot && r[s].is_empty();
        for (std::size_t k = 0; k < c.partial.size() && !any; ++k) {
            const FlatInstr& ins = c.code[c.partial[k]];
            any = !defined(ins, r);
        }
        if (!any) return false;
        for (Slot s : c.root->input_slots)
            if (s != ir::no_slot) file.may_empty[s] = r[s].is_empty();
        for (const FlatInstr& ins : c.code) {
            bool empty = false;
            for (int i = 0; i < ir::arity(ins.op); ++i) empty |= file.may_empty[ins.in[static_cast<std::size_t>(i)]] != 0;
            if (!empty && is_partial(ins.op)) empty = !defined(ins, r);
            file.may_empty[ins.out] = empty;
        }
        return true;
    }

    // A tape push: the pruned tape of the box, for this cell's descendants alone. `evaluated`: the
    // thread's register file holds the box's values (checked: else it is evaluated again).
    std::shared_ptr<ir::Evaluator> push(const Interval* box, double expected_evaluations, bool evaluated) {
        const FlatCode& c = *code_;
        if (!options_.prune || !c.has_choices || expected_evaluations <= interp_min_expected_evaluations)
            return nullptr;
        const auto t0 = std::chrono::steady_clock::now();
        ThreadFile& file = thread_file();
        if (!evaluated || file.last_eval != id_) {
            const ir::EvalStats saved = stats;
            eval_box(box);
            stats = saved; // a recording is not an evaluation of the shape
        }
        const Interval* r = file.boxes.data();
        const bool empties = mark_may_empty(file, r);
        const auto t1 = std::chrono::steady_clock::now();
        specialize_stats.record_ms += std::chrono::duration<double, std::milli>(t1 - t0).count();
        ++specialize_stats.requests;

        // Backward: the choices of the live code, and what stays live.
        const std::uint32_t gen = file.next_generation(c.root->num_slots);
        if (file.pick.size() < c.code.size()) file.pick.resize(c.code.size());
        std::uint32_t* live = file.live.data();
        live[c.result] = gen;
        std::size_t kept = 0;
        bool decided = false;
        for (std::size_t k = c.code.size(); k-- > 0;) {
            const FlatInstr& ins = c.code[k];
            if (live[ins.out] != gen) continue;
            std::uint8_t pick = 0;
            if (ir::is_choice(ins.op)) {
                const ir::Choice choice =
                    ir::decide_choice(ins.op, r[ins.in[0]], r[ins.in[1]], empties && file.may_empty[ins.in[0]],
                                      empties && file.may_empty[ins.in[1]]);
                if (choice != ir::Choice::both)
                    pick = static_cast<std::uint8_t>(1 + (ins.op == Op::Select ? 1 : 0) +
                                                     (choice == ir::Choice::second ? 1 : 0));
            }
            file.pick[k] = pick;
            if (pick) {
                live[ins.in[pick - 1u]] = gen;
                decided = true;
                continue;
            }
            ++kept;
            for (int i = 0; i < ir::arity(ins.op); ++i) live[ins.in[static_cast<std::size_t>(i)]] = gen;
        }
        if (!decided) {
            ++specialize_stats.unpruned;
            specialize_stats.prune_ms += elapsed_ms(t1);
            return nullptr;
        }
        if (static_cast<double>(kept) > ir::push_max_cost(static_cast<double>(c.code.size()), expected_evaluations)) {
            ++specialize_stats.too_little;
            specialize_stats.prune_ms += elapsed_ms(t1);
            return nullptr;
        }

        // Forward: the live code, each chosen operand in place of its choice.
        auto pruned = std::make_shared<FlatCode>();
        pruned->root = c.root;
        pruned->code.reserve(kept);
        file.aliased.clear();
        Slot* remap = file.remap.data();
        for (std::size_t k = 0; k < c.code.size(); ++k) {
            const FlatInstr& ins = c.code[k];
            if (live[ins.out] != gen) continue;
            if (const std::uint8_t pick = file.pick[k]) {
                remap[ins.out] = remap[ins.in[pick - 1u]];
                file.aliased.push_back(ins.out);
                continue;
            }
            FlatInstr n = ins;
            for (int i = 0; i < ir::arity(ins.op); ++i)
                n.in[static_cast<std::size_t>(i)] = remap[ins.in[static_cast<std::size_t>(i)]];
            if (is_partial(ins.op)) pruned->partial.push_back(static_cast<std::uint32_t>(pruned->code.size()));
            pruned->has_choices |= ir::is_choice(ins.op);
            pruned->code.push_back(n);
        }
        pruned->result = remap[c.result];
        for (Slot s : file.aliased) remap[s] = s;
        ++specialize_stats.pushes;
        specialize_stats.prune_ms += elapsed_ms(t1);
        return std::make_shared<FlatInterpreter>(std::move(pruned), options_);
    }

    std::shared_ptr<const FlatCode> code_;
    ir::EvalOptions options_;
    std::uint64_t id_; // names this evaluator's values in the thread's register file
};

} // namespace

bool runs_flat(const ir::Tape& tape) {
    if (tape.blocks.size() != 1 || !tape.series.empty()) return false;
    for (const ir::Instr& ins : tape.blocks[0]) {
        if (ins.op == Op::External || ir::is_series(ins.op)) return false;
        if (ins.op == Op::PowI && (ins.imm < std::numeric_limits<std::int32_t>::min() ||
                                   ins.imm > std::numeric_limits<std::int32_t>::max()))
            return false;
    }
    return true;
}

std::unique_ptr<ir::Evaluator> make_flat_interpreter(const ir::Tape& tape, const ir::EvalOptions& options) {
    if (!runs_flat(tape)) throw std::logic_error("make_flat_interpreter: the tape is not flat");
    if (options.max_terms < 1 || options.max_terms > ir::max_terms_limit)
        throw std::invalid_argument("max_terms out of range");
    auto root = std::make_shared<FlatRoot>();
    root->id = next_id();
    root->inputs = tape.inputs;
    root->num_slots = tape.num_slots;
    root->constants = tape.constants;
    root->input_slots = tape.input_slots;
    auto code = std::make_shared<FlatCode>();
    code->root = root;
    code->result = tape.result;
    code->code.reserve(tape.blocks[0].size());
    for (const ir::Instr& ins : tape.blocks[0]) {
        FlatInstr n{ins.out, ins.in, ins.op};
        if (ins.op == Op::PowI) n.in[1] = static_cast<Slot>(static_cast<std::int32_t>(ins.imm));
        if (is_partial(ins.op)) code->partial.push_back(static_cast<std::uint32_t>(code->code.size()));
        code->has_choices |= ir::is_choice(ins.op);
        code->code.push_back(n);
    }
    return std::make_unique<FlatInterpreter>(std::move(code), options);
}

} // namespace frac::interp
