// Levenberg-Marquardt fitting of a projected IFS to a height grid (seed 003 sec. 4).
//
// The model is seed 003's quad patch over a k x k control grid (m = k - 1), cut into N x N sub-patches
// T(i + N j) (column i, row j), with one edge IFS for its four sides (the bcifs topology quad(e) split
// N x N of docs/language.md). The operators are described by seed 003 sec. 3.3's grid of
// (mN + 1) x (mN + 1) barycentric points lambda: column (row r, column c) of T(i + N j) is
// lambda[m i + c][m j + r], so neighbouring sub-patches share their sides (adjacency), and the grid's
// border is the edge IFS's points embedded in the four sides (incidence). "The points are taken in the
// subspaces corresponding to parts of the control grid": the point at grid position (a, b) sits at a / N,
// b / N in control-grid units and weighs only the control points of the cell (or side, or corner) it
// falls in. The parameters are those weights (less one per point: barycentric) and the heights of the
// control points; with `positions`, also the control points' x and y ("the coefficients of the operators
// and the coordinates of the control grid", sec. 3.3), the residuals then being the components of the
// 3-D distance ||Q_ij - F(i / N^p, j / N^p)|| of sec. 4.2 (x, y in sample units, z in data units: the
// written model's own coordinates). Without them the control points stay on the regular grid and only
// heights are compared (the model as an image: z at each parameter point).
//
// The fitted surface is tabulated as in sec. 2.4: F(i / N^p, j / N^p) = P T_s1 ... T_sp e00, a vertex
// per (i, j) in 0 .. N^p; the data are compared with the tabulation bilinearly interpolated at their
// sample positions (the identity when the data are (N^p + 1)^2 samples, the paper's case). The
// residuals are polynomial in the weights and linear in the heights, so the Jacobian is exact: a
// forward product and a backward product along each vertex's address (no finite differences), fed to
// Ceres's Levenberg-Marquardt (dense normal equations).
#pragma once

#include "runtime/fit/height_grid.hpp"

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace frac::rt::fit {

struct PatchShape {
    std::size_t split = 3;    // N: sub-patches per side
    std::size_t controls = 4; // k: control points per side
    int depth = 4;            // p: tabulation depth, (N^p + 1)^2 vertices
    bool positions = false;   // fit the control points' x, y too (3-D residuals)
};

// The parameter layout of a shape: which weights the parameters are.
class PatchParameters {
public:
    explicit PatchParameters(const PatchShape& shape);

    const PatchShape& shape() const { return shape_; }
    std::size_t count() const { return count_; }
    std::size_t height_count() const { return shape_.controls * shape_.controls; }
    // Parameters: heights [0, height_count()), weights [height_count(), position_first()), then (with
    // positions) the control points' x and y, height_count() each.
    std::size_t position_first() const { return count_ - (shape_.positions ? 2 * height_count() : 0); }
    std::size_t weight_count() const { return position_first() - height_count(); }
    std::size_t coordinate_count() const { return shape_.positions ? 3 : 1; }          // z, then x, y
    std::size_t grid_side() const { return (shape_.controls - 1) * shape_.split + 1; } // mN + 1

    // A barycentric point of the grid: the control points it weighs (face indices k * row + column, or
    // edge indices for the edge's grid) and its free weights params[first .. first + support - 2]; the
    // last weight is 1 minus the others.
    struct Point {
        std::vector<std::size_t> support;
        std::size_t first = 0;
    };
    const std::vector<Point>& edge_points() const { return edge_; } // mN + 1 points of bary(k)
    const std::vector<Point>& face_points() const { return face_; } // (mN + 1)^2, index a + (mN + 1) b

    // The weights that make every operator the bilinear subdivision of the control grid (the attractor
    // is the bilinear interpolation of the control points), heights sampled from the data, and the
    // control points on the regular grid over the samples.
    std::vector<double> initial(const HeightGrid& data) const;

    // Control point q's coordinate (0: z, 1: x, 2: y; without positions x, y on the regular grid).
    double control(const std::vector<double>& params, std::size_t coordinate, std::size_t q,
                   const HeightGrid& data) const;

    // The dense face points lambda (grid_side^2 points of k^2 weights) and edge points (grid_side of k).
    std::vector<double> face_weights(const std::vector<double>& params) const;
    std::vector<double> edge_weights(const std::vector<double>& params) const;

private:
    // Control point q's x (coordinate 1) or y (2) on the regular grid over the samples.
    double regular_position(std::size_t coordinate, std::size_t q, const HeightGrid& data) const;

    PatchShape shape_;
    std::size_t count_ = 0;
    std::vector<Point> edge_, face_;
};

// Evaluation of the tabulated surface and its exact derivatives.
class PatchEvaluator {
public:
    PatchEvaluator(const PatchParameters& layout, const HeightGrid& data);

    // A residual per sample and coordinate: the z residuals of every sample, then (with positions) the
    // x residuals, then the y residuals.
    std::size_t residual_count() const { return data_.z.size() * layout_.coordinate_count(); }
    const PatchParameters& layout() const { return layout_; }

    // Residuals F(x_s, y_s) - (x_s, y_s, z_s) at every sample.
    void residuals(const std::vector<double>& params, double* out) const;
    // Residuals and their Jacobian, residual_count() x count(), row-major (one row a residual).
    void jacobian(const std::vector<double>& params, double* residuals_out, double* jacobian_row_major) const;
    // The model's heights at the samples.
    std::vector<double> approximation(const std::vector<double>& params) const;

private:
    // Vertex coordinates (value[coordinate * vertices + vertex]); when on_gradient is given, each
    // vertex coordinate's gradient (count() entries, valid only during the call) is handed to it as it
    // is computed, so no vertex-by-parameter array is built.
    using GradientSink =
        std::function<void(std::size_t vertex, std::size_t coordinate, const double* gradient)>;
    void vertices(const std::vector<double>& params, std::vector<double>& value,
                  const GradientSink* on_gradient) const;
    // Residuals from the vertex coordinates.
    void residuals_from(const std::vector<double>& value, double* out) const;
    // Sample s's value in a coordinate (z: the data; x, y: its position in sample units).
    double target(std::size_t coordinate, std::size_t s) const;
    struct Sample {
        std::size_t vertex[4];
        double weight[4];
    };
    struct Contribution {
        std::size_t sample;
        double weight;
    };
    const PatchParameters& layout_;
    const HeightGrid& data_;
    std::size_t side_ = 0; // N^p + 1
    std::vector<Sample> samples_;
    // The samples each vertex weighs in (nonzero bilinear weights), vertex v's at
    // contributions_[contribution_start_[v] .. contribution_start_[v + 1]).
    std::vector<std::size_t> contribution_start_;
    std::vector<Contribution> contributions_;
    std::vector<std::vector<std::size_t>> addresses_; // per vertex: the p - 1 operators, then the last point
};

enum class Derivatives { exact, finite_differences };

struct FitOptions {
    PatchShape shape;
    int max_iterations = 200;
    double max_seconds = 0; // 0: no time budget
    double target_psnr = 0; // stop once reached (0: run to convergence or budget)
    Derivatives derivatives = Derivatives::exact;
    // Bounds of the free weights. Near [0, 1] the operators stay near stochastic matrices, whose
    // contraction the compiler proves; unbounded, the fit drifts to operators it cannot prove (on the
    // 28 x 28 paraboloid: 40.1 dB after 20 iterations unbounded, refused; after 60, 38.5 dB within these
    // bounds, 37.4 within [0, 1]).
    double weight_range[2] = {-0.25, 1.25};
    // After each iteration: iteration, PSNR, elapsed seconds.
    std::function<void(int, double, double)> progress;
};

struct FitResult {
    std::vector<double> params;
    ErrorStats stats;
    int iterations = 0;
    double seconds = 0;
    double seconds_to_target = -1; // when target_psnr was reached: the time it took
    bool converged = false;        // LM stopped on a tolerance, or reached the target
    std::string stop_reason;
};

FitResult fit_patch(const HeightGrid& data, const FitOptions& options);

// Where the model's vertices lie against the samples' x, y (sample units): without fitted positions the
// fit bends the operators freely, and the written surface's vertices drift off the sample grid.
struct Drift {
    double max = 0, rms = 0;
};
Drift position_drift(const PatchParameters& layout, const std::vector<double>& params,
                     const HeightGrid& data);

// Parameters rounded as a coded model stores them: each group (heights, weights, and the control points'
// x, y when fitted) quantised to `bits` bits between its minimum and maximum (kept as two 32-bit floats
// each), then rounded to the decimals the written model holds (9 places; the dependent weight of each point
// then sums exactly).
struct QuantizedModel {
    std::vector<double> params;
    std::size_t bytes = 0; // parameters x bits / 8, plus the ranges
};
QuantizedModel quantize(const PatchParameters& layout, const std::vector<double>& params, int bits);

// The model as a bcifs of the language: cells v, e (bary(k)), f (bary(k^2)), the topology of an edge
// and of a quad patch, the operators written with exact decimals (so the compiler's exact check of the
// barycentric sums, incidence and adjacency holds), and the control points at their fitted x, y (or
// x = column / m * (width - 1), y = row / m * (height - 1)), z the fitted heights. `comment` goes at the top.
std::string write_bcifs(const PatchParameters& layout, const std::vector<double>& params,
                        const HeightGrid& data, const std::string& name, const std::string& comment);

} // namespace frac::rt::fit
