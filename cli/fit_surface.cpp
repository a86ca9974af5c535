// frac fit DATA -o MODEL.frac --method lm: a projected IFS (seed 003's quad patch) fitted by
// Levenberg-Marquardt with exact derivatives to a height grid or a grey image (runtime/fit/).
#include "cli/commands.hpp"
#include "runtime/fit/projected_ifs.hpp"
#include "support/atomic_file.hpp"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>

namespace frac::cli {

void add_fit_surface_options(CLI::App* fit, FitSurfaceOptions& o) {
    fit->add_option("--patches", o.patches, "sub-patches per side, NxN (the patch IFS has N^2 operators)")
        ->capture_default_str();
    fit->add_option("--controls", o.controls, "control points per side of the control grid")
        ->check(CLI::Range(2, 8))
        ->capture_default_str();
    fit->add_option(
           "--depth", o.depth,
           "tabulation depth p: the model is compared at (N^p + 1)^2 points (default: the least p with "
           "N^p + 1 at least the data's side)")
        ->check(CLI::Range(1, 12));
    fit->add_option("--iterations", o.iterations, "most Levenberg-Marquardt iterations")
        ->check(CLI::Range(1, 100000))
        ->capture_default_str();
    fit->add_option("--time", o.seconds, "time budget in seconds (0: none)")
        ->check(CLI::Range(0.0, 1e6))
        ->capture_default_str();
    fit->add_option("--target-psnr", o.target_psnr,
                    "stop once the PSNR reaches this many dB; a fit that does not reach it writes nothing")
        ->check(CLI::Range(0.0, 400.0));
    fit->add_flag("--fit-xy", o.fit_positions,
                  "fit the control points' x, y too: residuals are 3-D distances (seed 003 sec. 4.2), so "
                  "the written surface lies where the samples are, not only at their heights");
}

bool is_surface_data(const std::string& path) {
    if (ends_with(path, ".png")) return true;
    std::ifstream in(path);
    std::string line;
    while (std::getline(in, line)) {
        const auto first = line.find_first_not_of(" \t\r");
        if (first == std::string::npos || line[first] == '#') continue;
        return std::count(line.begin(), line.end(), ',') + 1 > 3;
    }
    return false;
}

namespace {

// A data error as the compiler's diagnostics look: FILE:LINE:COL, the line, a caret; one about the whole
// file names it (exit 65 both).
int report_data_error(const rt::fit::DataError& e) {
    if (e.line == 0) {
        std::cerr << fmt::format("frac: error: {}: {}\n", e.file, e.what());
    } else {
        std::cerr << fmt::format("{}:{}:{}: error: {}\n", e.file, e.line, e.column, e.what());
        std::cerr << fmt::format("{:>5} | {}\n      | {}^\n", e.line, e.source_line,
                                 std::string(e.column > 0 ? e.column - 1 : 0, ' '));
    }
    return front::exit_compile_error;
}

constexpr double max_fit_bytes = 2e9;

std::size_t parse_patches(const std::string& text) {
    const auto x = text.find('x');
    std::size_t n = 0, m = 0;
    try {
        std::size_t used = 0;
        n = std::stoul(text.substr(0, x), &used);
        if (used != x) throw std::invalid_argument(text);
        m = x == std::string::npos ? n : std::stoul(text.substr(x + 1), &used);
        if (x != std::string::npos && used != text.size() - x - 1) throw std::invalid_argument(text);
    } catch (const std::exception&) {
        throw UsageError(fmt::format("--patches '{}': expected NxN, e.g. 3x3", text));
    }
    if (n != m)
        throw UsageError(
            fmt::format("--patches {}: a quad patch is split alike along both sides (NxN)", text));
    if (n < 2 || n > 8) throw UsageError(fmt::format("--patches {}: N from 2 to 8", text));
    return n;
}

} // namespace

int run_fit_surface(const FitSurfaceOptions& o) {
    using namespace rt::fit;
    const std::size_t split = parse_patches(o.patches);
    check_output_writable(o.output, {o.data});
    HeightGrid data;
    try {
        data = read_height_grid(o.data);
    } catch (const DataError& e) {
        return report_data_error(e);
    }
    FitOptions options;
    options.shape.split = split;
    options.shape.controls = static_cast<std::size_t>(o.controls);
    options.shape.positions = o.fit_positions;
    if (o.depth > 0) {
        options.shape.depth = o.depth;
    } else {
        // The least p with N^p + 1 >= the data's longer side (every sample then has its own vertices).
        options.shape.depth = 1;
        std::size_t cells = split;
        while (cells + 1 < std::max(data.width, data.height) && cells * split <= 4096) {
            cells *= split;
            ++options.shape.depth;
        }
    }
    options.max_iterations = o.iterations;
    options.max_seconds = o.seconds;
    options.target_psnr = o.target_psnr;
    options.progress = [](int iteration, double psnr, double seconds) {
        std::cerr << fmt::format("fit: iteration {}: PSNR {:.2f} dB ({:.2f} s)\n", iteration, psnr, seconds);
    };
    std::unique_ptr<PatchParameters> layout;
    try {
        layout = std::make_unique<PatchParameters>(options.shape);
    } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
    }
    if (data.z.size() < layout->count())
        return report_data_error(DataError(
            o.data, 0, 0,
            fmt::format(
                "too few samples: {} x {} = {} for a model of {} parameters ({} x {} sub-patches, {} x {} "
                "control points)",
                data.width, data.height, data.z.size(), layout->count(), split, split, o.controls,
                o.controls)));
    const std::size_t side = static_cast<std::size_t>(std::llround(std::pow(split, options.shape.depth))) + 1;
    // Memory: the Jacobian (a dense row a sample and coordinate; Ceres keeps two copies of it) and the
    // tabulation (each vertex's address of p digits and its coordinates). Refuse what would not fit.
    const double jacobian_bytes = 2.0 * static_cast<double>(data.z.size() * layout->coordinate_count()) *
                                  static_cast<double>(layout->count()) * 8.0;
    const double tabulation_bytes =
        static_cast<double>(side * side) *
        (32.0 + 8.0 * static_cast<double>(static_cast<std::size_t>(options.shape.depth) +
                                          layout->coordinate_count()));
    if (jacobian_bytes + tabulation_bytes > max_fit_bytes)
        throw UsageError(fmt::format(
            "{} x {} samples and {} x {} vertices of {} parameters would take {:.1f} GB (derivatives {:.1f} "
            "GB, tabulation {:.1f} GB; at most {:.1f} GB): downsample the data, or lower --depth",
            data.width, data.height, side, side, layout->count(), (jacobian_bytes + tabulation_bytes) / 1e9,
            jacobian_bytes / 1e9, tabulation_bytes / 1e9, max_fit_bytes / 1e9));
    std::cout << fmt::format("data: {}, {} x {} samples, peak {}\n", o.data, data.width, data.height,
                             data.peak);
    std::cout << fmt::format(
        "model: {} x {} sub-patches, {} x {} control points{}, depth {} ({} x {} vertices), {} "
        "parameters\n",
        split, split, o.controls, o.controls, o.fit_positions ? " (x, y, z fitted)" : "", options.shape.depth,
        side, side, layout->count());
    const FitResult fit = fit_patch(data, options);
    if (!fit.converged)
        throw RunError(
            fmt::format("the fit did not converge: {} (PSNR {:.2f} dB after {} iterations); nothing "
                        "written",
                        fit.stop_reason, fit.stats.psnr, fit.iterations));
    const QuantizedModel model = quantize(*layout, fit.params, o.bits);
    const PatchEvaluator evaluator(*layout, data);
    const ErrorStats stats = error_stats(data, evaluator.approximation(model.params));
    const double data_bytes = static_cast<double>(data.z.size()) * (data.bits == 8 ? 1 : 2);
    std::cout << fmt::format("fit: {} iterations, stopped: {}\n", fit.iterations, fit.stop_reason);
    std::cout << fmt::format("error ({}-bit parameters): max {:.6g}, MSE {:.6g}, PSNR {:.2f} dB\n", o.bits,
                             stats.max_error, stats.mse, stats.psnr);
    const Drift drift = position_drift(*layout, model.params, data);
    std::cout << fmt::format("vertices off the samples' x, y: max {:.3g}, RMS {:.3g} (sample units){}\n",
                             drift.max, drift.rms, o.fit_positions ? "" : "; --fit-xy fits them");
    std::cout << fmt::format(
        "size: model {} bytes, data {} bytes ({}-bit samples), compression ratio {:.2f}\n", model.bytes,
        data_bytes, data.bits == 8 ? 8 : 16, data_bytes / static_cast<double>(model.bytes));
    const std::string text = write_bcifs(
        *layout, model.params, data, o.name,
        fmt::format("frac fit {} --method lm: a projected IFS quad patch (seed 003 sec. 4)\n"
                    "{} x {} sub-patches, {} x {} control points, {} parameters of {} bits; PSNR {:.2f} dB",
                    o.data, split, split, o.controls, o.controls, layout->count(), o.bits, stats.psnr));
    // The model must be one the compiler takes (sizes, exact barycentric sums, incidence, adjacency, a
    // contraction proof) before it replaces anything.
    const auto compiled = driver::compile_source(o.output, text);
    if (!compiled->ok())
        throw RunError(fmt::format("the fitted model is refused by the compiler; nothing written:\n{}",
                                   compiled->diags.render(compiled->sources)));
    support::write_file_atomically(o.output, text, "model");
    std::cout << fmt::format("wrote {}\n", o.output);
    return 0;
}

} // namespace frac::cli
