// Implementations of the IR's external functions (ir/external.hpp) by the runtime, bound to the
// graph of a compiled model after lowering (driver/pipeline.cpp): the frontend describes each External
// node (front::ExternalUse), the driver is where runtime code may be attached to IR.
#pragma once

#include "frontend/module.hpp"
#include "ir/external.hpp"
#include "runtime/automata/distance.hpp"

#include <memory>
#include <string>

namespace frac::driver {

// dist(p, A): the distance from p to the attractor of A, by the runtime's branch and bound
// (rt::AttractorDistance). Boxes: its proven enclosure; points: the midpoint of the point's proven
// enclosure (within epsilon / 2 of the distance). Const and thread-safe.
class AttractorDistanceFunction final : public ir::ExternalFunction {
public:
    // Throws std::invalid_argument as rt::AttractorDistance does.
    AttractorDistanceFunction(const ir::Automaton& a, std::string automaton_name,
                              rt::DistanceOptions options = default_options());

    static rt::DistanceOptions default_options();

    int arity() const override { return distance_.dimension(); }
    num::Interval eval_box(const num::Interval* args) const override;
    double eval_point(const double* args) const override;
    std::string name() const override { return "dist " + name_; }

    const rt::AttractorDistance& distance() const { return distance_; }

private:
    rt::AttractorDistance distance_;
    std::string name_;
};

// Binds an implementation to every external function of the module (Module::externals) in its graph.
// A use that cannot be bound (an automaton whose distance the runtime cannot bound) is an error at
// its location in `diags`.
void bind_externals(front::Module& m, front::Diagnostics& diags);

} // namespace frac::driver
