#include "driver/external_functions.hpp"

#include <stdexcept>

#include <fmt/format.h>

namespace frac::driver {

void bind_externals(front::Module& m, front::Diagnostics& diags) {
    m.graph.externals.resize(m.externals.size());
    for (std::size_t k = 0; k < m.externals.size(); ++k) {
        const front::ExternalUse& use = m.externals[k];
        switch (use.kind) {
        case front::ExternalUse::Kind::distance: {
            if (use.automaton >= m.automata.size()) break; // its error is reported
            try {
                m.graph.externals[k] = std::make_shared<AttractorDistanceFunction>(
                    rt::AttractorDistance(m.automata[use.automaton].automaton,
                                          AttractorDistanceFunction::default_options()),
                    use.automaton_name);
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
