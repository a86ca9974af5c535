// frac fit for curves and functions (seed 001): a CSV of (t, x), (x, y) or (t, x, y) samples fitted by the
// Hough recovery of a FIF, or by a least-squares PFIF or RFIF; the model is written as Frac source. The
// options are added to the `fit` command by add_fit_curve_options, so that other fitting modes share it.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace frac::cli {

struct FitCurveOptions {
    std::string file, output, method = "pfif", generate, name, kind = "auto";
    int maps = 0;      // 0: 2 for hough, 7 for pfif and rfif
    int quantize = 0;  // 0 or 8 bits per parameter
    int grid = 54;     // pfif: cells of the grid of segment end points
    int points = 0;    // --generate: samples (0: the generator's feature points)
    double budget = 0; // seconds, 0: none
    bool separable = false;
};

// The methods of this file (--method).
inline bool is_curve_fit_method(const std::string& method) {
    return method == "hough" || method == "pfif" || method == "rfif";
}

// Adds the curve fits' own options to `fit`; the data file, -o, --method, --quantize and --name are the
// command's, shared with the surface fit (cli/main.cpp).
void add_fit_curve_options(CLI::App* fit, FitCurveOptions& options);

// Runs the fit (or, with --generate, writes synthetic data); returns the exit code.
int run_fit_curve(const FitCurveOptions& options);

} // namespace frac::cli
