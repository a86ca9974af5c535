// The size of definitions once their calls are inlined, counted on the syntax tree before the type
// checker and lowering inline them: a chain of functions each calling the previous one twice doubles at
// each level (24 lines make 2^24 copies), which would take minutes and gigabytes to build.
#pragma once

#include "frontend/ast.hpp"
#include "frontend/lower.hpp"

namespace frac::front {

// Reports each shape, constant, test or print whose inlined expression passes limits.max_inline_nodes,
// at the definition, with the chain of calls that makes it large. Calls of functions passed as arguments
// count as one node (their callee is known only when inlined); direct calls count their callee's size.
void check_inline_size(const Program& program, const Limits& limits, Diagnostics& diags);

} // namespace frac::front
