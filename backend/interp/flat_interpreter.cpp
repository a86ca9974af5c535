#include "backend/interp/flat_interpreter.hpp"

#include "backend/interp/interpreter.hpp"
#include "backend/interp/lane_kernels.hpp"
#include "ir/semantics.hpp"
#include "ir/specialize.hpp"
#include "numeric/interval_kernels.hpp"

#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>

namespace frac::interp {

using ir::Interval;
using ir::Op;
using ir::Slot;

namespace {

// The operations run_box has a handler of its own for (the others go through ir::apply_interval).
enum class Handler : std::uint8_t { add, sub, mul, neg, sqr, sqrt, abs, min, max, powi, other };

Handler handler_of(Op op) {
    switch (op) {
    case Op::Add: return Handler::add;
    case Op::Sub: return Handler::sub;
    case Op::Mul: return Handler::mul;
    case Op::Neg: return Handler::neg;
    case Op::Sqr: return Handler::sqr;
    case Op::Sqrt: return Handler::sqrt;
    case Op::Abs: return Handler::abs;
    case Op::Min: return Handler::min;
    case Op::Max: return Handler::max;
    case Op::PowI: return Handler::powi;
    default: return Handler::other;
    }
}

// Names of tapes and evaluators, unique in the process.
std::uint64_t next_id() {
    static std::atomic<std::uint64_t> counter{0};
    return ++counter;
}

// Instruction k of a flat tape writes slot first_result() + k (FlatCode): no result field, 16 bytes.
struct FlatInstr {
    std::array<Slot, 3> in; // operands; powi: in[1] holds the exponent
    Op op;
    Handler handler;
};
static_assert(sizeof(FlatInstr) == 16);

bool is_partial(Op op) {
    return op == Op::Div || op == Op::Sqrt || op == Op::Log || op == Op::Pow || op == Op::PowI;
}

// A flat tape in dense slots: its constants (slots 0 .. constants.size() - 1), then input k at
// first_input() + k, then the instructions' results in program order, so the registers of a pushed
// tape are a few cache lines. One allocation holds its arrays.
struct FlatCode {
    std::uint64_t id = 0; // unique in the process: names the constants a register file holds
    int inputs = 0;
    Slot num_slots = 0;
    Slot result = ir::no_slot;
    bool has_choices = false;
    std::span<Interval> constants;
    std::span<double> constant_points;
    std::span<FlatInstr> code;
    std::span<std::uint32_t> partial; // instructions that may be undefined (div, sqrt, log, pow, powi)

    Slot constant_count() const { return static_cast<Slot>(constants.size()); }
    Slot first_input() const { return constant_count(); }
    // Notes what instruction k, once written, means for pushes: a partial operation, a choice
    // (instructions are noted in order).
    void note_instruction(std::size_t k) {
        if (is_partial(code[k].op)) partial[partial_noted++] = static_cast<std::uint32_t>(k);
        has_choices |= ir::is_choice(code[k].op);
    }
    Slot first_result() const { return constant_count() + static_cast<Slot>(inputs); }

    static std::shared_ptr<FlatCode> make(int inputs, std::size_t constants, std::size_t instructions,
                                          std::size_t partial) {
        auto c = std::make_shared<FlatCode>();
        c->id = next_id();
        c->inputs = inputs;
        c->num_slots = static_cast<Slot>(constants + static_cast<std::size_t>(inputs) + instructions);
        // Widest alignment first: intervals and doubles, then instructions and indices (4 bytes).
        const std::size_t bytes = constants * (sizeof(Interval) + sizeof(double)) +
                                  instructions * sizeof(FlatInstr) + partial * sizeof(std::uint32_t);
        c->storage_ = std::make_unique_for_overwrite<std::byte[]>(bytes); // every byte is written
        std::byte* p = c->storage_.get();
        const auto take = [&p]<class T>(std::size_t n, T*) {
            std::span<T> s(reinterpret_cast<T*>(p), n);
            p += n * sizeof(T);
            return s;
        };
        c->constants = take(constants, static_cast<Interval*>(nullptr));
        c->constant_points = take(constants, static_cast<double*>(nullptr));
        c->code = take(instructions, static_cast<FlatInstr*>(nullptr));
        c->partial = take(partial, static_cast<std::uint32_t*>(nullptr));
        return c;
    }

private:
    std::size_t partial_noted = 0;
    std::unique_ptr<std::byte[]> storage_;
};

std::int64_t immediate(const FlatInstr& ins) {
    return ins.op == Op::PowI ? static_cast<std::int32_t>(ins.in[1]) : 0;
}

// Boxes one evaluation runs side by side: each instruction is dispatched once for all of them, and
// their operations are independent (a cover's sibling cells share their parent's tape).
inline constexpr std::size_t lanes = 4;

// A register file of `L` boxes side by side: slot s holds its L lower bounds, then its L upper bounds,
// at values[s * 2L ...] (one cache line for four boxes, vectors of bounds for lane_kernels); `code` names
// the tape whose constants it holds.
struct RegisterFile {
    struct alignas(64) Line {
        double v[8];
    };
    std::uint64_t code = 0;
    std::vector<Line> lines;

    double* of(const FlatCode& c, std::size_t L) {
        if (code != c.id) {
            const std::size_t doubles = c.num_slots * 2 * L;
            if (lines.size() * 8 < doubles) lines.resize((doubles + 7) / 8);
            double* r = lines.data()->v;
            for (std::size_t s = 0; s < c.constants.size(); ++s) {
                std::fill_n(r + s * 2 * L, L, c.constants[s].lo);
                std::fill_n(r + s * 2 * L + L, L, c.constants[s].hi);
            }
            code = c.id;
        }
        return lines.data()->v;
    }
};

// The values of one box of the last evaluation: its lane of a register file.
struct BoxValues {
    const double* base;
    std::size_t lanes, lane;
    Interval operator[](Slot s) const {
        return {base[s * 2 * lanes + lane], base[s * 2 * lanes + lanes + lane]};
    }
};

// What the push analysis found for one lane of a box evaluation (FlatInterpreter::analyse).
struct LanePush {
    bool decided = false;                // a choice was decided
    bool too_long = false;               // the pruned code costs more than the rule allows
    std::uint32_t kept = 0;              // instructions the pruned code keeps
    std::uint32_t partial = 0;           // ... that may be undefined
    std::vector<std::uint32_t> reversed; // the pruned code in reverse (ThreadFile::pushes)
    std::weak_ptr<ir::Evaluator> built;  // the evaluator of the pruned tape, once built
};

// A thread's registers and push scratch, shared by every flat evaluator that runs on the thread.
struct ThreadFile {
    RegisterFile single, side_by_side; // one box; `lanes` boxes
    std::uint64_t point_code = 0;      // the tape whose constants `points` holds
    std::vector<double> points;
    // The last box evaluation: the evaluator, its register file and how many boxes it ran.
    std::uint64_t last_eval = 0;
    const RegisterFile* last_file = nullptr;
    std::size_t last_first = 0, last_count = 0; // the boxes first .. first + count - 1 of its batch
    std::uint64_t evaluations = 0;              // box evaluations on this thread: names the last one
    // The push analysis of the last box evaluation (analyse): which evaluation, for how many
    // expected evaluations; by parent slot, the lanes whose pruned tape reads it and the lanes where
    // it may be empty (when mark_may_empty found any); by lane, its outcome and its pruned code in
    // reverse, each entry the parent instruction's index << 2, | 0 to keep it or | 1 + the operand a
    // decided choice takes. final_slot: by parent slot, its slot in the tape being built.
    std::uint64_t analysed = 0;
    double analysed_expected = 0;
    std::vector<std::uint8_t> lane_live, lane_empty;
    std::vector<std::uint32_t> final_slot;
    std::array<LanePush, lanes> pushes;

    double* points_of(const FlatCode& c) {
        if (point_code != c.id) {
            if (points.size() < c.num_slots) points.resize(c.num_slots);
            std::copy(c.constant_points.begin(), c.constant_points.end(), points.begin());
            point_code = c.id;
        }
        return points.data();
    }
    // Sizes the push scratch for pushes from c.
    void prepare_push(const FlatCode& c) {
        if (lane_live.size() < c.num_slots) {
            lane_live.resize(c.num_slots);
            lane_empty.resize(c.num_slots);
            final_slot.resize(c.num_slots);
        }
    }
};

ThreadFile& thread_file() {
    thread_local ThreadFile file;
    return file;
}

// Instruction `ins` on each of the L boxes of register file r, by the reference's operations (powi and
// the operations without a handler). Out of line: compiled for any CPU, called from every loop.
[[gnu::noinline]] void apply_by_lane(const FlatInstr& ins, Slot out_slot, double* r, std::size_t L) {
    for (std::size_t j = 0; j < L; ++j) {
        const BoxValues v{r, L, j};
        Interval args[3];
        for (int i = 0; i < ir::arity(ins.op); ++i) args[i] = v[ins.in[static_cast<std::size_t>(i)]];
        const Interval out =
            ins.op == Op::PowI ? num::powi(args[0], immediate(ins)) : ir::apply_interval(ins.op, args, 0);
        r[out_slot * 2 * L + j] = out.lo;
        r[out_slot * 2 * L + L + j] = out.hi;
    }
}

std::atomic<bool> vector_lanes_wanted{true};

// Whether four boxes run on lane_kernels: asked for, and this CPU has them.
bool vector_lanes() {
#ifdef FRAC_LANE_KERNELS
    static const bool supported = lane_kernels::supported();
    return supported && vector_lanes_wanted.load(std::memory_order_relaxed);
#else
    return false;
#endif
}

// The operations with a handler of their own and a kernel (dispatch's labels).
#define FRAC_LANE_OPERATIONS(UNARY, BINARY)                                                                  \
    BINARY(add) BINARY(sub) BINARY(mul) UNARY(neg) UNARY(sqr) UNARY(sqrt) UNARY(abs) BINARY(min) BINARY(max)

// The scalar kernels, lane by lane.
template <std::size_t L>
struct ScalarLanes {
    static constexpr std::size_t lanes = L;
    using Value = std::array<Interval, L>;
    static Value load(const double* r, Slot s) {
        Value v;
        for (std::size_t j = 0; j < L; ++j) v[j] = {r[s * 2 * L + j], r[s * 2 * L + L + j]};
        return v;
    }
    static void store(double* r, Slot s, const Value& v) {
        for (std::size_t j = 0; j < L; ++j) {
            r[s * 2 * L + j] = v[j].lo;
            r[s * 2 * L + L + j] = v[j].hi;
        }
    }
#define FRAC_UNARY(name)                                                                                     \
    static Value name(const Value& a) {                                                                      \
        Value v;                                                                                             \
        for (std::size_t j = 0; j < L; ++j) v[j] = num::kernels::name(a[j]);                                 \
        return v;                                                                                            \
    }
#define FRAC_BINARY(name)                                                                                    \
    static Value name(const Value& a, const Value& b) {                                                      \
        Value v;                                                                                             \
        for (std::size_t j = 0; j < L; ++j) v[j] = num::kernels::name(a[j], b[j]);                           \
        return v;                                                                                            \
    }
    FRAC_LANE_OPERATIONS(FRAC_UNARY, FRAC_BINARY)
#undef FRAC_UNARY
#undef FRAC_BINARY
};

// The loop, compiled for any CPU.
#include "backend/interp/flat_dispatch.inc"

template <std::size_t L>
void run_lanes(const FlatCode& c, double* r) {
    dispatch<ScalarLanes<L>>(c, r);
}

#ifdef FRAC_LANE_KERNELS
// lane_kernels on the four lower and four upper bounds of a slot.
struct QuadLanes {
    static constexpr std::size_t lanes = 4;
    using Value = lane_kernels::Quad;
#define FRAC_QUAD_TARGET __attribute__((target("avx2,fma"), always_inline)) static
    FRAC_QUAD_TARGET Value load(const double* r, Slot s) {
        return {_mm256_load_pd(r + s * 8), _mm256_load_pd(r + s * 8 + 4)};
    }
    FRAC_QUAD_TARGET void store(double* r, Slot s, const Value& v) {
        _mm256_store_pd(r + s * 8, v.lo);
        _mm256_store_pd(r + s * 8 + 4, v.hi);
    }
#define FRAC_UNARY(name)                                                                                     \
    FRAC_QUAD_TARGET Value name(const Value& a) {                                                            \
        return lane_kernels::name(a);                                                                        \
    }
#define FRAC_BINARY(name)                                                                                    \
    FRAC_QUAD_TARGET Value name(const Value& a, const Value& b) {                                            \
        return lane_kernels::name(a, b);                                                                     \
    }
    FRAC_LANE_OPERATIONS(FRAC_UNARY, FRAC_BINARY)
#undef FRAC_UNARY
#undef FRAC_BINARY
#undef FRAC_QUAD_TARGET
};
static_assert(QuadLanes::lanes == lanes);

// The loop again, compiled for AVX2 and FMA (a function cannot take its target from a template
// argument, and GCC inlines no function with a computed goto).
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2,fma"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2,fma")
#endif
namespace avx2 {
#include "backend/interp/flat_dispatch.inc"
} // namespace avx2
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif

void run_quads(const FlatCode& c, double* r) {
    avx2::dispatch<QuadLanes>(c, r);
}
#endif
#undef FRAC_LANE_OPERATIONS

double elapsed_ms(std::chrono::steady_clock::time_point since) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since).count();
}

class FlatInterpreter final : public ir::Evaluator {
public:
    FlatInterpreter(std::shared_ptr<const FlatCode> code, const ir::EvalOptions& options)
        : code_(std::move(code)), options_(options), id_(next_id()) {}

    int dimension() const override { return code_->inputs; }
    std::string engine() const override { return "interp"; }
    std::unique_ptr<ir::Evaluator> clone() const override {
        return std::make_unique<FlatInterpreter>(code_, options_);
    }
    std::size_t instruction_count() const override { return code_->code.size(); }

    double eval_point(const double* coords) override {
        ++stats.calls;
        double* r = thread_file().points_of(*code_);
        std::copy_n(coords, code_->inputs, r + code_->first_input());
        Slot out = code_->first_result();
        for (const FlatInstr& ins : code_->code) {
            double args[3];
            for (int i = 0; i < ir::arity(ins.op); ++i) args[i] = r[ins.in[static_cast<std::size_t>(i)]];
            r[out++] = ir::apply_point(ins.op, args, immediate(ins));
        }
        return r[code_->result];
    }

    Interval eval_box(const Interval* box) override {
        num::UpwardRounding up;
        Interval out;
        run<1>(box, 1, &out);
        return out;
    }

    void eval_boxes(const Interval* boxes, std::size_t n, Interval* out) override {
        num::UpwardRounding up; // once per batch
        const auto d = static_cast<std::size_t>(code_->inputs);
        std::size_t k = 0;
        for (; k < n; k += lanes) {
            if (n - k == 1)
                run<1>(boxes + k * d, 1, out + k);
            else
                run<lanes>(boxes + k * d, std::min(lanes, n - k), out + k);
            thread_file().last_first = k;
        }
    }

    bool may_specialize() const override { return options_.prune && code_->has_choices; }
    bool specializes_independently() const override { return true; } // a tape push, no cache
    std::size_t kept_evaluations() const override { return lanes; }
    std::shared_ptr<ir::Evaluator> specialize(const Interval* box, double expected_evaluations) override {
        return push(box, std::numeric_limits<std::size_t>::max(), expected_evaluations);
    }
    std::shared_ptr<ir::Evaluator> specialize_after_eval(std::size_t k, const Interval* box,
                                                         double expected_evaluations) override {
        return push(box, k, expected_evaluations);
    }

private:
    // Evaluates n <= L boxes side by side (upward rounding set) into out. Lanes past n repeat box 0.
    template <std::size_t L>
    void run(const Interval* boxes, std::size_t n, Interval* out) {
        stats.calls += n;
        ThreadFile& file = thread_file();
        RegisterFile& regs = L == 1 ? file.single : file.side_by_side;
        double* const r = regs.of(*code_, L);
        const auto d = static_cast<std::size_t>(code_->inputs);
        double* const in = r + code_->first_input() * 2 * L;
        for (std::size_t k = 0; k < d; ++k)
            for (std::size_t j = 0; j < L; ++j) {
                const Interval& x = boxes[(j < n ? j : 0) * d + k];
                in[k * 2 * L + j] = x.lo;
                in[k * 2 * L + L + j] = x.hi;
            }
#ifdef FRAC_LANE_KERNELS
        if (L == lanes && vector_lanes())
            run_quads(*code_, r);
        else
#endif
            run_lanes<L>(*code_, r);
        for (std::size_t j = 0; j < n; ++j) out[j] = BoxValues{r, L, j}[code_->result];
        file.last_eval = id_;
        file.last_file = &regs;
        file.last_first = 0;
        file.last_count = n;
        ++file.evaluations;
    }

    static bool defined(const FlatInstr& ins, const BoxValues& r) {
        const Interval a = r[ins.in[0]];
        return ir::defined_over_box(ins.op, a, ir::arity(ins.op) > 1 ? r[ins.in[1]] : a, immediate(ins));
    }

    // Marks in file.lane_empty, per slot, the lanes where its enclosure can become empty on a sub-box
    // (the reference's emptiness analysis, on values alone: every slot of a flat tape has one), for the
    // lanes of `box`. No pass, and false, when it can nowhere: in every lane every input is non-empty
    // and every partial operation is defined.
    [[gnu::noinline]] bool mark_may_empty(ThreadFile& file, const BoxValues& box,
                                          unsigned lanes_of_box) const {
        const FlatCode& c = *code_;
        const auto lane = [&](unsigned j) { return BoxValues{box.base, box.lanes, j}; };
        const auto empty_inputs = [&](Slot s) {
            unsigned m = 0;
            for (unsigned j = 0; j < box.lanes; ++j)
                m |= (lanes_of_box >> j & 1) && lane(j)[s].is_empty() ? 1u << j : 0;
            return m;
        };
        const auto undefined = [&](const FlatInstr& ins, unsigned lanes_left) {
            unsigned m = 0;
            for (unsigned j = 0; j < box.lanes; ++j)
                if (lanes_left >> j & 1) m |= defined(ins, lane(j)) ? 0 : 1u << j;
            return m;
        };
        unsigned any = 0;
        for (Slot s = c.first_input(); s < c.first_result(); ++s) any |= empty_inputs(s);
        for (std::size_t k = 0; k < c.partial.size() && any != lanes_of_box; ++k)
            any |= undefined(c.code[c.partial[k]], lanes_of_box & ~any);
        if (!any) return false;
        std::uint8_t* const empty = file.lane_empty.data();
        std::fill_n(empty, c.constant_count(), 0);
        for (Slot s = c.first_input(); s < c.first_result(); ++s)
            empty[s] = static_cast<std::uint8_t>(empty_inputs(s));
        Slot out = c.first_result();
        for (const FlatInstr& ins : c.code) {
            unsigned m = 0;
            for (int i = 0; i < ir::arity(ins.op); ++i) m |= empty[ins.in[static_cast<std::size_t>(i)]];
            if (is_partial(ins.op)) m |= undefined(ins, any & ~m);
            empty[out++] = static_cast<std::uint8_t>(m);
        }
        return true;
    }

    // The push analysis of every box of the thread's last evaluation (this evaluator's) at once, so
    // the parent's code and registers are read once for all the siblings that push: one backward pass
    // over the live code, per lane deciding its choices from the registers (ir::decide_choice, the
    // emptiness rule ir::defined_over_box), marking the slots its pruned tape reads and writing its
    // pruned code in reverse; a lane stops as soon as its code costs more than push_max_cost.
    [[gnu::noinline]] void analyse(ThreadFile& file, double expected_evaluations) {
        const FlatCode& c = *code_;
        const std::size_t stride = file.last_file == &file.single ? 1 : lanes;
        const BoxValues box{file.last_file->lines.data()->v, stride, 0};
        const unsigned lanes_of_box = (1u << file.last_count) - 1;
        file.prepare_push(c);
        const bool empties = mark_may_empty(file, box, lanes_of_box);
        const std::uint8_t* const empty = file.lane_empty.data();
        std::uint8_t* const live = file.lane_live.data();
        std::fill_n(live, c.num_slots, 0);
        for (LanePush& p : file.pushes) {
            p.decided = p.too_long = false;
            p.kept = p.partial = 0;
            p.reversed.clear();
            p.built.reset();
        }
        const double max_cost = ir::push_max_cost(static_cast<double>(c.code.size()), expected_evaluations);
        unsigned active = lanes_of_box; // lanes still within max_cost
        live[c.result] = static_cast<std::uint8_t>(active);
        for (std::size_t i = c.code.size(); i-- > 0 && active;) {
            const FlatInstr& ins = c.code[i];
            unsigned m = live[c.first_result() + i] & active;
            if (!m) continue;
            const auto index = static_cast<std::uint32_t>(i) << 2;
            if (ir::is_choice(ins.op)) {
                for (unsigned rest = m; rest; rest &= rest - 1) {
                    const auto j = static_cast<unsigned>(std::countr_zero(rest));
                    const BoxValues r{box.base, stride, j};
                    const ir::Choice choice = ir::decide_choice(ins.op, r[ins.in[0]], r[ins.in[1]],
                                                                empties && (empty[ins.in[0]] >> j & 1),
                                                                empties && (empty[ins.in[1]] >> j & 1));
                    if (choice == ir::Choice::both) continue;
                    const std::uint32_t taken =
                        (ins.op == Op::Select ? 1 : 0) + (choice == ir::Choice::second ? 1 : 0);
                    LanePush& p = file.pushes[j];
                    p.decided = true;
                    p.reversed.push_back(index | (taken + 1));
                    live[ins.in[taken]] |= static_cast<std::uint8_t>(1u << j);
                    m &= ~(1u << j);
                }
                if (!m) continue;
            }
            for (unsigned rest = m; rest; rest &= rest - 1) {
                const auto j = static_cast<unsigned>(std::countr_zero(rest));
                LanePush& p = file.pushes[j];
                // Past the most it may cost, with a choice decided: too little pruned.
                if (p.decided && static_cast<double>(p.kept + 1) > max_cost) {
                    p.too_long = true;
                    active &= ~(1u << j);
                    m &= ~(1u << j);
                    continue;
                }
                p.reversed.push_back(index);
                ++p.kept;
                p.partial += is_partial(ins.op);
            }
            for (int a = 0; a < ir::arity(ins.op); ++a)
                live[ins.in[static_cast<std::size_t>(a)]] |= static_cast<std::uint8_t>(m);
        }
        for (LanePush& p : file.pushes) p.too_long |= static_cast<double>(p.kept) > max_cost;
        file.analysed = file.evaluations;
        file.analysed_expected = expected_evaluations;
    }

    // The pruned tape of lane j of the analysis: its code forward in dense slots (constants in the
    // parent's order, inputs, results in program order), a decided choice's result the slot of the
    // operand it takes.
    [[gnu::noinline]] std::shared_ptr<FlatCode> build(ThreadFile& file, unsigned j) const {
        const FlatCode& c = *code_;
        const LanePush& p = file.pushes[j];
        const std::uint8_t* const live = file.lane_live.data();
        std::uint32_t* const final_slot = file.final_slot.data();
        std::size_t constants = 0;
        for (Slot s = 0; s < c.first_input(); ++s) constants += live[s] >> j & 1;
        std::shared_ptr<FlatCode> pruned = FlatCode::make(c.inputs, constants, p.kept, p.partial);
        for (Slot s = 0, k = 0; s < c.first_input(); ++s) {
            if (!(live[s] >> j & 1)) continue;
            pruned->constants[k] = c.constants[s];
            pruned->constant_points[k] = c.constant_points[s];
            final_slot[s] = k++;
        }
        for (Slot s = c.first_input(); s < c.first_result(); ++s)
            final_slot[s] = pruned->first_input() + (s - c.first_input());
        Slot next = pruned->first_result();
        std::size_t k = 0;
        for (auto e = p.reversed.rbegin(); e != p.reversed.rend(); ++e) {
            const FlatInstr& ins = c.code[*e >> 2];
            const Slot out = c.first_result() + (*e >> 2);
            if (const std::uint32_t taken = *e & 3) {
                final_slot[out] = final_slot[ins.in[taken - 1]];
                continue;
            }
            FlatInstr& n = pruned->code[k];
            n = ins;
            for (int a = 0; a < ir::arity(ins.op); ++a)
                n.in[static_cast<std::size_t>(a)] = final_slot[ins.in[static_cast<std::size_t>(a)]];
            final_slot[out] = next++;
            pruned->note_instruction(k++);
        }
        pruned->result = final_slot[c.result];
        return pruned;
    }

    // A tape push: the pruned tape of the box, for this cell's descendants alone. The values are those
    // of box k of this evaluator's last evaluation (checked: else the box is evaluated again); the
    // analysis of that evaluation serves every box of it.
    std::shared_ptr<ir::Evaluator> push(const Interval* box, std::size_t k, double expected_evaluations) {
        const FlatCode& c = *code_;
        if (!options_.prune || !c.has_choices || expected_evaluations <= interp_min_expected_evaluations)
            return nullptr;
        const auto t0 = std::chrono::steady_clock::now();
        ThreadFile& file = thread_file();
        if (file.last_eval != id_ || k < file.last_first || k - file.last_first >= file.last_count) {
            const ir::EvalStats saved = stats;
            eval_box(box);
            stats = saved; // a recording is not an evaluation of the shape
            k = 0;
        }
        const auto lane = static_cast<unsigned>(k - file.last_first);
        if (file.analysed != file.evaluations || file.analysed_expected != expected_evaluations)
            analyse(file, expected_evaluations);
        const auto t1 = std::chrono::steady_clock::now();
        specialize_stats.record_ms += std::chrono::duration<double, std::milli>(t1 - t0).count();
        ++specialize_stats.requests;
        const LanePush& p = file.pushes[lane];
        if (p.too_long || !p.decided) {
            ++(p.decided ? specialize_stats.too_little : specialize_stats.unpruned);
            return nullptr;
        }
        // Siblings often decide every choice alike: a lane whose pruned code equals another's shares
        // its evaluator (one tape, one variant of the cover).
        for (const LanePush& other : file.pushes)
            if (&other != &p && other.reversed == p.reversed)
                if (std::shared_ptr<ir::Evaluator> shared = other.built.lock()) {
                    ++specialize_stats.hits;
                    specialize_stats.prune_ms += elapsed_ms(t1);
                    return shared;
                }
        auto pushed = std::make_shared<FlatInterpreter>(build(file, lane), options_);
        file.pushes[lane].built = pushed;
        ++specialize_stats.pushes;
        specialize_stats.prune_ms += elapsed_ms(t1);
        return pushed;
    }

    std::shared_ptr<const FlatCode> code_;
    ir::EvalOptions options_;
    std::uint64_t id_; // names this evaluator's values in the thread's register file
};

} // namespace

bool use_vector_lanes(bool wanted) {
    vector_lanes_wanted.store(wanted, std::memory_order_relaxed);
    return vector_lanes();
}

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
    // Dense slots: constants, inputs, then results in program order.
    const std::vector<ir::Instr>& instructions = tape.blocks[0];
    std::size_t partial = 0;
    for (const ir::Instr& ins : instructions) partial += is_partial(ins.op);
    std::shared_ptr<FlatCode> code =
        FlatCode::make(tape.inputs, tape.constants.size(), instructions.size(), partial);
    std::vector<Slot> renumber(tape.num_slots, ir::no_slot);
    for (std::size_t k = 0; k < tape.constants.size(); ++k) {
        renumber[tape.constants[k].slot] = static_cast<Slot>(k);
        code->constants[k] = tape.constants[k].value;
        code->constant_points[k] = tape.constants[k].point;
    }
    for (std::size_t k = 0; k < tape.input_slots.size(); ++k)
        if (tape.input_slots[k] != ir::no_slot)
            renumber[tape.input_slots[k]] = code->first_input() + static_cast<Slot>(k);
    const auto slot = [&](Slot s) {
        if (s >= renumber.size() || renumber[s] == ir::no_slot)
            throw std::logic_error("make_flat_interpreter: a slot is read before it is written");
        return renumber[s];
    };
    Slot next = code->first_result();
    for (std::size_t k = 0; k < instructions.size(); ++k) {
        const ir::Instr& ins = instructions[k];
        FlatInstr n{ins.in, ins.op, handler_of(ins.op)};
        for (int i = 0; i < ir::arity(ins.op); ++i)
            n.in[static_cast<std::size_t>(i)] = slot(ins.in[static_cast<std::size_t>(i)]);
        if (ins.op == Op::PowI) n.in[1] = static_cast<Slot>(static_cast<std::int32_t>(ins.imm));
        renumber[ins.out] = next++;
        code->code[k] = n;
        code->note_instruction(k);
    }
    code->result = slot(tape.result);
    return std::make_unique<FlatInterpreter>(std::move(code), options);
}

} // namespace frac::interp
