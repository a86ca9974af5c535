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

// Evaluation time per unit of tape cost (ir::tape_cost) and box, measured by bench/bench_prune: the
// tape interpreter (tapes with series or external functions) on the pruned tapes of its CSG scene,
// the flat interpreter (four boxes side by side on vector kernels) on those of a 300-clause model.
// They weigh against the JIT's jit_prune_costs.eval_ns_per_cost (0.8), so they keep the ratios
// measured in one run: the flat interpreter 1.42 ns per cost, the JIT 0.35 and the tape interpreter
// 12.7 (a quiet run: 4.0 and 36 times the JIT; the tape interpreter's 33 is 41 times the JIT's 0.8;
// docs/performance.md "The JIT's second tier"): 3.2 is 4.0 times the JIT's constant.
inline constexpr double flat_eval_ns_per_cost = 3.2;
inline constexpr double tape_eval_ns_per_cost = 33.0;
// That of the interpreter make_interpreter picks for `tape`.
double eval_ns_per_cost(const ir::Tape& tape);

// What an evaluation of a pruned tape costs the interpreter in a cover apart from the tape's
// instructions (in the unit of the constants above): the call on a parent's few children at a time,
// the cell's box, its verdict and the pushes below it (bench/bench_prune part 1b measures it from
// pruned covers; docs/performance.md "The JIT's pruning on short tapes").
inline constexpr double cover_eval_ns_fixed = 260.0;
// Time per evaluation of `tape` in a pruned cover: the fixed part and the tape's.
double cover_eval_ns(const ir::Tape& tape);

// What specialising costs the interpreter (a tape copy, no compilation), measured by bench/bench_prune;
// its evaluation time is the tape interpreter's (eval_ns_per_cost tells a flat tape's).
inline constexpr ir::PruneCosts interp_prune_costs{.eval_ns_per_cost = tape_eval_ns_per_cost,
                                                   .compile_ns_fixed = 2000.0,
                                                   .compile_ns_per_instruction = 0.0,
                                                   .eval_ns_fixed = cover_eval_ns_fixed};

// Recording the choices over a box and building the pruned tape (its memory, fresh, faulted in;
// and a variant of the cover) cost more than the 12 expected descendants of a 2D cell two levels
// above the depth save (bench/bench_large quick, one thread, the Zen 5 VM: 1000, 3000 and 7000
// clauses 698, 926, 1258 ns per evaluation pushing there, 572, 795, 1124 not; one level above, 4
// descendants: 3.3 against 2.3 µs on 1000 clauses): the interpreter prunes for cells with more than
// this many expected descendant evaluations (2D: 3 levels above the depth, 28; 3D: 2, 40).
inline constexpr double interp_min_expected_evaluations = 16;

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
