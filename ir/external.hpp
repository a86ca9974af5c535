// A function the IR does not define, called by an Op::External node: for example the distance to the
// attractor of an automaton (driver/external_functions.hpp), which lives in the runtime. The graph and
// the tape hold implementations by pointer; the engines call them (interpreter directly, the JIT
// through a C helper with the pointer as a constant), so an implementation must be thread-safe.
#pragma once

#include "numeric/interval.hpp"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

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

    // How a compiled model (frac compile) carries the function: it cannot hold a pointer into this
    // process, so it embeds `data` and, at its first call, asks the C function `resolve` of the run-time
    // archive `archive` (a file next to the frac binary) to rebuild the function from it; `release`
    // frees that when the model is unloaded. Both take an ExternalData*. nullopt: not compilable.
    struct Compiled {
        std::string archive;          // "libfrac_aot_automata.a"
        std::string resolve, release; // C symbols in the archive
        std::vector<std::uint8_t> data;
    };
    virtual std::optional<Compiled> compiled() const { return std::nullopt; }
};

// A compiled model's record of one external function, laid out as the generated code emits it
// (backend/llvm/aot.cpp): the function rebuilt from the data (null until the first call; written
// once, with atomic_ref), and the embedded data.
struct ExternalData {
    const ExternalFunction* function;
    std::uint64_t size;
    const std::uint8_t* data;
};

} // namespace frac::ir
