#include "backend/llvm/tiered.hpp"

#include "backend/interp/interpreter.hpp"

#include <pthread.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <iostream>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <type_traits>

namespace frac::jit {

namespace {

// A thin integer exponent makes the JIT's pow call the numeric core (powi), as the interpreter does.
// Which slots hold a thin integer wherever they are read: constants, series indices, and sums,
// differences, negations and products of those while their magnitude stays below 2^53 (where interval
// arithmetic on integers is exact, so the result stays thin). Slots are reused along the tape, so a
// slot counts only if every instruction that writes it makes such an integer; the bounds are iterated
// to a fixed point (a loop-carried slot whose bound keeps growing ends past 2^53, not integral).
std::vector<bool> integral_slots(const ir::Tape& tape) {
    constexpr double exact_limit = 9007199254740992.0; // 2^53
    constexpr double not_integral = std::numeric_limits<double>::infinity();
    // Per slot: -1 not written yet (by what the analysis has seen), else a bound on |value|, or
    // not_integral.
    std::vector<double> bound(tape.num_slots, -1.0);
    const auto join = [&](ir::Slot slot, double b) {
        double& cur = bound[slot];
        const double next = b > exact_limit ? not_integral : std::max(cur, b);
        const bool changed = next != cur;
        cur = next;
        return changed;
    };
    for (const ir::TapeConst& c : tape.constants)
        join(c.slot, c.value.lo == c.value.hi && std::floor(c.value.lo) == c.value.lo ? std::fabs(c.value.lo)
                                                                                      : not_integral);
    for (const ir::TapeSeries& series : tape.series)
        if (series.index_slot != ir::no_slot)
            join(series.index_slot, series.data.end == ir::infinite_end
                                        ? static_cast<double>(series.data.start) + ir::max_terms_limit
                                        : static_cast<double>(std::max(std::llabs(series.data.start),
                                                                       std::llabs(series.data.end))));
    for (const ir::Slot input : tape.input_slots)
        if (input != ir::no_slot) join(input, not_integral);
    for (const ir::TapeSeries& series : tape.series)
        for (const ir::Slot state : series.state_slots) join(state, not_integral);
    bool changed = true;
    for (int pass = 0; changed; ++pass) {
        changed = false;
        for (const auto& block : tape.blocks)
            for (const ir::Instr& ins : block) {
                if (ins.out == ir::no_slot) continue;
                double b = not_integral;
                const auto arg = [&](int k) { return bound[ins.in[static_cast<std::size_t>(k)]]; };
                switch (ins.op) {
                case ir::Op::Add:
                case ir::Op::Sub:
                    if (arg(0) >= 0 && arg(1) >= 0)
                        b = arg(0) + arg(1);
                    else if (arg(0) < 0 || arg(1) < 0)
                        continue; // an operand not seen yet
                    break;
                case ir::Op::Mul:
                    if (arg(0) >= 0 && arg(1) >= 0)
                        b = arg(0) * arg(1);
                    else if (arg(0) < 0 || arg(1) < 0)
                        continue;
                    break;
                case ir::Op::Neg:
                    if (arg(0) < 0) continue;
                    b = arg(0);
                    break;
                default: break;
                }
                // After many passes a bound still growing is a loop: give up on it.
                changed |= join(ins.out, pass > 64 ? not_integral : b);
            }
    }
    // An operand no one writes (verify_tape forbids it) proves nothing.
    for (const auto& block : tape.blocks)
        for (const ir::Instr& ins : block)
            for (int k = 0; k < ir::arity(ins.op); ++k)
                if (ins.out != ir::no_slot && ins.in[static_cast<std::size_t>(k)] != ir::no_slot &&
                    bound[ins.in[static_cast<std::size_t>(k)]] < 0)
                    bound[ins.out] = not_integral;
    std::vector<bool> integral(tape.num_slots);
    for (std::size_t k = 0; k < bound.size(); ++k) integral[k] = bound[k] >= 0 && bound[k] <= exact_limit;
    return integral;
}

} // namespace

bool tiers_exactly(const ir::Tape& tape) {
    const std::vector<bool> integral = integral_slots(tape);
    for (const auto& block : tape.blocks)
        for (const ir::Instr& ins : block) switch (ins.op) {
            case ir::Op::Sin:
            case ir::Op::Cos:
            case ir::Op::Exp:
            case ir::Op::Tan:
            case ir::Op::Log:
            case ir::Op::Atan2: return false;
            case ir::Op::Pow:
                if (!integral[ins.in[1]]) return false;
                break;
            default: break;
            }
    return true;
}

using ir::Interval;

namespace {

enum class Phase { queued, compiling, ready, failed };

// One tape's compiles, shared by a tiered evaluator, its clones and the compile thread: first with
// LLVM's fast machine code generation, then, once the evaluations done would repay it, optimised.
struct TierState {
    ir::Tape tape;
    ir::EvalOptions options;
    JitConfig config; // the optimised code's (unless fast_codegen); the first compile's has fast_codegen
    // The first compile starts once the interpreter has worked this long (0: at once).
    std::chrono::nanoseconds start_after{0};
    std::atomic<std::int64_t> interpreted_ns{0};     // every evaluator's, summed ...
    std::atomic<std::uint64_t> interpreted_calls{0}; // ... for these evaluations
    std::atomic<bool> foreseen{false};               // a caller tells the work to come (foresee)
    std::atomic<bool> started{false};                // the first compile is queued (or done)
    std::atomic<Phase> phase{Phase::queued};
    std::unique_ptr<ir::Evaluator> jit; // written before phase becomes ready, then only read
    std::string error;                  // written before phase becomes failed
    std::mutex done_mu;
    std::condition_variable done;
    // The second compile: asked for once `evaluated` (every evaluator's, added after each call)
    // reaches optimize_at (set when the first is ready); its code is read once `optimized_ready`.
    std::atomic<std::uint64_t> evaluated{0};
    std::atomic<std::uint64_t> optimize_at{std::numeric_limits<std::uint64_t>::max()};
    std::atomic<bool> optimize_asked{false}, optimized_ready{false}, optimized_done{false};
    std::unique_ptr<ir::Evaluator> optimized;
    bool first_is_optimized = false; // `jit` is the optimised code (from the cache, or no thread)
};

// The background compile thread. LLVM's instruction selection recurses along the code, so the thread
// gets the large stack the CLI's work thread has (address space only).
//
// A compile must not outlive the process's orderly exit: static objects that LLVM made during it
// (function-local ones, made after this object) are destroyed before this object's destructor could
// join the thread. So when the last evaluator of a tape goes, its queued compile is dropped and one in
// progress is waited for, unless the process has said it ends with std::_Exit while one is pending
// (leave_compiles_at_exit: the CLI, which must not wait for LLVM after its work is done).
class Compiler {
public:
    // A compile starts this long after its evaluator was made: a job that is over by then (most of
    // `frac test`'s, small pictures) never shares the cores with LLVM; a long one loses this much.
    static constexpr std::chrono::milliseconds start_delay{10};

    static Compiler& get() {
        static Compiler c;
        return c;
    }

    // What a job does: the first compile, the optimised second one, or a look into the code cache
    // for a compile that waits (probe_cache).
    enum class Work { first, optimized, probe };

    // False when no compile thread can be started: the caller compiles itself. The second compile is
    // due at once.
    bool enqueue(const std::shared_ptr<TierState>& s, Work work = Work::first) {
        std::lock_guard<std::mutex> lock(mu_);
        start_locked();
        if (!started_) return false;
        jobs_.push_back({s,
                         std::chrono::steady_clock::now() +
                             (work == Work::optimized ? std::chrono::milliseconds{0} : start_delay),
                         work});
        wake_.notify_one();
        return true;
    }

    // The evaluators of `s` are gone.
    void forget(const TierState* s) {
        std::unique_lock<std::mutex> lock(mu_);
        std::erase_if(jobs_, [&](const Job& j) { return j.state.get() == s; });
        if (!leave_at_exit_) finished_.wait(lock, [&] { return current_ != s; });
    }

    bool pending() {
        std::lock_guard<std::mutex> lock(mu_);
        return current_ != nullptr || !jobs_.empty();
    }

    void leave_at_exit() {
        std::lock_guard<std::mutex> lock(mu_);
        leave_at_exit_ = true;
    }

    // Compiles on the calling thread (the compile thread's job, or the caller's when there is none):
    // the first compile with `first_config`, or the optimised one.
    static void compile(TierState& s, const JitConfig& first_config) {
        s.phase.store(Phase::compiling, std::memory_order_relaxed);
        Phase result = Phase::ready;
        try {
            if (first_config.fast_codegen && !s.config.cache_dir.empty()) {
                // The optimised code from a warm cache beats compiling the fast code.
                JitConfig cached = s.config;
                cached.cache_only = true;
                try {
                    s.jit = make_jit(s.tape, s.options, cached);
                    s.first_is_optimized = true;
                } catch (const NotCached&) {
                }
            }
            if (!s.jit) {
                s.jit = make_jit(s.tape, s.options, first_config);
                // A configuration asking for the fast machine code has no second compile (long tapes:
                // LLVM's optimised machine code generation grows quadratically with their length).
                s.first_is_optimized = !first_config.fast_codegen || s.config.fast_codegen;
            }
            if (!s.first_is_optimized)
                s.optimize_at.store(optimize_after(s.tape, *compile_info(*s.jit)), std::memory_order_relaxed);
        } catch (const std::exception& e) {
            s.error = e.what();
            result = Phase::failed;
        }
        {
            std::lock_guard<std::mutex> lock(s.done_mu);
            s.phase.store(result, std::memory_order_release);
        }
        s.done.notify_all();
    }

    // A first compile that waits for the interpreter's work (start_after) may find its code in the
    // cache now: then the code is taken at once and the compile never starts. On a miss nothing
    // changes (the look costs the IR's generation, a small part of a long tape's compile).
    static void probe_cache(TierState& s) {
        if (s.started.load(std::memory_order_acquire)) return; // the compile is queued: it looks itself
        JitConfig cached = s.config;
        cached.cache_only = true;
        std::unique_ptr<ir::Evaluator> code;
        try {
            code = make_jit(s.tape, s.options, cached);
        } catch (const std::exception&) {
            return; // not cached (or not compilable: the compile will say so)
        }
        // The interpreter's work may have queued the compile meanwhile; that compile finds the cache.
        if (s.started.exchange(true, std::memory_order_acq_rel)) return;
        s.jit = std::move(code);
        s.first_is_optimized = true; // nothing better is compiled after the code of s.config
        {
            std::lock_guard<std::mutex> lock(s.done_mu);
            s.phase.store(Phase::ready, std::memory_order_release);
        }
        s.done.notify_all();
    }

    // The optimised compile; when it fails the fast code stays.
    static void compile_optimized(TierState& s) {
        try {
            s.optimized = make_jit(s.tape, s.options, s.config);
            s.optimized_ready.store(true, std::memory_order_release);
        } catch (const std::exception&) {
        }
        {
            std::lock_guard<std::mutex> lock(s.done_mu);
            s.optimized_done.store(true, std::memory_order_release);
        }
        s.done.notify_all();
    }

    ~Compiler() {
        {
            std::lock_guard<std::mutex> lock(mu_);
            stop_ = true;
            jobs_.clear();
        }
        wake_.notify_all();
        if (started_) pthread_join(thread_, nullptr);
    }

private:
    void start_locked() {
        if (started_ || failed_to_start_) return;
        pthread_attr_t attr;
        constexpr std::size_t stack_bytes = std::size_t{1} << 30;
        const auto body = [](void* self) -> void* {
            static_cast<Compiler*>(self)->loop();
            return nullptr;
        };
        started_ = pthread_attr_init(&attr) == 0 && pthread_attr_setstacksize(&attr, stack_bytes) == 0 &&
                   pthread_create(&thread_, &attr, body, this) == 0;
        pthread_attr_destroy(&attr);
        failed_to_start_ = !started_;
    }

    void loop() {
        std::shared_ptr<TierState> s;
        Work work = Work::first;
        for (;;) {
            {
                std::unique_lock<std::mutex> lock(mu_);
                if (s) {
                    current_ = nullptr;
                    finished_.notify_all();
                }
                s = nullptr; // released under the lock: forget() may be waiting to free it
                wake_.wait(lock, [&] { return stop_ || !jobs_.empty(); });
                if (stop_) return;
                const auto due = jobs_.front().due;
                if (std::chrono::steady_clock::now() < due) {
                    wake_.wait_until(lock, due); // then look again: the job may be gone
                    continue;
                }
                s = std::move(jobs_.front().state);
                work = jobs_.front().work;
                jobs_.pop_front();
                current_ = s.get();
            }
            if (work == Work::optimized) {
                compile_optimized(*s);
            } else if (work == Work::probe) {
                probe_cache(*s);
            } else {
                JitConfig first = s->config;
                first.fast_codegen = true;
                compile(*s, first);
            }
        }
    }

    std::mutex mu_;
    std::condition_variable wake_, finished_;
    struct Job {
        std::shared_ptr<TierState> state;
        std::chrono::steady_clock::time_point due; // not started before
        Work work = Work::first;
    };
    std::deque<Job> jobs_;
    const TierState* current_ = nullptr; // being compiled
    bool stop_ = false, started_ = false, failed_to_start_ = false, leave_at_exit_ = false;
    pthread_t thread_{};
};

// Queues the first compile of `s` (once); without a compile thread, compiles the optimised code now.
void start_first_compile(const std::shared_ptr<TierState>& s) {
    if (s->started.exchange(true, std::memory_order_acq_rel)) return;
    if (!Compiler::get().enqueue(s)) Compiler::compile(*s, s->config);
}

// Shared by a tiered evaluator and its clones; the last one to go tells the compiler.
struct TierOwner {
    std::shared_ptr<TierState> state;
    explicit TierOwner(std::shared_ptr<TierState> s) : state(std::move(s)) {}
    TierOwner(const TierOwner&) = delete;
    TierOwner& operator=(const TierOwner&) = delete;
    ~TierOwner() { Compiler::get().forget(state.get()); }
};

class TieredEvaluator final : public ir::Evaluator {
public:
    TieredEvaluator(std::shared_ptr<TierOwner> owner, std::unique_ptr<ir::Evaluator> interp,
                    std::unique_ptr<ir::Evaluator> jit, std::uint64_t switch_after, bool optimized = false)
        : owner_(std::move(owner)), interp_(std::move(interp)), jit_(std::move(jit)), optimized_(optimized),
          switch_after_(switch_after) {}

    int dimension() const override { return interp_->dimension(); }
    std::string engine() const override { return "auto"; }
    std::size_t instruction_count() const override { return interp_->instruction_count(); }

    double eval_point(const double* coords) override {
        return counted([&](ir::Evaluator& e) { return e.eval_point(coords); });
    }
    Interval eval_box(const Interval* box) override {
        return counted([&](ir::Evaluator& e) { return e.eval_box(box); });
    }
    void eval_points(const double* coords, std::size_t n, double* out) override {
        counted([&](ir::Evaluator& e) {
            e.eval_points(coords, n, out);
            return 0;
        });
    }
    void eval_boxes(const Interval* boxes, std::size_t n, Interval* out) override {
        counted([&](ir::Evaluator& e) {
            e.eval_boxes(boxes, n, out);
            return 0;
        });
    }

    void eval_cells(const ir::CellGrid& grid, const std::uint32_t* coords, std::size_t stride, std::size_t n,
                    ir::CellVerdict* out, bool closed_inside) override {
        counted([&](ir::Evaluator& e) {
            e.eval_cells(grid, coords, stride, n, out, closed_inside);
            return 0;
        });
    }

    std::unique_ptr<ir::Evaluator> clone() const override {
        return std::make_unique<TieredEvaluator>(owner_, interp_->clone(), jit_ ? jit_->clone() : nullptr,
                                                 switch_after_, optimized_);
    }

    bool may_specialize() const override { return interp_->may_specialize(); }

    // Until the code is ready a pruned tape would be an interpreted one for the cell's whole subtree,
    // which would never move to the JIT: prune nothing, the children ask again.
    bool may_specialize_now(double expected_evaluations) override {
        ir::Evaluator& e = current();
        return !waiting_for_code(e) && e.may_specialize_now(expected_evaluations);
    }
    std::shared_ptr<ir::Evaluator> specialize(const Interval* box, double expected_evaluations) override {
        ir::Evaluator& e = current();
        if (waiting_for_code(e)) return nullptr;
        e.specialize_stats = {};
        auto p = e.specialize(box, expected_evaluations);
        specialize_stats += e.specialize_stats;
        return p;
    }

    // A compile that waits for start_after of interpreted time starts when the interpreter's time for the
    // evaluations foreseen (at its rate so far) reaches start_after instead: rent for the work to come,
    // not for the work done, so that a job whose end is near never starts a compile it cannot repay.
    void foresee(double evaluations) override {
        TierState& s = *owner_->state;
        if (s.start_after.count() == 0 || s.started.load(std::memory_order_acquire)) return;
        s.foreseen.store(true, std::memory_order_relaxed);
        const auto calls = s.interpreted_calls.load(std::memory_order_relaxed);
        if (calls == 0) return; // no rate yet: the next forecast decides
        const double ns_per_call = static_cast<double>(s.interpreted_ns.load(std::memory_order_relaxed)) /
                                   static_cast<double>(calls);
        if (evaluations * ns_per_call >= static_cast<double>(s.start_after.count()))
            start_first_compile(owner_->state);
    }

    void checkpoint(std::uint64_t evaluated) override {
        if (switch_after_ == when_ready || jit_ || evaluated < switch_after_) return;
        wait();
        if (owner_->state->phase.load(std::memory_order_acquire) == Phase::ready)
            take_first_code();
        else
            tell_failure();
    }

    // Blocks until the optimised compile, if asked for, has finished; returns whether it was.
    bool wait_optimized() {
        TierState& s = *owner_->state;
        if (!s.optimize_asked.load(std::memory_order_acquire)) return false;
        std::unique_lock<std::mutex> lock(s.done_mu);
        s.done.wait(lock, [&] { return s.optimized_done.load(std::memory_order_acquire); });
        return true;
    }

    TierStatus status() const {
        const TierState& s = *owner_->state;
        TierStatus t;
        t.tier = !jit_ ? Tier::interpreter : optimized_ ? Tier::optimized : Tier::fast;
        t.evaluated = s.evaluated.load(std::memory_order_relaxed);
        t.optimize_at = s.optimize_at.load(std::memory_order_relaxed);
        t.optimize_asked = s.optimize_asked.load(std::memory_order_relaxed);
        t.optimized_ready = s.optimized_ready.load(std::memory_order_acquire);
        t.compile_started = s.started.load(std::memory_order_acquire);
        return t;
    }

    void wait() {
        start_first_compile(owner_->state); // a delayed compile is due now
        std::unique_lock<std::mutex> lock(owner_->state->done_mu);
        owner_->state->done.wait(lock, [&] {
            const Phase p = owner_->state->phase.load(std::memory_order_acquire);
            return p == Phase::ready || p == Phase::failed;
        });
    }

private:
    bool waiting_for_code(const ir::Evaluator& e) const {
        return &e == interp_.get() && owner_->state->phase.load(std::memory_order_acquire) != Phase::failed;
    }
    // The first compile's code (phase ready).
    void take_first_code() {
        jit_ = owner_->state->jit->clone();
        optimized_ = owner_->state->first_is_optimized;
    }

    ir::Evaluator& current() {
        if (jit_ && !optimized_ && owner_->state->optimized_ready.load(std::memory_order_acquire)) {
            // The optimised code gives the fast code's results bit for bit: move at any call.
            jit_ = owner_->state->optimized->clone();
            optimized_ = true;
        }
        if (jit_ || switch_after_ != when_ready) return jit_ ? *jit_ : *interp_;
        const Phase p = owner_->state->phase.load(std::memory_order_acquire);
        if (p == Phase::ready) {
            take_first_code();
            return *jit_;
        }
        if (p == Phase::failed) tell_failure();
        return *interp_;
    }

    void tell_failure() const {
        static std::atomic<bool> told{false}; // say it once per run
        if (!told.exchange(true))
            std::cerr << "frac: note: the JIT cannot be used (" << owner_->state->error
                      << "); using the interpreter\n";
    }

    // Runs f on the current engine and adds what it counted to this evaluator's counters (which the
    // caller may reset at any time).
    template <class F>
    std::invoke_result_t<F, ir::Evaluator&> counted(F&& f) {
        ir::Evaluator& e = current();
        // A delayed compile counts the interpreter's time (two clock reads a call: a call is a batch).
        const bool timed = &e == interp_.get() && !owner_->state->started.load(std::memory_order_relaxed);
        const auto t0 = timed ? std::chrono::steady_clock::now() : std::chrono::steady_clock::time_point{};
        e.stats = {};
        auto r = f(e);
        stats += e.stats;
        if (jit_ && !optimized_) count_towards_optimizing(e.stats.calls);
        if (timed) count_towards_starting(std::chrono::steady_clock::now() - t0, e.stats.calls);
        return r;
    }

    // The interpreter's time, every evaluator's of the tape; past the state's start_after the first
    // compile is queued (once), unless a caller foresees the work to come.
    void count_towards_starting(std::chrono::nanoseconds spent, std::uint64_t calls) {
        TierState& s = *owner_->state;
        s.interpreted_calls.fetch_add(calls, std::memory_order_relaxed);
        if (s.interpreted_ns.fetch_add(spent.count(), std::memory_order_relaxed) + spent.count() >=
                s.start_after.count() &&
            !s.foreseen.load(std::memory_order_relaxed))
            start_first_compile(owner_->state);
    }

    // The evaluations on the fast code, of every evaluator of the tape; past the state's
    // optimize_after the optimised compile is queued (once).
    void count_towards_optimizing(std::uint64_t calls) {
        TierState& s = *owner_->state;
        const std::uint64_t done = s.evaluated.fetch_add(calls, std::memory_order_relaxed) + calls;
        if (done < s.optimize_at.load(std::memory_order_relaxed) ||
            s.optimize_asked.exchange(true, std::memory_order_relaxed))
            return;
        Compiler::get().enqueue(owner_->state, Compiler::Work::optimized);
    }

    std::shared_ptr<TierOwner> owner_;
    std::unique_ptr<ir::Evaluator> interp_;
    std::unique_ptr<ir::Evaluator> jit_; // this evaluator's clone of the compiled code, once switched
    bool optimized_ = false;             // jit_ is the optimised code
    static constexpr std::uint64_t when_ready = 0; // switch_after_ of TierSwitch::when_ready
    std::uint64_t switch_after_;                   // else: the checkpoint's cells that switch
};

} // namespace

std::uint64_t checkpoint_evaluations(const ir::Tape& tape) {
    // Only tapes with loose inline kernels (transcendentals) switch at checkpoints: the rates are those of
    // bench_kernels' gyroid (27 instructions; interpreter 650 ns per evaluation, JIT 55.7): a JIT
    // evaluation saves 24 - 2.1 ns per unit of cost.
    constexpr double interp_ns_per_cost = 24, jit_ns_per_cost = 2.1, compile_ns_fixed = 15e6,
                     compile_ns_per_cost = 0.4e6;
    const double cost = std::max(1.0, ir::tape_cost(tape));
    return static_cast<std::uint64_t>(std::max(1.0, (compile_ns_fixed + compile_ns_per_cost * cost) /
                                                        ((interp_ns_per_cost - jit_ns_per_cost) * cost)));
}

std::uint64_t optimize_after(const ir::Tape& tape, const CompileInfo& fast) {
    // Measured by bench_jit (2026-12-04): the optimised machine code takes 2.34 times the fast one's
    // time over the stdlib shapes, so the optimised compile costs the fast one's total plus 1.35 times
    // its machine code time; the optimised carpet evaluates a box in 42.9 ns against 60.3, 0.27 ns per
    // unit of tape cost saved.
    constexpr double extra_machine = 1.35, saved_ns_per_cost = 0.27;
    const double compile_ns = 1e6 * (fast.total_ms + extra_machine * fast.machine_ms);
    const double cost = std::max(1.0, ir::tape_cost(tape));
    return static_cast<std::uint64_t>(std::max(1.0, compile_ns / (saved_ns_per_cost * cost)));
}

std::chrono::nanoseconds long_tape_start_after(const ir::Tape& tape) {
    // Measured (docs/performance.md, "Long tapes"): the fast machine code of a long tape compiles in
    // 0.10-0.19 ms per instruction (0.98 s at 9,971, 2.4 s at 12,373 on a loaded machine, 5.8 s at 38,000
    // with the rest of the compile). The compile takes a core from the cover while it runs, so it waits
    // for three times its time in interpreted work: a job of 4.4 s of interpreted CPU against a 2.4 s
    // compile (a depth-15 picture on two threads) ended later than the interpreter alone when it started
    // sooner.
    constexpr double compile_ns_per_instruction = 0.15e6, rent_factor = 3;
    return std::chrono::nanoseconds(static_cast<std::int64_t>(std::max(
        1.0, rent_factor * compile_ns_per_instruction * static_cast<double>(tape.instruction_count()))));
}

std::unique_ptr<ir::Evaluator> make_tiered(const ir::Tape& tape, const ir::EvalOptions& options,
                                           const JitConfig& config, TierSwitch when,
                                           std::chrono::nanoseconds start_after) {
    if (when == TierSwitch::when_ready && !tiers_exactly(tape))
        throw std::invalid_argument(
            "make_tiered: the tape has an inline kernel wider than the interpreter's");
    auto state = std::make_shared<TierState>();
    state->tape = tape;
    state->options = options;
    state->config = config;
    state->start_after = start_after;
    auto interp = interp::make_interpreter(tape, options);
    if (start_after.count() == 0)
        start_first_compile(state);
    else if (!config.cache_dir.empty())
        Compiler::get().enqueue(state, Compiler::Work::probe); // a warm cache serves before the delay
    return std::make_unique<TieredEvaluator>(
        std::make_shared<TierOwner>(std::move(state)), std::move(interp), nullptr,
        when == TierSwitch::when_ready ? 0 : checkpoint_evaluations(tape));
}

bool background_compile_pending() {
    return Compiler::get().pending();
}

void leave_compiles_at_exit() {
    Compiler::get().leave_at_exit();
}

void wait_for_tier(ir::Evaluator& e) {
    if (auto* t = dynamic_cast<TieredEvaluator*>(&e)) t->wait();
}

bool wait_for_optimized_tier(ir::Evaluator& e) {
    auto* t = dynamic_cast<TieredEvaluator*>(&e);
    return t && t->wait_optimized();
}

std::optional<TierStatus> tier_status(const ir::Evaluator& e) {
    const auto* t = dynamic_cast<const TieredEvaluator*>(&e);
    if (!t) return std::nullopt;
    return t->status();
}

} // namespace frac::jit
