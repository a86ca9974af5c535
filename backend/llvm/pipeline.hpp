// The steps the JIT and the AOT compiler share around code generation (codegen.hpp): option checks,
// verification of the generated module, the optimisation pipeline and the default vector width.
// Private to backend/llvm.
#pragma once

#include "ir/evaluator.hpp"
#include "ir/tape.hpp"

namespace llvm {
class Module;
class TargetMachine;
} // namespace llvm

namespace frac::jit {

// Throws std::invalid_argument for options out of range or a malformed tape (as the interpreter does).
void check_options(const ir::Tape& tape, const ir::EvalOptions& options);

// Throws std::logic_error when the generated module is not valid LLVM IR (a bug in the generator).
void verify_generated(const llvm::Module& module);

// The pass pipeline every generated module runs (target information from `tm`).
void optimize(llvm::Module& module, llvm::TargetMachine* tm);

// Boxes per vector of the interval code when the caller does not choose: one per 64-bit lane of the
// widest vector registers the target has.
int default_lanes(bool avx512, bool avx);

} // namespace frac::jit
