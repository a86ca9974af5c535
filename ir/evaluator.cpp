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

std::shared_ptr<Evaluator> Evaluator::specialize(const Interval*, double) {
    return nullptr;
}

EvalStats& EvalStats::operator+=(const EvalStats& o) {
    calls += o.calls;
    series_terms += o.series_terms;
    series_capped += o.series_capped;
    return *this;
}

SpecializeStats& SpecializeStats::operator+=(const SpecializeStats& o) {
    requests += o.requests;
    unpruned += o.unpruned;
    too_little += o.too_little;
    declined += o.declined;
    hits += o.hits;
    compiled += o.compiled;
    pushes += o.pushes;
    fallbacks += o.fallbacks;
    compile_ms += o.compile_ms;
    record_ms += o.record_ms;
    prune_ms += o.prune_ms;
    return *this;
}

} // namespace frac::ir
