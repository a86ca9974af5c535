// Name resolution: every name used is defined, every call has the right number of arguments,
// no name is defined twice. Reports every problem it finds; elaboration runs only on a clean program.
#pragma once

#include "frontend/ast.hpp"

namespace frac::front {

void resolve_names(const Program& program, Diagnostics& diags);

} // namespace frac::front
