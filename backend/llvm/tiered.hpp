// Tiered evaluation: the interpreter answers at once while LLVM compiles the tape on a background
// thread; each evaluator (and each clone, per subdivision thread) moves to the machine code as soon
// as it is ready. That first compile uses LLVM's fast machine code generation (about half the time);
// once the evaluations on it would repay the optimised code's compile (optimize_after), that is
// compiled on the same thread and each evaluator moves to it at its next call (the two give the same
// results bit for bit). The default engine of the command line ("auto"), so that a small job never waits
// for the compiler and a large one gets the JIT's speed.
//
// Outputs must not depend on when the compile finishes. Where the JIT's enclosures are the
// interpreter's bit for bit (`tiers_exactly`), an evaluator switches at its first call after the code
// is ready. Elsewhere (sin, cos, exp, tan, log, pow and atan2 have inline kernels a few ulps wider than the
// numeric core's) it switches only at a checkpoint of the caller's work (Evaluator::checkpoint: a
// cover's level boundary) once the work done has passed an estimate of the compile's cost, waiting
// for the code there if need be: the same point whatever the threads and the timing.
#pragma once

#include "backend/llvm/jit.hpp"

#include <chrono>
#include <optional>

namespace frac::jit {

// Whether the JIT computes this tape's box enclosures, point values and series term counts bit for
// bit as the interpreter does (no loose inline kernel).
bool tiers_exactly(const ir::Tape& tape);

// When a tiered evaluator moves to the compiled code.
enum class TierSwitch {
    when_ready, // at its first call once the code is ready (requires tiers_exactly)
    checkpoints // at the first checkpoint with at least checkpoint_evaluations(tape) cells done
};

// An evaluator that interprets the tape until it switches to the compiled code. The compile is
// queued on one background thread shared by the process (one compile at a time; a job whose
// evaluators are all gone is dropped). Until the switch, specialize() prunes nothing (the children
// of a cell ask again). When compiling fails, the evaluator stays interpreted and says so once on
// stderr. TierSwitch::when_ready requires tiers_exactly(tape) (std::invalid_argument otherwise).
// A `config` with fast_codegen makes the fast code the last tier (no optimised compile follows).
// `start_after` > 0 delays the compile until the interpreter has worked that long (the time of its
// calls, summed over the evaluator and its clones; wait_for_tier starts it at once): a short job never
// compiles. Once a caller foresees its work (Evaluator::foresee: a cover, at each level), the compile
// starts instead when the interpreter's time for the work foreseen, at its rate so far, reaches
// start_after. Its code in the config's cache is looked for at once (on the compile thread) and, when it
// is there, taken without waiting.
std::unique_ptr<ir::Evaluator> make_tiered(const ir::Tape& tape, const ir::EvalOptions& options,
                                           const JitConfig& config, TierSwitch when = TierSwitch::when_ready,
                                           std::chrono::nanoseconds start_after = std::chrono::nanoseconds{
                                               0});

// The interpreter's working time after which a long tape's fast compile starts: a few times what the
// compile will take (rent before buying: a shorter job never compiles, a longer one pays a bounded
// multiple of what it would with hindsight).
std::chrono::nanoseconds long_tape_start_after(const ir::Tape& tape);

// Cells evaluated after which interpreting has cost about what compiling saves (measured rates on a
// transcendental tape, bench_kernels' gyroid: the interpreter 24 ns per unit of tape cost and box, the
// JIT 2.1; LLVM about 15 ms plus 0.4 ms per unit).
std::uint64_t checkpoint_evaluations(const ir::Tape& tape);

// Evaluations on the first compile's code (LLVM's fast machine code generation) after which compiling
// the optimised code would repay itself, from what the fast compile took (`fast`).
std::uint64_t optimize_after(const ir::Tape& tape, const CompileInfo& fast);

// When the last evaluator of a tape goes, its queued compile is dropped and one in progress is waited
// for: LLVM's static objects must not be destroyed under it at exit. A program that promises to end
// with std::_Exit (after flushing its output) while background_compile_pending() — the CLI, which must
// not wait for LLVM once its work is done — calls this first, and nothing waits.
void leave_compiles_at_exit();

// Whether a background compile is running or queued for a live evaluator.
bool background_compile_pending();

// Blocks until the compile of a tiered evaluator (or a clone) has finished or failed, for tests and
// benchmarks. No effect on other evaluators.
void wait_for_tier(ir::Evaluator& e);

// Blocks until the optimised compile of a tiered evaluator has finished, if it was asked for; returns
// whether it was.
bool wait_for_optimized_tier(ir::Evaluator& e);

// Where a tiered evaluator stands (for tests and benchmarks); nullopt for other evaluators.
enum class Tier { interpreter, fast, optimized };
struct TierStatus {
    Tier tier = Tier::interpreter; // the code this evaluator runs
    std::uint64_t evaluated = 0;   // evaluations on the fast code, every evaluator of the tape
    std::uint64_t optimize_at = 0; // ... at which the optimised compile is asked for
    bool optimize_asked = false;
    bool optimized_ready = false;
    bool compile_started = false; // the first compile is queued or done
};
std::optional<TierStatus> tier_status(const ir::Evaluator& e);

} // namespace frac::jit
