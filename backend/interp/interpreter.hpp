// The reference interpreter: runs a tape instruction by instruction, on points and on boxes.
#pragma once

#include "ir/evaluator.hpp"
#include "ir/specialize.hpp"
#include "ir/tape.hpp"

#include <memory>

namespace frac::interp {

// Flat tapes (backend/interp/flat_interpreter.hpp) run on the flat interpreter, others on the tape
// interpreter below.
std::unique_ptr<ir::Evaluator> make_interpreter(ir::Tape tape, const ir::EvalOptions& options = {});
// The interpreter of any tape (series and external functions included), instruction by instruction:
// the reference the flat interpreter is tested against.
std::unique_ptr<ir::Evaluator> make_tape_interpreter(ir::Tape tape, const ir::EvalOptions& options = {});

// What specialising costs the interpreter (a tape copy, no compilation), measured by bench/bench_prune.
inline constexpr ir::PruneCosts interp_prune_costs{/*eval_ns_per_cost=*/33.0, /*compile_ns_fixed=*/2000.0,
                                                   /*compile_ns_per_instruction=*/0.0};

// Recording the choices over a box and building the pruned tape cost about as much as the 4
// children of a 2D cell one level above the depth could save (bench/bench_large: 3.3 µs per
// evaluation when those cells prune too, 2.3 µs without, on a 1000-clause model): the interpreter
// prunes for cells with at least this many expected descendant evaluations (2D: 2 levels above the
// depth; 3D: 1).
inline constexpr double interp_min_expected_evaluations = 8;

// Records the min/max/select choices of a tape over boxes with the interpreter (ir/specialize.hpp):
// how engines without a register file of their own (the JIT) learn what to prune.
class ChoiceRecorder {
public:
    ChoiceRecorder(const ir::Tape& tape, const ir::EvalOptions& options);
    ~ChoiceRecorder();
    std::vector<ir::Choice> record(const ir::Interval* box);

private:
    std::unique_ptr<ir::Evaluator> interp_;
};

} // namespace frac::interp
