#include "ir/evaluator.hpp"

namespace frac::ir {

void Evaluator::eval_points(const double* coords, std::size_t n, double* out) {
    const int d = dimension();
    for (std::size_t i = 0; i < n; ++i) out[i] = eval_point(coords + i * d);
}

void Evaluator::eval_boxes(const Interval* boxes, std::size_t n, Interval* out) {
    const int d = dimension();
    for (std::size_t i = 0; i < n; ++i) out[i] = eval_box(boxes + i * d);
}

} // namespace frac::ir
