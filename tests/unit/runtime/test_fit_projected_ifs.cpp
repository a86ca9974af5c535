// Levenberg-Marquardt fitting of projected IFS (runtime/fit): the exact Jacobian against central
// differences, the bilinear start, the fit's progress, quantisation, the written bcifs against the
// language's own tessellation of it, and the data readers' errors.
#include "driver/pipeline.hpp"
#include "runtime/automata/surface.hpp"
#include "runtime/fit/height_grid.hpp"
#include "runtime/fit/projected_ifs.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <tuple>

using namespace frac;
using namespace frac::rt::fit;

namespace {

PatchShape small_shape(std::size_t split, std::size_t controls, int depth) {
    PatchShape s;
    s.split = split;
    s.controls = controls;
    s.depth = depth;
    return s;
}

// Parameters away from the bilinear start, so that every term of the Jacobian is exercised.
std::vector<double> perturbed(const PatchParameters& layout, const HeightGrid& data) {
    std::vector<double> x = layout.initial(data);
    for (std::size_t i = 0; i < x.size(); ++i) x[i] += 0.04 * std::sin(1.7 * static_cast<double>(i) + 0.3);
    return x;
}

std::string temp_file(const std::string& name, const std::string& text) {
    const std::string path = "/tmp/frac-unit-fit-" + name;
    std::ofstream(path) << text;
    return path;
}

} // namespace

TEST_CASE("fit: the exact Jacobian matches central differences", "[fit]") {
    // Data of another size than the tabulation (the samples interpolate vertices bilinearly), and data
    // on the tabulation's vertices (each sample one vertex).
    // With positions, the x and y residuals' rows too.
    for (const auto& [base_shape, width, height, positions] :
         {std::tuple{small_shape(3, 4, 2), std::size_t{13}, std::size_t{14}, false},
          std::tuple{small_shape(2, 3, 3), std::size_t{9}, std::size_t{10}, false},
          std::tuple{small_shape(3, 3, 2), std::size_t{10}, std::size_t{11}, false},
          std::tuple{small_shape(3, 4, 2), std::size_t{10}, std::size_t{10}, false},
          std::tuple{small_shape(3, 4, 2), std::size_t{13}, std::size_t{14}, true},
          std::tuple{small_shape(2, 3, 3), std::size_t{9}, std::size_t{9}, true}}) {
        PatchShape shape = base_shape;
        shape.positions = positions;
        const HeightGrid data = elliptic_paraboloid(width, height);
        const PatchParameters layout(shape);
        const PatchEvaluator evaluator(layout, data);
        const std::vector<double> x = perturbed(layout, data);
        const std::size_t m = evaluator.residual_count(), n = layout.count();
        // Every entry must be written: the buffer starts as NaN, as Ceres's may hold anything.
        std::vector<double> r(m), jac(m * n, std::numeric_limits<double>::quiet_NaN()), plus(m), minus(m);
        evaluator.jacobian(x, r.data(), jac.data());
        double worst = 0;
        for (std::size_t j = 0; j < n; ++j) {
            std::vector<double> xp = x, xm = x;
            const double h = 1e-6;
            xp[j] += h;
            xm[j] -= h;
            evaluator.residuals(xp, plus.data());
            evaluator.residuals(xm, minus.data());
            for (std::size_t s = 0; s < m; ++s)
                worst = std::max(worst, std::isnan(jac[s * n + j])
                                            ? std::numeric_limits<double>::infinity()
                                            : std::abs((plus[s] - minus[s]) / (2 * h) - jac[s * n + j]));
        }
        INFO("split " << shape.split << ", controls " << shape.controls << ", depth " << shape.depth
                      << ", positions " << shape.positions);
        CHECK(worst < 1e-7);
    }
}

TEST_CASE("fit: the start is the bilinear interpolation of the control heights", "[fit]") {
    // A bilinear function is reproduced exactly (to rounding) at every sample.
    HeightGrid data;
    data.width = 28;
    data.height = 28;
    for (std::size_t y = 0; y < 28; ++y)
        for (std::size_t x = 0; x < 28; ++x) {
            const double u = static_cast<double>(x) / 27, v = static_cast<double>(y) / 27;
            data.z.push_back(1 + 2 * u - 3 * v + 5 * u * v);
        }
    const PatchParameters layout(small_shape(3, 4, 3));
    const PatchEvaluator evaluator(layout, data);
    const ErrorStats s = error_stats(data, evaluator.approximation(layout.initial(data)));
    CHECK(s.max_error < 1e-12);
}

TEST_CASE("fit: Levenberg-Marquardt improves on the start, and quantisation costs little", "[fit]") {
    const HeightGrid data = elliptic_paraboloid(28, 28);
    FitOptions options;
    options.shape = small_shape(3, 4, 3);
    options.max_iterations = 15;
    const PatchParameters layout(options.shape);
    const PatchEvaluator evaluator(layout, data);
    const double start = error_stats(data, evaluator.approximation(layout.initial(data))).psnr;
    const FitResult fit = fit_patch(data, options);
    CHECK(fit.converged);
    CHECK(fit.stats.psnr > start + 10);
    const QuantizedModel q16 = quantize(layout, fit.params, 16), q8 = quantize(layout, fit.params, 8);
    CHECK(q16.bytes == (layout.count() * 16 + 7) / 8 + 16);
    CHECK(q8.bytes == layout.count() + 16);
    const double psnr16 = error_stats(data, evaluator.approximation(q16.params)).psnr;
    const double psnr8 = error_stats(data, evaluator.approximation(q8.params)).psnr;
    CHECK(std::abs(psnr16 - fit.stats.psnr) < 0.1);
    CHECK(psnr8 > fit.stats.psnr - 3);
    // Forward differences (seed 003's way) follow the same path to within their error.
    FitOptions differences = options;
    differences.derivatives = Derivatives::finite_differences;
    differences.max_iterations = 5;
    options.max_iterations = 5;
    CHECK(std::abs(fit_patch(data, differences).stats.psnr - fit_patch(data, options).stats.psnr) < 0.5);
    // A target out of reach within the budget is not a converged fit.
    options.target_psnr = 200;
    options.max_iterations = 2;
    CHECK_FALSE(fit_patch(data, options).converged);
}

TEST_CASE("fit: the written bcifs compiles and its tessellation is the fitted surface", "[fit]") {
    const HeightGrid data = elliptic_paraboloid(28, 28);
    FitOptions options;
    options.shape = small_shape(3, 4, 3);
    options.max_iterations = 8;
    const FitResult fit = fit_patch(data, options);
    const PatchParameters layout(options.shape);
    const QuantizedModel model = quantize(layout, fit.params, 16);
    const std::string text = write_bcifs(layout, model.params, data, "fitted", "a test fit");
    const auto c = driver::compile_source("fitted.frac", text);
    REQUIRE(c->ok());
    REQUIRE(c->module.automata.size() == 1);
    const ir::Automaton& a = c->module.automata.front().automaton;
    rt::SurfaceLayout surface = rt::infer_layout(a);
    const rt::Tessellation t = rt::tessellate(a, surface, 3);
    REQUIRE(t.side_s == 28);
    REQUIRE(t.side_t == 28);
    // The language's vertex i * 28 + j is the sample of row i (y), column j (x): the heights agree, and
    // the control grid puts the vertex near that column and row.
    const PatchEvaluator evaluator(layout, data);
    const std::vector<double> z = evaluator.approximation(model.params);
    double worst = 0, drift = 0;
    for (std::size_t i = 0; i < 28; ++i)
        for (std::size_t j = 0; j < 28; ++j) {
            const auto& v = t.vertices[i * t.side_t + j];
            worst = std::max(worst, std::abs(v[2] - z[i * 28 + j]));
            drift = std::max(
                {drift, std::abs(v[0] - static_cast<double>(j)), std::abs(v[1] - static_cast<double>(i))});
        }
    CHECK(drift < 3);
    CHECK(worst < 1e-9);
}

TEST_CASE("fit: malformed data is located", "[fit]") {
    const auto located = [](const std::string& path, std::size_t line, std::size_t column) {
        try {
            read_height_grid(path);
        } catch (const DataError& e) {
            CHECK(e.file == path);
            CHECK(e.line == line);
            CHECK(e.column == column);
            return;
        }
        FAIL("no DataError for " << path);
    };
    located(temp_file("inf.csv", "1, 2, 3\n4, 5, inf\n7, 8, 9\n"), 2, 7);
    located(temp_file("word.csv", "# heights\n1, 2\n3, x\n"), 3, 4);
    located(temp_file("empty_value.csv", "1, , 3\n4, 5, 6\n"), 1, 4);
    located(temp_file("row.csv", "1, 2, 3\n4, 5, 6, 7\n"), 2, 1);
    located(temp_file("one_row.csv", "1, 2, 3\n"), 0, 0);
    located(temp_file("not.png", "this is not a PNG"), 0, 0);
    const HeightGrid g = read_height_grid(temp_file("ok.csv", "1, 2\n\n# comment\n3,4\r\n"));
    CHECK(g.width == 2);
    CHECK(g.height == 2);
    CHECK(g.at(1, 1) == 4);
    CHECK(g.peak == 3);
}

namespace {

// Heights with detail finer than the control grid: a fit bends the operators, and with them the
// vertices' x and y.
HeightGrid rough_surface(std::size_t side) {
    HeightGrid data = elliptic_paraboloid(side, side);
    for (std::size_t y = 0; y < side; ++y)
        for (std::size_t x = 0; x < side; ++x)
            data.z[y * side + x] += 0.08 * std::sin(0.9 * static_cast<double>(x)) *
                                    std::cos(0.7 * static_cast<double>(y) + 0.4 * static_cast<double>(x));
    return data;
}

double squares(const std::vector<double>& r, std::size_t from, std::size_t to) {
    double sum = 0;
    for (std::size_t i = from; i < to; ++i) sum += r[i] * r[i];
    return sum;
}

} // namespace

TEST_CASE("fit: control points' positions fitted with 3-D residuals, written as fitted", "[fit]") {
    const std::size_t side = 28, samples = side * side;
    const HeightGrid data = rough_surface(side);
    FitOptions heights_only;
    heights_only.shape = small_shape(3, 4, 3);
    heights_only.max_iterations = 12;
    FitOptions with_positions = heights_only;
    with_positions.shape.positions = true;
    const PatchParameters layout0(heights_only.shape), layout(with_positions.shape);
    REQUIRE(layout.count() == layout0.count() + 2 * 16);
    REQUIRE(layout.position_first() == layout0.count());
    const PatchEvaluator evaluator(layout, data);
    REQUIRE(evaluator.residual_count() == 3 * samples);
    // The start has the control points on the regular grid: no x, y residual.
    std::vector<double> r(evaluator.residual_count());
    evaluator.residuals(layout.initial(data), r.data());
    CHECK(squares(r, samples, 3 * samples) < 1e-20);

    const FitResult fit0 = fit_patch(data, heights_only);
    const FitResult fit = fit_patch(data, with_positions);
    REQUIRE(fit0.converged);
    REQUIRE(fit.converged);
    // The heights-only fit, seen in 3-D (its control points where they stay): its bent operators move
    // the vertices off the samples' x, y. The 3-D fit has a smaller 3-D distance, and less drift.
    std::vector<double> as_3d = fit0.params;
    for (std::size_t c = 1; c <= 2; ++c)
        for (std::size_t q = 0; q < 16; ++q) as_3d.push_back(layout0.control(fit0.params, c, q, data));
    std::vector<double> r0(evaluator.residual_count());
    evaluator.residuals(as_3d, r0.data());
    evaluator.residuals(fit.params, r.data());
    INFO("heights-only: z " << squares(r0, 0, samples) << ", x y " << squares(r0, samples, 3 * samples)
                            << "; 3-D: z " << squares(r, 0, samples) << ", x y "
                            << squares(r, samples, 3 * samples));
    CHECK(squares(r0, samples, 3 * samples) > 1e-3);
    CHECK(squares(r, 0, 3 * samples) < 0.9 * squares(r0, 0, 3 * samples));
    CHECK(squares(r, samples, 3 * samples) < 0.5 * squares(r0, samples, 3 * samples));
    bool moved = false;
    for (std::size_t q = 0; q < 16; ++q)
        moved = moved || std::abs(fit.params[layout.position_first() + q] -
                                  layout0.control(fit0.params, 1, q, data)) > 1e-6;
    CHECK(moved);

    // Stored with a third range (x, y), and written with the fitted x, y: the language's tessellation of
    // the model is the fitted surface in all three coordinates.
    const QuantizedModel model = quantize(layout, fit.params, 16);
    CHECK(model.bytes == (layout.count() * 16 + 7) / 8 + 24);
    const std::string text = write_bcifs(layout, model.params, data, "fitted", "a 3-D fit");
    const auto c = driver::compile_source("fitted.frac", text);
    REQUIRE(c->ok());
    const ir::Automaton& a = c->module.automata.front().automaton;
    const rt::Tessellation t = rt::tessellate(a, rt::infer_layout(a), 3);
    REQUIRE(t.side_s == side);
    REQUIRE(t.side_t == side);
    evaluator.residuals(model.params, r.data());
    double worst = 0;
    for (std::size_t i = 0; i < side; ++i)
        for (std::size_t j = 0; j < side; ++j) {
            const std::size_t s = i * side + j;
            const auto& v = t.vertices[i * t.side_t + j];
            worst = std::max({worst, std::abs(v[2] - (r[s] + data.z[s])),
                              std::abs(v[0] - (r[samples + s] + static_cast<double>(j))),
                              std::abs(v[1] - (r[2 * samples + s] + static_cast<double>(i)))});
        }
    CHECK(worst < 1e-9);
}
