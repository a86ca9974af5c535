// Ahead-of-time compilation of shapes to an object file with a C ABI (docs/c-abi.md).
//
// The same code generator as the JIT (codegen.hpp) emits each shape's batch functions into one LLVM
// module; exported C wrappers with stable names are added around them, and LLVM's TargetMachine writes
// the object (compile_aot). The object still calls the numeric core: build_aot links it with
// libfrac_aot_runtime.a (aot_runtime.hpp, helpers.hpp, the numeric core, LLVM libc), and with the
// archives of the external functions it calls (dist(p, A): libfrac_aot_automata.a), into a
// self-contained object or a shared library (`frac compile`), and make_aot loads such a library into
// this process as an evaluator (`--engine aot`, the conformance suite).
//
// Only backend/llvm includes LLVM headers; this header does not.
#pragma once

#include "ir/evaluator.hpp"
#include "ir/tape.hpp"

#include <memory>
#include <string>
#include <vector>

namespace frac::jit {

struct AotShape {
    std::string name; // a C identifier
    ir::Tape tape;
    std::vector<ir::Interval> box; // default box, one interval per coordinate
};

struct AotConfig {
    // Baked into the code: series term limits and tables are compile-time choices.
    ir::EvalOptions options;
    // "generic": the architecture's baseline CPU (x86-64: SSE2), runs on any machine of the
    // architecture. "native": this host's CPU and features. Else a CPU name LLVM knows ("x86-64-v3",
    // "x86-64-v4", "znver4", ...). Where the CPU has AVX-512F the interval code uses embedded rounding
    // ({ru-sae}, as the JIT on such a host), elsewhere constrained intrinsics.
    std::string cpu = "generic";
    // The exported names are <prefix><shape>_<function>.
    std::string prefix = "frac_";
};

// What the generated code is (for the header's comments and the CLI's summary).
struct AotInfo {
    std::string triple, cpu, rounding; // rounding: "constrained" or "avx512"
    int lanes = 1;
};

// The exported name of one function of a shape ("eval_point", "eval_box", ...).
std::string aot_symbol(const AotConfig& config, const std::string& shape, const std::string& function);

// Whether `name` can be part of a C identifier's name (letters, digits, '_', not starting with a digit).
bool is_c_identifier(const std::string& name);

// Generates, optimises and writes the code of `shapes`: the relocatable object (without the run-time
// support) to `object_path` and/or the LLVM IR to `llvm_ir_path` (an empty path: not written).
// Throws JitError (jit.hpp) when LLVM cannot target this host or a file cannot be written,
// std::invalid_argument for options out of range or a CPU LLVM does not know.
AotInfo compile_aot(const std::vector<AotShape>& shapes, const AotConfig& config,
                    const std::string& object_path, const std::string& llvm_ir_path);

// The run-time archives (file names) that the external functions the shapes call need besides
// libfrac_aot_runtime.a (ir::ExternalFunction::compiled). Throws std::invalid_argument for a function
// compiled models cannot carry.
std::vector<std::string> external_archives(const std::vector<AotShape>& shapes);

// compile_aot, then the object linked with the run-time archive into `output`: a relocatable object
// (.o) or a shared library (.so) whose only global symbols are the exported functions (docs/c-abi.md,
// "Linking"). Throws as compile_aot, and JitError when the run-time archive cannot be found (it is
// looked for before any work) or a linker step fails.
AotInfo build_aot(const std::vector<AotShape>& shapes, const AotConfig& config, const std::string& output,
                  const std::string& llvm_ir_path = "");

// An evaluator over `tape` compiled ahead of time: build_aot writes a shared library to a temporary
// directory, dlopen loads it, and the evaluator calls its C functions (engine "aot"). The options are
// baked into the code. What the C ABI does not offer: series counters (stats counts calls only), min/max
// pruning (specialize() returns null), and a box with an empty coordinate has the empty image where
// the other engines evaluate the function on it (docs/c-abi.md). Otherwise the results are the
// JIT's bits. `cpu` as AotConfig::cpu. Throws as build_aot, and JitError when loading fails.
std::unique_ptr<ir::Evaluator> make_aot(const ir::Tape& tape, const ir::EvalOptions& options = {},
                                        const std::string& cpu = "native");

// The C header declaring the functions of `shapes` (with comments: layouts, rounding contract, limits).
std::string aot_header(const std::vector<AotShape>& shapes, const AotConfig& config, const AotInfo& info,
                       const std::string& source_name, const std::string& guard);

} // namespace frac::jit
