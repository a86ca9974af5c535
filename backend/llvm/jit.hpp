// The LLVM ORC JIT engine: compiles a tape to machine code behind the ir::Evaluator interface.
//
//   auto eval = frac::jit::make_jit(tape, options);   // throws frac::jit::JitError
//
// Results are bit-identical to the reference interpreter (backend/interp) for boxes and points,
// including series term counts (EvalStats). eval_box / eval_boxes set upward rounding once per call;
// the generated interval code uses LLVM's constrained floating-point intrinsics ("round.upward",
// "fpexcept.ignore"), so the optimiser cannot fold or reorder it as if it rounded to nearest, and
// computes lower bounds as -RU(-x op y) like the numeric core. See docs/design.md and
// backend/llvm/codegen.hpp.
//
// Only backend/llvm includes LLVM headers; this header does not.
#pragma once

#include "ir/evaluator.hpp"
#include "ir/specialize.hpp"
#include "ir/tape.hpp"

#include <memory>
#include <stdexcept>
#include <string>

namespace frac::jit {

// The JIT cannot be used (LLVM could not be initialised for this host, or compiling failed).
class JitError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// make_jit with JitConfig::cache_only found no object in the cache.
class NotCached : public JitError {
public:
    using JitError::JitError;
};

// Whether the JIT works in this process (initialises LLVM once). On false, `why` says why, and the
// caller falls back to the interpreter and tells the user so.
bool jit_available(std::string* why = nullptr);

// Choices of code generation (the defaults are what the CLI uses).
struct JitConfig {
    // How interval code rounds upward. automatic: AVX-512 instructions with embedded rounding
    // ({ru-sae}, no dependence on MXCSR, freely optimisable) when the host has AVX-512F, else LLVM's
    // constrained intrinsics (portable). Both give the same bits; tests force each one.
    enum class Rounding { automatic, constrained, avx512 } rounding = Rounding::automatic;
    // Boxes evaluated at once by the interval code, one per vector lane: 0 chooses for the host (8 with
    // AVX-512, 4 with AVX, else 2); 1 is scalar code. AVX-512 rounding needs 1 or 8.
    int lanes = 0;
    // The on-disk cache of machine code (code_cache.hpp): a directory, or empty for none (the library's
    // default; the CLI uses $FRAC_CACHE_DIR, else $XDG_CACHE_HOME/frac, else ~/.cache/frac). Tapes
    // that call external functions embed their addresses and are never cached.
    std::string cache_dir;
    std::size_t cache_max_bytes = std::size_t{256} << 20;
    // LLVM's machine code generation without optimisation (CodeGenOptLevel::None; the IR passes are
    // the same): compiles about 2x faster, runs up to 1.4x slower, the same results bit for bit. The
    // tiered engine's first compile (docs/performance.md "First compile in a fresh process").
    bool fast_codegen = false;
    // Only from the on-disk cache: make_jit throws NotCached when the object is not there (the tiered
    // engine's first try, so that a warm cache of optimised code is used at once).
    bool cache_only = false;
};

// A configuration that chooses the form of the code only (no cache).
inline JitConfig codegen_config(JitConfig::Rounding rounding, int lanes) {
    JitConfig c;
    c.rounding = rounding;
    c.lanes = lanes;
    return c;
}

// Whether the host can run the AVX-512 form of the generated code.
bool host_has_avx512();

// Compiles the tape. Throws JitError when LLVM cannot be used (or the requested rounding form is
// not available on this host), std::invalid_argument for options out of range (as the interpreter
// does). The evaluator and its clones share the machine code.
std::unique_ptr<ir::Evaluator> make_jit(const ir::Tape& tape, const ir::EvalOptions& options = {},
                                        const JitConfig& config = {});

// What specialising costs and saves with the JIT (ir/specialize.hpp), measured by bench/bench_prune:
// evaluation time per unit of tape cost and box, compile time of a pruned tape.
// Its fixed part per evaluation in a cover (the generated code builds and classifies the cells) is
// measured by bench/bench_prune part 1b like the interpreter's cover_eval_ns_fixed.
inline constexpr ir::PruneCosts jit_prune_costs{.eval_ns_per_cost = 0.8,
                                                .compile_ns_fixed = 2.0e7,
                                                .compile_ns_per_instruction = 2.0e6,
                                                .eval_ns_fixed = 45.0};

// Recording the choices over a box is an interpreter evaluation of the whole tape, 10-30 JIT
// evaluations: the JIT records only for a cell with at least this many expected descendant
// evaluations (in 2D, 5 levels above the depth; measured in docs/performance.md, "Min/max pruning").
// Its second tier (pruned tapes on the interpreter) records at every level. Nor does it record where
// no outcome could repay it (ir::SpecializationCache::may_pay: short tapes).
inline constexpr double jit_min_expected_evaluations = 120;

// What compiling one tape cost (wall clock, milliseconds), for benchmarks and --verbose output.
struct CompileInfo {
    double tables_ms = 0;            // index and series tables
    double codegen_ms = 0;           // tape -> LLVM IR
    double optimize_ms = 0;          // LLVM IR passes
    double machine_ms = 0;           // instruction selection, emission and linking in the JIT
    double total_ms = 0;             // make_jit from start to finish
    std::size_t ir_instructions = 0; // after optimisation (0 when the object came from the cache)
    std::size_t table_bytes = 0;
    std::string rounding;      // "avx512" or "constrained"
    int lanes = 1;             // boxes per vector of the interval code
    bool fast_codegen = false; // LLVM's fast machine code generation (JitConfig::fast_codegen)
    // The on-disk cache: "off" (none, or the tape calls external functions), "miss" (compiled, then
    // stored) or "hit" (loaded: no optimisation, no code generation).
    std::string cache = "off";
    double cache_ms = 0; // writing and hashing the module's bitcode, reading or writing the entry
};
// The compile info of a JIT evaluator (or a clone); nullptr for any other engine.
const CompileInfo* compile_info(const ir::Evaluator& e);

// The LLVM IR the JIT generates for a tape, optimised or not (for `--emit=llvm` and tests).
std::string emit_llvm(const ir::Tape& tape, const ir::EvalOptions& options = {}, bool optimized = true,
                      const JitConfig& config = {});

} // namespace frac::jit
