#include "runtime/fit/projected_ifs.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

namespace frac::rt::fit {

namespace {

std::size_t ceil_div(std::size_t a, std::size_t b) {
    return (a + b - 1) / b;
}

std::size_t power(std::size_t base, int p) {
    std::size_t r = 1;
    for (int i = 0; i < p; ++i) r *= base;
    return r;
}

// Bilinear sample of the data at (x, y) in sample units.
double sample_data(const HeightGrid& g, double x, double y) {
    const auto x0 = std::min(static_cast<std::size_t>(x), g.width - 2);
    const auto y0 = std::min(static_cast<std::size_t>(y), g.height - 2);
    const double u = x - static_cast<double>(x0), v = y - static_cast<double>(y0);
    return (1 - v) * ((1 - u) * g.at(x0, y0) + u * g.at(x0 + 1, y0)) +
           v * ((1 - u) * g.at(x0, y0 + 1) + u * g.at(x0 + 1, y0 + 1));
}

} // namespace

PatchParameters::PatchParameters(const PatchShape& shape) : shape_(shape) {
    const std::size_t k = shape.controls, n = shape.split;
    if (k < 2 || k > 8) throw std::invalid_argument("a control grid has 2 to 8 points per side");
    if (n < 2 || n > 8) throw std::invalid_argument("a patch is split 2 to 8 times per side");
    if (shape.depth < 1 || shape.depth > 12 || power(n, shape.depth) > 4096)
        throw std::invalid_argument("the tabulation depth p must be at least 1, with N^p at most 4096");
    const std::size_t g = grid_side(), m = k - 1;
    count_ = k * k; // the heights
    // Grid position a sits at a / N in control-grid units: between control points a / N and ceil(a / N).
    auto span = [&](std::size_t a) {
        std::vector<std::size_t> s{a / n};
        if (ceil_div(a, n) != a / n) s.push_back(ceil_div(a, n));
        return s;
    };
    for (std::size_t a = 0; a < g; ++a) {
        Point p{span(a), count_};
        count_ += p.support.size() - 1;
        edge_.push_back(p);
    }
    face_.resize(g * g);
    for (std::size_t b = 0; b < g; ++b)
        for (std::size_t a = 0; a < g; ++a) {
            Point& p = face_[a + g * b];
            // The border is the edge's points embedded in the four sides (incidence): B0 bottom (row 0),
            // B3 top (row m) along the columns, B1 left (column 0), B2 right (column m) along the rows.
            if (b == 0 || b == g - 1) {
                p.first = edge_[a].first;
                for (std::size_t c : edge_[a].support) p.support.push_back(k * (b == 0 ? 0 : m) + c);
            } else if (a == 0 || a == g - 1) {
                p.first = edge_[b].first;
                for (std::size_t r : edge_[b].support) p.support.push_back(k * r + (a == 0 ? 0 : m));
            } else {
                for (std::size_t r : span(b))
                    for (std::size_t c : span(a)) p.support.push_back(k * r + c);
                p.first = count_;
                count_ += p.support.size() - 1;
            }
        }
    if (shape.positions) count_ += 2 * k * k;
}

std::vector<double> PatchParameters::initial(const HeightGrid& data) const {
    const std::size_t k = shape_.controls, n = shape_.split;
    std::vector<double> x(count_, 0.0);
    if (shape_.positions)
        for (std::size_t q = 0; q < k * k; ++q) {
            x[position_first() + q] = regular_position(1, q, data);
            x[position_first() + k * k + q] = regular_position(2, q, data);
        }
    for (std::size_t q = 0; q < k * k; ++q)
        x[q] = sample_data(data, control(x, 1, q, data), control(x, 2, q, data));
    // The linear weights of a position between its two control points (the first of them is free).
    auto frac_part = [&](std::size_t a) { return static_cast<double>(a % n) / static_cast<double>(n); };
    const std::size_t g = grid_side();
    for (std::size_t a = 0; a < g; ++a)
        if (edge_[a].support.size() == 2) x[edge_[a].first] = 1 - frac_part(a);
    for (std::size_t b = 1; b + 1 < g; ++b)
        for (std::size_t a = 1; a + 1 < g; ++a) {
            const Point& p = face_[a + g * b];
            const double u = frac_part(a), v = frac_part(b);
            if (p.support.size() == 4) {
                x[p.first] = (1 - u) * (1 - v);
                x[p.first + 1] = u * (1 - v);
                x[p.first + 2] = (1 - u) * v;
            } else if (p.support.size() == 2) {
                x[p.first] = a % n != 0 ? 1 - u : 1 - v;
            }
        }
    return x;
}

double PatchParameters::control(const std::vector<double>& params, std::size_t coordinate, std::size_t q,
                                const HeightGrid& data) const {
    const std::size_t k = shape_.controls;
    if (coordinate == 0) return params[q];
    if (shape_.positions) return params[position_first() + (coordinate - 1) * k * k + q];
    return regular_position(coordinate, q, data);
}

double PatchParameters::regular_position(std::size_t coordinate, std::size_t q,
                                         const HeightGrid& data) const {
    const std::size_t k = shape_.controls;
    const std::size_t index = coordinate == 1 ? q % k : q / k;
    const std::size_t samples = coordinate == 1 ? data.width : data.height;
    return static_cast<double>(index) / static_cast<double>(k - 1) * static_cast<double>(samples - 1);
}

namespace {

// Dense barycentric points from their free weights: `dim` weights a point.
std::vector<double> dense_points(const std::vector<PatchParameters::Point>& points, std::size_t dim,
                                 const std::vector<double>& params) {
    std::vector<double> w(points.size() * dim, 0.0);
    for (std::size_t i = 0; i < points.size(); ++i) {
        const auto& p = points[i];
        double rest = 1;
        for (std::size_t s = 0; s + 1 < p.support.size(); ++s) {
            w[i * dim + p.support[s]] = params[p.first + s];
            rest -= params[p.first + s];
        }
        w[i * dim + p.support.back()] = rest;
    }
    return w;
}

} // namespace

std::vector<double> PatchParameters::face_weights(const std::vector<double>& params) const {
    return dense_points(face_, shape_.controls * shape_.controls, params);
}

std::vector<double> PatchParameters::edge_weights(const std::vector<double>& params) const {
    return dense_points(edge_, shape_.controls, params);
}

PatchEvaluator::PatchEvaluator(const PatchParameters& layout, const HeightGrid& data)
    : layout_(layout), data_(data) {
    const auto& shape = layout.shape();
    const std::size_t n = shape.split, m = shape.controls - 1, g = layout.grid_side();
    const std::size_t cells = power(n, shape.depth);
    side_ = cells + 1;
    // Each vertex's address: the digits (sigma, tau) of i / N^p and j / N^p, the last one picking a
    // corner of the sub-patch it ends in (the point lambda there).
    addresses_.resize(side_ * side_);
    for (std::size_t j = 0; j < side_; ++j)
        for (std::size_t i = 0; i < side_; ++i) {
            auto& address = addresses_[i + side_ * j];
            std::size_t ri = i, rj = j, unit = cells;
            std::size_t last_i = 0, last_j = 0;
            for (int l = 1; l <= shape.depth; ++l) {
                unit /= n;
                const std::size_t si = std::min(ri / unit, n - 1), sj = std::min(rj / unit, n - 1);
                ri -= si * unit;
                rj -= sj * unit;
                if (l < shape.depth)
                    address.push_back(si + n * sj);
                else {
                    last_i = si;
                    last_j = sj;
                }
            }
            address.push_back((m * last_i + m * ri) + g * (m * last_j + m * rj));
        }
    samples_.resize(data.width * data.height);
    for (std::size_t y = 0; y < data.height; ++y)
        for (std::size_t x = 0; x < data.width; ++x) {
            const double fx = static_cast<double>(x) / static_cast<double>(data.width - 1) * cells;
            const double fy = static_cast<double>(y) / static_cast<double>(data.height - 1) * cells;
            const auto i0 = std::min(static_cast<std::size_t>(fx), cells - 1);
            const auto j0 = std::min(static_cast<std::size_t>(fy), cells - 1);
            const double u = fx - static_cast<double>(i0), v = fy - static_cast<double>(j0);
            Sample& s = samples_[y * data.width + x];
            const std::size_t base = i0 + side_ * j0;
            s.vertex[0] = base, s.weight[0] = (1 - u) * (1 - v);
            s.vertex[1] = base + 1, s.weight[1] = u * (1 - v);
            s.vertex[2] = base + side_, s.weight[2] = (1 - u) * v;
            s.vertex[3] = base + side_ + 1, s.weight[3] = u * v;
        }
    contribution_start_.assign(side_ * side_ + 1, 0);
    for (const Sample& s : samples_)
        for (int c = 0; c < 4; ++c)
            if (s.weight[c] != 0) ++contribution_start_[s.vertex[c] + 1];
    for (std::size_t v = 0; v < side_ * side_; ++v) contribution_start_[v + 1] += contribution_start_[v];
    contributions_.resize(contribution_start_.back());
    std::vector<std::size_t> fill(contribution_start_.begin(), contribution_start_.end() - 1);
    for (std::size_t i = 0; i < samples_.size(); ++i)
        for (int c = 0; c < 4; ++c)
            if (samples_[i].weight[c] != 0)
                contributions_[fill[samples_[i].vertex[c]]++] = {i, samples_[i].weight[c]};
}

void PatchEvaluator::vertices(const std::vector<double>& params, std::vector<double>& value,
                              const GradientSink* on_gradient) const {
    const auto& shape = layout_.shape();
    const std::size_t k = shape.controls, kk = k * k, n = shape.split, m = k - 1, g = layout_.grid_side();
    const std::size_t count = layout_.count(), coordinates = layout_.coordinate_count();
    const std::size_t vertex_count = addresses_.size();
    const std::vector<double> lambda = layout_.face_weights(params);
    const auto& points = layout_.face_points();
    // Column q = k r + c of sub-patch T(i + N j) is the grid point (m i + c, m j + r).
    std::vector<std::size_t> column_point(n * n * kk);
    for (std::size_t j = 0; j < n; ++j)
        for (std::size_t i = 0; i < n; ++i)
            for (std::size_t r = 0; r < k; ++r)
                for (std::size_t c = 0; c < k; ++c)
                    column_point[(i + n * j) * kk + k * r + c] = (m * i + c) + g * (m * j + r);
    // The control points' coordinates (a row P of the projection) and where their parameters are.
    std::vector<double> control(coordinates * kk);
    std::vector<std::size_t> control_first(coordinates);
    for (std::size_t c = 0; c < coordinates; ++c) {
        for (std::size_t q = 0; q < kk; ++q) control[c * kk + q] = layout_.control(params, c, q, data_);
        control_first[c] = c == 0 ? 0 : layout_.position_first() + (c - 1) * kk;
    }
    const std::size_t levels = static_cast<std::size_t>(shape.depth);
    value.assign(vertex_count * coordinates, 0.0);
    std::vector<double> gradient(on_gradient ? count : 0);
    // cols[l]: T_(l+1) ... T_(p-1) lambda_last (cols[p-1] = lambda_last); rows[l]: P T_1 ... T_l.
    std::vector<double> cols(levels * kk), rows(levels * kk);
    for (std::size_t v = 0; v < vertex_count; ++v) {
        const auto& address = addresses_[v];
        const std::size_t ops = address.size() - 1;
        const double* last = &lambda[address.back() * kk];
        std::copy(last, last + kk, &cols[ops * kk]);
        for (std::size_t l = ops; l-- > 0;) {
            const std::size_t* column = &column_point[address[l] * kk];
            double* out = &cols[l * kk];
            std::fill(out, out + kk, 0.0);
            const double* in = &cols[(l + 1) * kk];
            for (std::size_t q = 0; q < kk; ++q) {
                if (in[q] == 0) continue;
                const auto& p = points[column[q]];
                const double* w = &lambda[column[q] * kk];
                for (std::size_t s : p.support) out[s] += w[s] * in[q];
            }
        }
        for (std::size_t c = 0; c < coordinates; ++c) {
            const double* row0 = &control[c * kk];
            double z = 0;
            for (std::size_t q = 0; q < kk; ++q) z += row0[q] * cols[q];
            value[c * vertex_count + v] = z;
            if (!on_gradient) continue;
            double* grad = gradient.data();
            std::fill(grad, grad + count, 0.0);
            if (c == 0 || shape.positions) // d / d control coordinate
                for (std::size_t q = 0; q < kk; ++q) grad[control_first[c] + q] = cols[q];
            std::copy(row0, row0 + kk, rows.begin());
            // d / d lambda_point[s] = rows_(l-1)[s] * cols_(l+1)[q] for the point in column q of T_l;
            // then through the free weights: d / d param[first + i] = d[s_i] - d[s_last].
            auto accumulate = [&](const PatchParameters::Point& p, const double* row, double factor) {
                const double last_d = row[p.support.back()] * factor;
                for (std::size_t i = 0; i + 1 < p.support.size(); ++i)
                    grad[p.first + i] += row[p.support[i]] * factor - last_d;
            };
            for (std::size_t l = 0; l < ops; ++l) {
                const std::size_t* column = &column_point[address[l] * kk];
                const double* row = &rows[l * kk];
                const double* next = &cols[(l + 1) * kk];
                double* row_out = l + 1 < levels ? &rows[(l + 1) * kk] : nullptr;
                for (std::size_t q = 0; q < kk; ++q) {
                    const auto& p = points[column[q]];
                    const double* w = &lambda[column[q] * kk];
                    if (next[q] != 0) accumulate(p, row, next[q]);
                    double dot = 0;
                    for (std::size_t s : p.support) dot += row[s] * w[s];
                    row_out[q] = dot;
                }
            }
            accumulate(points[address.back()], &rows[ops * kk], 1.0);
            (*on_gradient)(v, c, grad);
        }
    }
}

double PatchEvaluator::target(std::size_t coordinate, std::size_t s) const {
    if (coordinate == 0) return data_.z[s];
    return static_cast<double>(coordinate == 1 ? s % data_.width : s / data_.width);
}

void PatchEvaluator::residuals_from(const std::vector<double>& value, double* out) const {
    const std::size_t vertex_count = addresses_.size(), sample_count = samples_.size();
    for (std::size_t c = 0; c < layout_.coordinate_count(); ++c)
        for (std::size_t s = 0; s < sample_count; ++s) {
            const Sample& sm = samples_[s];
            double f = 0;
            for (int i = 0; i < 4; ++i) f += sm.weight[i] * value[c * vertex_count + sm.vertex[i]];
            out[c * sample_count + s] = f - target(c, s);
        }
}

void PatchEvaluator::residuals(const std::vector<double>& params, double* out) const {
    std::vector<double> value;
    vertices(params, value, nullptr);
    residuals_from(value, out);
}

void PatchEvaluator::jacobian(const std::vector<double>& params, double* residuals_out, double* jac) const {
    // Each vertex's gradient goes straight into the rows of the samples it weighs in (one row per
    // vertex when the samples are the tabulation's vertices, the paper's case).
    const std::size_t count = layout_.count(), sample_count = samples_.size();
    std::vector<char> started(residual_count(), 0);
    const GradientSink to_rows = [&](std::size_t v, std::size_t coordinate, const double* grad) {
        for (std::size_t i = contribution_start_[v]; i < contribution_start_[v + 1]; ++i) {
            const auto [sample, w] = contributions_[i];
            const std::size_t s = coordinate * sample_count + sample;
            double* row = jac + s * count;
            if (started[s])
                for (std::size_t j = 0; j < count; ++j) row[j] += w * grad[j];
            else if (w == 1)
                std::copy(grad, grad + count, row);
            else
                for (std::size_t j = 0; j < count; ++j) row[j] = w * grad[j];
            started[s] = 1;
        }
    };
    std::vector<double> value;
    vertices(params, value, &to_rows);
    residuals_from(value, residuals_out);
}

std::vector<double> PatchEvaluator::approximation(const std::vector<double>& params) const {
    std::vector<double> r(residual_count());
    residuals(params, r.data());
    r.resize(samples_.size()); // the z residuals
    for (std::size_t s = 0; s < r.size(); ++s) r[s] += data_.z[s];
    return r;
}

namespace {

// The residual block of the whole fit: every sample's residual, every parameter, derivatives exact.
class ExactCost : public ceres::CostFunction {
public:
    explicit ExactCost(const PatchEvaluator& e) : evaluator_(e) {
        mutable_parameter_block_sizes()->push_back(static_cast<std::int32_t>(e.layout().count()));
        set_num_residuals(static_cast<int>(e.residual_count()));
    }
    bool Evaluate(double const* const* params, double* residuals, double** jacobians) const override {
        const std::vector<double> x(params[0], params[0] + evaluator_.layout().count());
        if (jacobians != nullptr && jacobians[0] != nullptr)
            evaluator_.jacobian(x, residuals, jacobians[0]);
        else
            evaluator_.residuals(x, residuals);
        return true;
    }

private:
    const PatchEvaluator& evaluator_;
};

// The same residuals for Ceres's forward differences (seed 003's perturbation of one parameter at a time).
struct ResidualFunctor {
    const PatchEvaluator* evaluator;
    bool operator()(double const* const* params, double* residuals) const {
        evaluator->residuals(std::vector<double>(params[0], params[0] + evaluator->layout().count()),
                             residuals);
        return true;
    }
};

// Progress, and the stop at the target PSNR.
// With positions the cost holds x, y residuals too: the PSNR is then of the heights at the current
// parameters (which Ceres keeps up to date for it).
class Progress : public ceres::IterationCallback {
public:
    Progress(const FitOptions& options, const HeightGrid& data, const PatchEvaluator& evaluator,
             const std::vector<double>& params, FitResult& result)
        : options_(options), data_(data), evaluator_(evaluator), params_(params),
          samples_(static_cast<double>(data.z.size())), result_(result),
          start_(std::chrono::steady_clock::now()) {}
    ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
        // An unsuccessful step reports the cost it tried; the fit stays at the best so far.
        if (summary.iteration == 0 || (summary.step_is_successful && summary.cost < best_cost_))
            best_cost_ = summary.cost;
        double mse = 2 * best_cost_ / samples_;
        if (evaluator_.layout().shape().positions) {
            const std::vector<double> z = evaluator_.approximation(params_);
            mse = 0;
            for (std::size_t s = 0; s < z.size(); ++s) mse += (z[s] - data_.z[s]) * (z[s] - data_.z[s]);
            mse /= samples_;
        }
        const double psnr = mse > 0 ? 10.0 * std::log10(data_.peak * data_.peak / mse)
                                    : std::numeric_limits<double>::infinity();
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
        result_.iterations = summary.iteration;
        if (summary.iteration > 0 && options_.progress) options_.progress(summary.iteration, psnr, seconds);
        if (options_.target_psnr > 0 && psnr >= options_.target_psnr) {
            result_.seconds_to_target = seconds;
            return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
        }
        return ceres::SOLVER_CONTINUE;
    }

private:
    const FitOptions& options_;
    const HeightGrid& data_;
    const PatchEvaluator& evaluator_;
    const std::vector<double>& params_;
    double samples_;
    FitResult& result_;
    double best_cost_ = std::numeric_limits<double>::infinity();
    std::chrono::steady_clock::time_point start_;
};

} // namespace

FitResult fit_patch(const HeightGrid& data, const FitOptions& options) {
    const PatchParameters layout(options.shape);
    const PatchEvaluator evaluator(layout, data);
    if (evaluator.residual_count() < layout.count())
        throw std::invalid_argument(fmt::format("too few samples: {} for a model of {} parameters",
                                                evaluator.residual_count(), layout.count()));
    FitResult result;
    result.params = layout.initial(data);
    ceres::Problem::Options problem_options;
    ceres::Problem problem(problem_options); // owns the cost function
    if (options.derivatives == Derivatives::exact) {
        problem.AddResidualBlock(new ExactCost(evaluator), nullptr, result.params.data());
    } else {
        auto* cost = new ceres::DynamicNumericDiffCostFunction<ResidualFunctor, ceres::FORWARD>(
            new ResidualFunctor{&evaluator});
        cost->AddParameterBlock(static_cast<int>(layout.count()));
        cost->SetNumResiduals(static_cast<int>(evaluator.residual_count()));
        problem.AddResidualBlock(cost, nullptr, result.params.data());
    }
    for (std::size_t i = layout.height_count(); i < layout.position_first(); ++i) {
        problem.SetParameterLowerBound(result.params.data(), static_cast<int>(i), options.weight_range[0]);
        problem.SetParameterUpperBound(result.params.data(), static_cast<int>(i), options.weight_range[1]);
    }
    ceres::Solver::Options solver;
    solver.minimizer_type = ceres::TRUST_REGION;
    solver.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
    solver.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
    solver.max_num_iterations = options.max_iterations;
    if (options.max_seconds > 0) solver.max_solver_time_in_seconds = options.max_seconds;
    solver.function_tolerance = 1e-10;
    solver.parameter_tolerance = 1e-10;
    solver.gradient_tolerance = 1e-14;
    solver.logging_type = ceres::SILENT;
    solver.num_threads = 1;
    solver.update_state_every_iteration = options.shape.positions;
    Progress progress(options, data, evaluator, result.params, result);
    solver.callbacks.push_back(&progress);
    ceres::Solver::Summary summary;
    ceres::Solve(solver, &problem, &summary);
    result.seconds = summary.total_time_in_seconds;
    result.stats = error_stats(data, evaluator.approximation(result.params));
    const bool finite = std::isfinite(result.stats.mse);
    if (!finite)
        result.stop_reason = "the error is not finite";
    else if (result.seconds_to_target >= 0)
        result.stop_reason = fmt::format("reached the target PSNR {:.2f} dB", options.target_psnr);
    else if (summary.termination_type == ceres::NO_CONVERGENCE)
        result.stop_reason = result.iterations >= options.max_iterations ? "the iteration budget is spent"
                                                                         : "the time budget is spent";
    else
        result.stop_reason = summary.message;
    // Without a target, a fit that ran into its budget is a result (the budget is the user's); with one,
    // only reaching it is.
    const bool stopped_well =
        summary.termination_type == ceres::CONVERGENCE || summary.termination_type == ceres::NO_CONVERGENCE;
    result.converged = finite && (options.target_psnr > 0 ? result.seconds_to_target >= 0 : stopped_well);
    return result;
}

Drift position_drift(const PatchParameters& layout, const std::vector<double>& params,
                     const HeightGrid& data) {
    PatchShape shape = layout.shape();
    shape.positions = true;
    const PatchParameters with_positions(shape);
    std::vector<double> x(params.begin(),
                          params.begin() + static_cast<std::ptrdiff_t>(layout.position_first()));
    for (std::size_t c = 1; c <= 2; ++c)
        for (std::size_t q = 0; q < layout.height_count(); ++q)
            x.push_back(layout.control(params, c, q, data));
    const PatchEvaluator evaluator(with_positions, data);
    std::vector<double> r(evaluator.residual_count());
    evaluator.residuals(x, r.data());
    const std::size_t samples = data.z.size();
    Drift d;
    for (std::size_t s = 0; s < samples; ++s) {
        const double squared = r[samples + s] * r[samples + s] + r[2 * samples + s] * r[2 * samples + s];
        d.max = std::max(d.max, std::sqrt(squared));
        d.rms += squared;
    }
    d.rms = std::sqrt(d.rms / static_cast<double>(samples));
    return d;
}

namespace {

constexpr double decimal_scale = 1e9; // the written model's decimals: 9 places

std::string decimal(std::int64_t units) {
    const bool negative = units < 0;
    const std::uint64_t a =
        negative ? static_cast<std::uint64_t>(-(units + 1)) + 1 : static_cast<std::uint64_t>(units);
    const std::uint64_t whole = a / 1000000000u, part = a % 1000000000u;
    std::string s = fmt::format("{}{}", negative ? "-" : "", whole);
    if (part != 0) {
        std::string digits = fmt::format("{:09}", part);
        digits.erase(digits.find_last_not_of('0') + 1);
        s += "." + digits;
    }
    return s;
}

std::int64_t units(double v) {
    return static_cast<std::int64_t>(std::llround(v * decimal_scale));
}

} // namespace

QuantizedModel quantize(const PatchParameters& layout, const std::vector<double>& params, int bits) {
    if (bits < 2 || bits > 32) throw std::invalid_argument("parameters are quantised to 2 to 32 bits");
    QuantizedModel q;
    q.params = params;
    const std::size_t heights = layout.height_count();
    auto quantize_group = [&](std::size_t from, std::size_t to) {
        if (from >= to) return;
        const auto [lo_it, hi_it] = std::minmax_element(params.begin() + static_cast<std::ptrdiff_t>(from),
                                                        params.begin() + static_cast<std::ptrdiff_t>(to));
        const double lo = static_cast<float>(*lo_it), hi = static_cast<float>(*hi_it);
        const double levels = std::ldexp(1.0, bits) - 1;
        const double step = hi > lo ? (hi - lo) / levels : 0;
        for (std::size_t i = from; i < to; ++i)
            q.params[i] =
                step > 0 ? lo + step * std::clamp(std::round((params[i] - lo) / step), 0.0, levels) : lo;
    };
    quantize_group(0, heights);
    quantize_group(heights, layout.position_first());
    quantize_group(layout.position_first(), params.size()); // the control points' x, y, if fitted
    for (double& v : q.params) v = static_cast<double>(units(v)) / decimal_scale;
    const std::size_t groups = layout.shape().positions ? 3 : 2; // each stores its range: two floats
    q.bytes = (params.size() * static_cast<std::size_t>(bits) + 7) / 8 + groups * 2 * 4;
    return q;
}

std::string write_bcifs(const PatchParameters& layout, const std::vector<double>& params,
                        const HeightGrid& data, const std::string& name, const std::string& comment) {
    const auto& shape = layout.shape();
    const std::size_t k = shape.controls, kk = k * k, n = shape.split, m = k - 1, g = layout.grid_side();
    // The weights in units of 1e-9, the dependent one of each point exactly 1e9 minus the others.
    auto point_units = [&](const PatchParameters::Point& p, std::size_t dim) {
        std::vector<std::int64_t> w(dim, 0);
        std::int64_t rest = 1000000000;
        for (std::size_t s = 0; s + 1 < p.support.size(); ++s) {
            w[p.support[s]] = units(params[p.first + s]);
            rest -= w[p.support[s]];
        }
        w[p.support.back()] = rest;
        return w;
    };
    // A matrix whose column q is the point `column(q)`, `dim` rows.
    auto matrix = [&](std::size_t dim, std::size_t columns, const auto& column) {
        std::vector<std::vector<std::int64_t>> cols;
        for (std::size_t q = 0; q < columns; ++q) cols.push_back(column(q));
        std::string s = "[";
        for (std::size_t r = 0; r < dim; ++r) {
            s += r ? ",\n            [" : "[";
            for (std::size_t q = 0; q < columns; ++q) s += (q ? ", " : "") + decimal(cols[q][r]);
            s += "]";
        }
        return s + "]";
    };
    std::string out;
    for (std::size_t start = 0; start < comment.size();) {
        const auto end = comment.find('\n', start);
        out +=
            "// " + comment.substr(start, end == std::string::npos ? std::string::npos : end - start) + "\n";
        if (end == std::string::npos) break;
        start = end + 1;
    }
    out +=
        fmt::format("bcifs {} {{\n    cell v in bary(1);\n    cell e in bary({});\n    cell f in bary({});\n",
                    name, k, kk);
    out += "    subdivide e {\n";
    for (std::size_t i = 0; i < n; ++i)
        out += fmt::format("        T{} = {};\n", i, matrix(k, k, [&](std::size_t c) {
                               return point_units(layout.edge_points()[m * i + c], k);
                           }));
    out += "    }\n    subdivide f {\n";
    for (std::size_t j = 0; j < n; ++j)
        for (std::size_t i = 0; i < n; ++i)
            out +=
                fmt::format("        T{} = {};\n", i + n * j, matrix(kk, kk, [&](std::size_t q) {
                                const std::size_t r = q / k, c = q % k;
                                return point_units(layout.face_points()[(m * i + c) + g * (m * j + r)], kk);
                            }));
    out += fmt::format(
        "    }}\n    topology e = edge(v) split {};\n    topology f = quad(e) split {} x {};\n", n, n, n);
    out += "    project = controls(";
    for (std::size_t q = 0; q < kk; ++q)
        out += fmt::format("{}({}, {}, {})", q ? ",\n                       " : "",
                           decimal(units(layout.control(params, 1, q, data))),
                           decimal(units(layout.control(params, 2, q, data))), decimal(units(params[q])));
    out += ");\n}\n";
    return out;
}

} // namespace frac::rt::fit
