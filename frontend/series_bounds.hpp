// Static bounds of series terms. For an infinite series, the compiler proves that every term t_i
// (i >= start >= 0) lies in (A + B i) gamma^i, with A, B enclosed at run time by graph nodes that do
// not depend on i (they may depend on the coordinates), and a constant decay 0 < gamma < 1. From that
// form every engine derives a sound tail enclosure after any number of terms (ir/series_tail).
#pragma once

#include "ir/graph.hpp"

#include <optional>
#include <string>

namespace frac::front {

struct TermBound {
    ir::NodeId a = ir::no_node;
    ir::NodeId b = ir::no_node; // no_node: B = 0
    ir::Interval gamma{1.0, 1.0};
    // Why the terms have no lower (upper) bound, when they have none: a min series needs only a
    // lower bound, a max series only an upper bound, a sum both.
    std::string no_lower, no_upper;
};

// Derives the bound of `term` as a function of the index of series `level`, for a series of `kind`
// (SeriesSum/Min/Max). On failure returns nullopt and sets `why` to a sentence saying what cannot be
// bounded.
std::optional<TermBound> bound_series_term(ir::Graph& g, ir::NodeId term, int level, ir::Op kind,
                                           std::string& why);

} // namespace frac::front
