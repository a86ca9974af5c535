// The evaluators of a model's expressions: the JIT, the interpreter as its fallback, both tiered
// ("auto": the interpreter while LLVM compiles; the command line's default), or a model compiled ahead
// of time and loaded ("aot").
#pragma once

#include "frontend/module.hpp"
#include "ir/evaluator.hpp"

#include <memory>
#include <stdexcept>
#include <string>

namespace frac::driver {

struct EngineOptions {
    // "jit" (compiled before the first evaluation), "auto" (backend/llvm/tiered.hpp), "interp" (the
    // fallback when the JIT cannot be used), "aot".
    std::string engine = "jit";
    ir::EvalOptions eval;
    int threads = 0;                              // subdivision threads; 0: all cores
    std::size_t max_compile_instructions = 20000; // aot: FRAC_MAX_COMPILE_INSTRUCTIONS (cli/session.hpp)
    std::string jit_cache_dir; // the JIT's on-disk cache of machine code; empty: none (cli/session.hpp)
    // The caller calls Evaluator::checkpoint (a cover): then "auto" tiers every tape, switching those
    // whose JIT bits differ from the interpreter's at a checkpoint; else it compiles those first.
    bool checkpoints = false;
};

// A user-facing run-time failure (I/O, a computation that cannot be done): message and exit code 1.
struct RunError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Compiled code (`frac compile`, the aot engine) of more than `limit` instructions is refused: LLVM's
// compile time grows about quadratically with one function's length. Throws RunError naming `what`.
void check_compile_size(std::size_t instructions, std::size_t limit, const std::string& what);

// An evaluator of the expression `root` reading `inputs` variables (a shape's coordinates, or the
// answers of queries). When the JIT cannot be used, says why once on stderr and interprets.
std::unique_ptr<ir::Evaluator> make_evaluator(const front::Module& m, ir::NodeId root, int inputs,
                                              const EngineOptions& options);

// A program that ends with std::_Exit, after flushing its output, while background_compile_pending()
// calls leave_compiles_at_exit() first: evaluators of the "auto" engine then do not wait for their
// compile when they go (backend/llvm/tiered.hpp). The CLI does, so that it never waits for LLVM once
// its work is done.
void leave_compiles_at_exit();
bool background_compile_pending();

} // namespace frac::driver
