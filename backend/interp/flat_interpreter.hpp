// The interpreter of flat tapes (one block: no series, no external functions), the form large
// F-rep models take; make_interpreter uses it for every flat tape.
//
// Built for tape pushes (libfive's, Fidget's): a box evaluation leaves every value in the thread's
// register file, and a push reads the choices off those values in one backward pass over the live
// code, writing the pruned tape in reverse, then one forward pass over the pruned code that numbers
// its slots densely (constants, inputs, results), so a deep cell's registers are a few cache lines.
// Instructions are 20 bytes with their handler resolved; a tape's arrays share one allocation. Box
// evaluation runs up to `lanes` boxes side by side (a cover's sibling cells share their parent's
// tape), dispatching each instruction once for all of them.
//
// Results are the tape interpreter's bit for bit (tests/unit/llvm/test_flat_interpreter.cpp): the same
// interval operations, the same choices (ir::decide_choice) and emptiness rule (ir::defined_over_box).
#pragma once

#include "ir/evaluator.hpp"
#include "ir/tape.hpp"

#include <memory>

namespace frac::interp {

// Whether `tape` runs on the flat interpreter: a single block, no external function, powi exponents
// that fit 32 bits.
bool runs_flat(const ir::Tape& tape);

// Whether boxes evaluated side by side run on the vector kernels (backend/interp/lane_kernels.hpp) when
// the CPU has them (the default), or on the scalar kernels lane by lane (the same results, for tests and
// benchmarks). Returns whether the vector kernels are now in use.
bool use_vector_lanes(bool wanted);

// Requires runs_flat(tape).
std::unique_ptr<ir::Evaluator> make_flat_interpreter(const ir::Tape& tape, const ir::EvalOptions& options);

} // namespace frac::interp
