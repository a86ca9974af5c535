// The meaning of each arithmetic and logic opcode, on intervals (guaranteed enclosures; upward
// rounding must be active) and on points (round to nearest). Shared by constant folding and the
// interpreter, so there is one definition of every operation.
#pragma once

#include "ir/graph.hpp"

namespace frac::ir {

// args holds arity(op) values. Not for leaf or series ops.
Interval apply_interval(Op op, const Interval* args, std::int64_t imm);
double apply_point(Op op, const double* args, std::int64_t imm);

// Three-valued truth values as intervals.
inline constexpr Interval tv_false{0.0, 0.0};
inline constexpr Interval tv_true{1.0, 1.0};
inline constexpr Interval tv_unknown{0.0, 1.0};

} // namespace frac::ir
