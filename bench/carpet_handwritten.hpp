// The Sierpinski carpet of stdlib/fractals.frac written by hand in C++ interval arithmetic, as the
// yardstick for the JIT:
//   carpet(x, y) = min(i in 0.., (1/3 - min(dz(3^i x), dz(3^i y))) / 3^i)
// The same operations as the numeric core (upward rounding set once per batch, lower bounds as
// -RU(-a op b)), the same adaptive term rule and tail as the interpreter, tables of 3^i and of the
// stopping thresholds computed once. Its results are bit-identical to the interpreter's.
#pragma once

#include "ir/evaluator.hpp"

#include <memory>

namespace frac::bench {

// An evaluator of the hand-written carpet (dimension 2) for the given term limit.
std::unique_ptr<ir::Evaluator> make_carpet_handwritten(int max_terms = 128);

} // namespace frac::bench
