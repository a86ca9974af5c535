// Synthetic ground truth for fitting: fractal functions with known maps, and their feature points (seed
// 001 sec. 4.1: the fixed points of the maps and their images under compositions).
#pragma once

#include "runtime/fit/data.hpp"
#include "runtime/fit/model.hpp"

#include <string>
#include <vector>

namespace frac::rt::fit {

// Table 1 of seed 001: two shears over t in [-1, 1] (Fig. 2).
FractalFunction table1_fif();

// The hidden-variable Sierpinski space curve (seed 001 Fig. 3; Barnsley et al. 1989): three maps of
// (t, x, y), t -> (t + i) / 3, each a half-size copy of the Sierpinski triangle's corner with the
// orientation of the arrowhead curve, so (x, y)(t) is a continuous curve through the gasket; the maps of
// the first and last thirds mix x and y (eq. 9), so x(t) alone is not self-affine.
FractalFunction sierpinski_space_curve();

// The end points of the graph mapped by every composition of `level` maps, sorted by t, one point per t
// (2^level + 1 points for a FIF of two maps). Every domain must be the whole interval.
Samples feature_points(const FractalFunction& f, int level);

// The named generator's function: "table1" or "sierpinski"; empty when unknown.
std::vector<std::string> generator_names();
FractalFunction generator(const std::string& name);

} // namespace frac::rt::fit
