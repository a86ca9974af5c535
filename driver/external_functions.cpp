#include "driver/external_functions.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

namespace frac::driver {

AttractorDistanceFunction::AttractorDistanceFunction(const ir::Automaton& a, std::string automaton_name,
                                                     rt::DistanceOptions options)
    : distance_(a, options), name_(std::move(automaton_name)) {}

rt::DistanceOptions AttractorDistanceFunction::default_options() {
    rt::DistanceOptions o;
    o.epsilon = 1e-6;
    return o;
}

num::Interval AttractorDistanceFunction::eval_box(const num::Interval* args) const {
    const int d = distance_.dimension();
    for (int k = 0; k < d; ++k)
        if (args[k].is_empty()) return num::Interval::empty();
    for (int k = 0; k < d; ++k)
        if (!std::isfinite(args[k].lo) || !std::isfinite(args[k].hi))
            return {0.0, std::numeric_limits<double>::infinity()}; // a distance, unbounded box
    return distance_.eval_box(args);
}

double AttractorDistanceFunction::eval_point(const double* args) const {
    const int d = distance_.dimension();
    for (int k = 0; k < d; ++k) {
        if (std::isnan(args[k])) return std::numeric_limits<double>::quiet_NaN();
        if (std::isinf(args[k])) return std::numeric_limits<double>::infinity();
    }
    const num::Interval r = distance_.eval_point(args);
    return num::midpoint(r);
}

void bind_externals(front::Module& m, front::Diagnostics& diags) {
    m.graph.externals.resize(m.externals.size());
    for (std::size_t k = 0; k < m.externals.size(); ++k) {
        const front::ExternalUse& use = m.externals[k];
        switch (use.kind) {
        case front::ExternalUse::Kind::distance: {
            if (use.automaton >= m.automata.size()) break; // its error is reported
            try {
                m.graph.externals[k] = std::make_shared<AttractorDistanceFunction>(
                    m.automata[use.automaton].automaton, use.automaton_name);
            } catch (const std::invalid_argument& e) {
                diags.error(use.loc, fmt::format("cannot compute distances to '{}': {}", use.automaton_name,
                                                 e.what()));
            }
            break;
        }
        }
    }
}

} // namespace frac::driver
