#include "driver/engines.hpp"

#include "backend/interp/interpreter.hpp"
#include "backend/llvm/aot.hpp"
#include "backend/llvm/jit.hpp"
#include "backend/llvm/tiered.hpp"
#include "ir/specialize.hpp"
#include "ir/tape.hpp"

#include <fmt/format.h>

#include <iostream>

namespace frac::driver {

namespace {

// A tape with min/max to prune and more instructions than this goes to the interpreter even when the
// JIT is asked for: LLVM's compile grows faster than the tape (5 s for 1,262 instructions, 22-67 s for
// 3,720-12,033 on the loaded development machine), while the interpreter's tape pushes cover such
// models at depth 10 in 0.14-0.6 s, as fast per evaluation as the JIT's code on the whole tape
// (docs/performance.md, "Large models"). The stdlib's shapes and the CSG scene of bench_prune stay
// far below it.
constexpr std::size_t jit_max_prunable_instructions = 1000;

// A tape longer than this gets LLVM's fast machine code generation only (JitConfig::fast_codegen): the
// optimised one grows about quadratically with the length of one function (its machine scheduler; a
// sum of n square roots: 4.1 s at 10,000 instructions, 18.8 s at 20,000), the fast one linearly (1.0 s
// and 2.4 s), and its code still evaluates a box about 3 times faster than the interpreter. The default
// engine interprets it until the work to come (a cover foresees it, Evaluator::foresee), else the work
// done, is three times what the compile will take (jit::long_tape_start_after), then compiles in the
// background: a compile of seconds started at once beside a cover on two cores made it slower than the
// interpreter (a depth-15 picture of 12,400 instructions: 3.15 s against 2.28; docs/performance.md,
// "Long tapes").
constexpr std::size_t jit_max_optimized_instructions = 10000;

// Any tape longer than this is interpreted, whatever the engine asked for: the fast machine code
// generation takes 5.8 s and 490 MB at 38,000 instructions.
constexpr std::size_t jit_max_instructions = 40000;

} // namespace

void check_compile_size(std::size_t instructions, std::size_t limit, const std::string& what) {
    if (instructions > limit)
        throw RunError(
            fmt::format("{} has {} instructions, more than the limit of {} for compiled code (LLVM's "
                        "compile time grows about quadratically with one function's length: 52 s at "
                        "20,000) (FRAC_MAX_COMPILE_INSTRUCTIONS raises it)",
                        what, instructions, limit));
}

std::unique_ptr<ir::Evaluator> make_evaluator(const front::Module& m, ir::NodeId root, int inputs,
                                              const EngineOptions& options) {
    ir::Tape tape = ir::build_tape(m.graph, root, inputs);
    if (std::string defect = ir::verify_tape(tape); !defect.empty())
        throw front::InternalError("malformed tape: " + defect);
    const bool prunable_and_large = options.eval.prune && ir::has_choices(tape) &&
                                    tape.instruction_count() > jit_max_prunable_instructions;
    const bool automatic = options.engine == "auto";
    const bool wants_jit = options.engine == "jit" || automatic;
    const bool long_tape = tape.instruction_count() > jit_max_optimized_instructions;
    // Long tapes compile late (long_tape_start_after), which needs the switch at any call.
    const bool too_long = tape.instruction_count() > jit_max_instructions ||
                          (automatic && long_tape && !jit::tiers_exactly(tape));
    if (wants_jit && too_long && !prunable_and_large) {
        static bool told = false; // say it once per run
        if (!told)
            std::cerr << fmt::format(
                "frac: note: {} instructions are more than the JIT compiles in reasonable "
                "time ({}); using the interpreter\n",
                tape.instruction_count(),
                tape.instruction_count() > jit_max_instructions ? jit_max_instructions
                                                                : jit_max_optimized_instructions);
        told = true;
    } else if (wants_jit && !prunable_and_large) {
        jit::JitConfig config;
        config.cache_dir = options.jit_cache_dir;
        config.fast_codegen = long_tape;
        // The interpreter serves while LLVM starts and compiles, where that cannot change a result.
        if (automatic && long_tape)
            return jit::make_tiered(tape, options.eval, config, jit::TierSwitch::when_ready,
                                    jit::long_tape_start_after(tape));
        if (automatic && jit::tiers_exactly(tape)) return jit::make_tiered(tape, options.eval, config);
        if (automatic && options.checkpoints)
            return jit::make_tiered(tape, options.eval, config, jit::TierSwitch::checkpoints);
        std::string why;
        if (jit::jit_available(&why)) {
            try {
                return jit::make_jit(tape, options.eval, config);
            } catch (const jit::JitError& e) {
                why = e.what();
            }
        }
        static bool told = false; // say it once per run
        if (!told)
            std::cerr << fmt::format("frac: note: the JIT cannot be used ({}); using the interpreter\n", why);
        told = true;
    } else if (options.engine == "aot") {
        // Asked for by name, so no fallback: a model that cannot be compiled and loaded is an error.
        check_compile_size(tape.instruction_count(), options.max_compile_instructions, "the expression");
        try {
            return jit::make_aot(tape, options.eval);
        } catch (const jit::JitError& e) {
            throw RunError(fmt::format("the aot engine cannot be used: {}", e.what()));
        }
    } else if (options.engine != "interp" && !wants_jit) {
        throw RunError(
            fmt::format("unknown engine '{}' (available: auto, jit, interp, aot)", options.engine));
    }
    return interp::make_interpreter(std::move(tape), options.eval);
}

void leave_compiles_at_exit() {
    jit::leave_compiles_at_exit();
}

bool background_compile_pending() {
    return jit::background_compile_pending();
}

} // namespace frac::driver
