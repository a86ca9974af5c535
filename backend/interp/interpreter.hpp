// The reference interpreter: runs a tape instruction by instruction, on points and on boxes.
#pragma once

#include "ir/evaluator.hpp"
#include "ir/tape.hpp"

#include <memory>

namespace frac::interp {

std::unique_ptr<ir::Evaluator> make_interpreter(ir::Tape tape, const ir::EvalOptions& options = {});

} // namespace frac::interp
