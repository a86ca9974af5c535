// A function the IR does not define, called by an Op::External node: for example the distance to the
// attractor of an automaton (driver/external_functions.hpp), which lives in the runtime. The graph and
// the tape hold implementations by pointer; the engines call them (interpreter directly, the JIT
// through a C helper with the pointer as a constant), so an implementation must be thread-safe.
#pragma once

#include "numeric/interval.hpp"

#include <string>

namespace frac::ir {

class ExternalFunction {
public:
    virtual ~ExternalFunction() = default;
    // Coordinates read (1 to 3); the External node passes three, the rest are ignored.
    virtual int arity() const = 0;
    // A proven enclosure of the values over the box args[0..arity()-1] (empty when a box is empty).
    virtual num::Interval eval_box(const num::Interval* args) const = 0;
    // The value at a point, deterministic (round to nearest where it is not exact).
    virtual double eval_point(const double* args) const = 0;
    // For printers and messages ("dist sierpinski").
    virtual std::string name() const = 0;
};

} // namespace frac::ir
