// The interpreter of flat tapes (one block: no series, no external functions), the form large
// F-rep models take. Built for tape pushes (libfive's, Fidget's): a pruned tape keeps its root's
// slot numbering, so every tape pushed from one root runs in one register file per thread, and a push
// is two passes over the parent's code (a backward pass deciding the choices from the values its
// evaluation left and marking the live code, a forward pass copying it with the chosen operands in
// place of the choices) into compact 20-byte instructions, without renumbering, hashing or extra
// allocation. Results are the reference interpreter's bit for bit: the same interval operations, the
// same choices (ir::decide_choice) and emptiness rule (ir::defined_over_box).
#pragma once

#include "ir/evaluator.hpp"
#include "ir/tape.hpp"

#include <memory>

namespace frac::interp {

// Whether `tape` runs on the flat interpreter: a single block, no external function, powi exponents
// that fit 32 bits.
bool runs_flat(const ir::Tape& tape);

// Requires runs_flat(tape).
std::unique_ptr<ir::Evaluator> make_flat_interpreter(const ir::Tape& tape, const ir::EvalOptions& options);

} // namespace frac::interp
