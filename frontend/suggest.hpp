// "Did you mean" suggestions for misspelt names, shared by the compiler's diagnostics and the CLI.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace frac::front {

// Optimal string alignment (Damerau-Levenshtein) distance: insertions, deletions, substitutions and
// swaps of adjacent characters each cost 1. Letter case is ignored.
std::size_t edit_distance(const std::string& a, const std::string& b);

// The candidate closest to `name`, when it is close enough to be a likely misspelling (distance at
// most 2 and a third of the name's length, at least 1; names of 1 or 2 letters: a difference of case
// only); ties go to the first.
std::optional<std::string> closest_name(const std::string& name, const std::vector<std::string>& candidates);

// "name1, name2, name3" (or "none").
std::string list_names(const std::vector<std::string>& names);

} // namespace frac::front
