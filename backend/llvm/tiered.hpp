// Tiered evaluation: the interpreter answers at once while LLVM compiles the tape on a background
// thread; each evaluator (and each clone, per subdivision thread) moves to the machine code as soon
// as it is ready. The default engine of the command line ("auto"), so that a small job never waits
// for the compiler and a large one gets the JIT's speed.
//
// Outputs must not depend on when the compile finishes, so a tape is tiered only where the JIT's
// enclosures are the interpreter's bit for bit (`tiers_exactly`): sin, cos, exp, tan, log and pow
// have inline kernels a few ulps wider than the numeric core's, and tapes with them are compiled
// before evaluation starts, as with the "jit" engine.
#pragma once

#include "backend/llvm/jit.hpp"

namespace frac::jit {

// Whether the JIT computes this tape's box enclosures, point values and series term counts bit for
// bit as the interpreter does (no loose inline kernel).
bool tiers_exactly(const ir::Tape& tape);

// An evaluator that interprets the tape until its compiled code is ready, then runs that. The
// compile is queued on one background thread shared by the process (one compile at a time; a job
// whose evaluators are all gone is dropped). Until the code is ready, specialize() prunes nothing
// (the children of a cell ask again). When compiling fails, the evaluator stays interpreted and
// says so once on stderr. Requires tiers_exactly(tape) (std::invalid_argument otherwise).
std::unique_ptr<ir::Evaluator> make_tiered(const ir::Tape& tape, const ir::EvalOptions& options,
                                           const JitConfig& config);

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

} // namespace frac::jit
