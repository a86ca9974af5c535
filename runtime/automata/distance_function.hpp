// dist(p, A) as an external function of the IR (ir/external.hpp): the distance to the attractor of an
// automaton by branch and bound (AttractorDistance). The driver binds it to the models that call dist;
// compiled models embed its serialized form and rebuild it through the C entry points below, which
// libfrac_aot_automata.a provides with the queries (distance_query.cpp) and nothing else of Frac.
#pragma once

#include "ir/external.hpp"
#include "runtime/automata/distance.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

namespace frac::rt {

// Boxes: the proven enclosure of the distance; points: the midpoint of the point's proven enclosure
// (within epsilon / 2 of the distance). Const and thread-safe.
class AttractorDistanceFunction final : public ir::ExternalFunction {
public:
    AttractorDistanceFunction(AttractorDistance distance, std::string automaton_name);

    // The options models are compiled with (epsilon 1e-6).
    static DistanceOptions default_options();
    // The function compiled()->data describes; throws std::invalid_argument on malformed data.
    static AttractorDistanceFunction from_compiled(const std::uint8_t* data, std::size_t size);

    int arity() const override { return distance_.dimension(); }
    num::Interval eval_box(const num::Interval* args) const override;
    double eval_point(const double* args) const override;
    std::string name() const override { return "dist " + name_; }
    std::optional<Compiled> compiled() const override;

    const AttractorDistance& distance() const { return distance_; }

private:
    AttractorDistance distance_;
    std::string name_;
};

} // namespace frac::rt

extern "C" {
// The function of a compiled model's record, rebuilt from its data at the first call (thread-safe: the
// first to finish publishes it, the others discard theirs); null when the data is malformed, which
// the helpers answer with "anything" (the entire line, NaN).
const frac::ir::ExternalFunction* frac_aot_attractor_distance(frac::ir::ExternalData* record) noexcept;
// Frees what frac_aot_attractor_distance built (the model's destructor calls it when it is unloaded).
void frac_aot_attractor_distance_release(frac::ir::ExternalData* record) noexcept;
}
