// The reference interpreter: runs a tape instruction by instruction, on points and on boxes.
#pragma once

#include "ir/evaluator.hpp"
#include "ir/specialize.hpp"
#include "ir/tape.hpp"

#include <memory>

namespace frac::interp {

std::unique_ptr<ir::Evaluator> make_interpreter(ir::Tape tape, const ir::EvalOptions& options = {});

// What specialising costs the interpreter (a tape copy, no compilation), measured by bench/bench_prune.
inline constexpr ir::PruneCosts interp_prune_costs{/*eval_ns_per_cost=*/33.0, /*compile_ns_fixed=*/2000.0,
                                                   /*compile_ns_per_instruction=*/0.0};

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
