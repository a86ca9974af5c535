// Implementations of the IR's external functions (ir/external.hpp) by the runtime, bound to the
// graph of a compiled model after lowering (driver/pipeline.cpp): the frontend describes each External
// node (front::ExternalUse), the driver is where runtime code may be attached to IR.
#pragma once

#include "frontend/module.hpp"
#include "ir/external.hpp"
#include "runtime/automata/distance_function.hpp"

#include <memory>
#include <string>

namespace frac::driver {

// dist(p, A): the distance from p to the attractor of A (runtime/automata/distance_function.hpp).
using AttractorDistanceFunction = rt::AttractorDistanceFunction;

// Binds an implementation to every external function of the module (Module::externals) in its graph.
// A use that cannot be bound (an automaton whose distance the runtime cannot bound) is an error at
// its location in `diags`.
void bind_externals(front::Module& m, front::Diagnostics& diags);

} // namespace frac::driver
