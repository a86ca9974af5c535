// The interval batch function of a tape (see box_codegen.cpp). Private to backend/llvm.
#pragma once

#include "backend/llvm/codegen.hpp"

namespace frac::jit {

// Emits `<name>_box` into the module, evaluating `lanes` boxes at a time (1, or a vector width;
// AVX-512 rounding needs 1 or 8). Returns the function's name.
std::string generate_box_function(const ir::Tape& tape, const ir::EvalOptions& options, const Tables& tables,
                                  llvm::Module& module, const std::string& name, Rounding rounding,
                                  int lanes);

} // namespace frac::jit
