// The interval batch function of a tape (see box_codegen.cpp). Private to backend/llvm.
#pragma once

#include "backend/llvm/codegen.hpp"

namespace frac::jit {

// Emits `<name>_box` and `<name>_cells` (codegen.hpp) into the module, evaluating `lanes` boxes at a
// time (1, or a vector width; AVX-512 rounding needs 1 or 8): both call one function of the box code,
// which takes its inputs from boxes or from cells. Sets names.box and names.cells.
void generate_box_functions(const ir::Tape& tape, const ir::EvalOptions& options, const Tables& tables,
                            llvm::Module& module, const std::string& name, Rounding rounding, int lanes,
                            GeneratedNames& names);

} // namespace frac::jit
