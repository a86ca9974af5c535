#include "driver/engines.hpp"

#include "backend/interp/interpreter.hpp"
#include "backend/llvm/aot.hpp"
#include "backend/llvm/jit.hpp"
#include "ir/tape.hpp"

#include <fmt/format.h>
#include <iostream>

namespace frac::driver {

std::unique_ptr<ir::Evaluator> make_evaluator(const front::Module& m, ir::NodeId root, int inputs,
                                              const EngineOptions& options) {
    ir::Tape tape = ir::build_tape(m.graph, root, inputs);
    if (std::string defect = ir::verify_tape(tape); !defect.empty())
        throw front::InternalError("malformed tape: " + defect);
    if (options.engine == "jit") {
        std::string why;
        if (jit::jit_available(&why)) {
            try {
                return jit::make_jit(tape, options.eval);
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
        try {
            return jit::make_aot(tape, options.eval);
        } catch (const jit::JitError& e) {
            throw RunError(fmt::format("the aot engine cannot be used: {}", e.what()));
        }
    } else if (options.engine != "interp") {
        throw RunError(fmt::format("unknown engine '{}' (available: jit, interp, aot)", options.engine));
    }
    return interp::make_interpreter(std::move(tape), options.eval);
}

} // namespace frac::driver
