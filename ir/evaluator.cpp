#include "ir/evaluator.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace frac::ir {

namespace {

// most[a] = the largest of coords[k * stride + a] over k < n, a < D.
template <int D>
void largest(const std::uint32_t* coords, std::size_t stride, std::size_t n, std::uint32_t* most) {
    std::uint32_t m[D] = {};
    for (std::size_t k = 0; k < n; ++k, coords += stride)
        for (int a = 0; a < D; ++a) m[a] = std::max(m[a], coords[a]);
    std::copy_n(m, D, most);
}

} // namespace

void CellGrid::check_shape(int dimension, const std::uint64_t* cells) {
    if (dimension < 1 || dimension > 3)
        throw std::invalid_argument("cell grid: " + std::to_string(dimension) + " axes; it takes 1 to 3");
    for (int a = 0; a < dimension; ++a)
        if (cells[a] > (std::uint64_t{1} << 32))
            throw std::invalid_argument("cell grid: " + std::to_string(cells[a]) + " cells along axis " +
                                        std::to_string(a) + "; at most 2^32 (coordinates are 32-bit)");
}

void CellGrid::check(int dimension, const std::uint32_t* coords, std::size_t stride, std::size_t n) const {
    if (dimension != dimension_)
        throw std::invalid_argument("eval_cells: a grid of " + std::to_string(dimension_) +
                                    " axes for a function of " + std::to_string(dimension) + " coordinates");
    const auto d = static_cast<std::size_t>(dimension);
    if (stride < d)
        throw std::invalid_argument("eval_cells: stride " + std::to_string(stride) + " below the " +
                                    std::to_string(d) + " coordinates of a cell");
    if (n == 0) return;
    // The largest coordinate per axis (in registers: about a cycle a cell); the cells at fault are
    // looked for only on failure.
    std::uint32_t most[3] = {0, 0, 0};
    if (d == 1) largest<1>(coords, stride, n, most);
    if (d == 2) largest<2>(coords, stride, n, most);
    if (d == 3) largest<3>(coords, stride, n, most);
    bool bad = false;
    for (std::size_t a = 0; a < d; ++a) bad |= most[a] >= axes_[a].size();
    if (!bad) return;
    for (std::size_t k = 0; k < n; ++k)
        for (std::size_t a = 0; a < d; ++a)
            if (coords[k * stride + a] >= axes_[a].size())
                throw std::out_of_range("eval_cells: cell " + std::to_string(k) + " has coordinate " +
                                        std::to_string(coords[k * stride + a]) + " along axis " +
                                        std::to_string(a) + ", outside the grid's " +
                                        std::to_string(axes_[a].size()) + " cells");
}

void Evaluator::eval_points(const double* coords, std::size_t n, double* out) {
    const int d = dimension();
    for (std::size_t i = 0; i < n; ++i) out[i] = eval_point(coords + i * d);
}

void Evaluator::eval_boxes(const Interval* boxes, std::size_t n, Interval* out) {
    const int d = dimension();
    for (std::size_t i = 0; i < n; ++i) out[i] = eval_box(boxes + i * d);
}

void Evaluator::eval_cells(const CellGrid& grid, const std::uint32_t* coords, std::size_t stride,
                           std::size_t n, CellVerdict* out, bool closed_inside) {
    grid.check(dimension(), coords, stride, n);
    const auto d = static_cast<std::size_t>(dimension());
    // One eval_boxes call for the n cells, as a caller building the boxes itself would make.
    std::vector<Interval> boxes(n * d), values(n);
    for (std::size_t k = 0; k < n; ++k) grid.box(coords + k * stride, &boxes[k * d]);
    eval_boxes(boxes.data(), n, values.data());
    for (std::size_t k = 0; k < n; ++k) out[k] = classify(values[k], closed_inside);
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
