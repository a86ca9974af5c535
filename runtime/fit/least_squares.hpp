// Least-squares fitting of a partitioned or recurrent fractal interpolation function (seed 001 sec. 3.2),
// after fractal image compression: the data's t interval is cut into range segments and each range is
// matched against every candidate domain segment (longer than it, both orientations): the samples of the
// range against the data at their preimages in the domain (linear interpolation between samples) give the
// vertical part of the shear by least squares (eq. 15) — b, c, e for a function; for a curve through the
// hidden variable t, b, c, e per coordinate (eq. 8, eight parameters with a and d) or with the coupling
// c_xy, c_yx (eq. 9, ten). The vertical scalings are held below `max_scaling` (a row of C scaled down and
// b, e refitted), so the result contracts.
//
// PFIF: range and domain end points lie on a grid of `grid` cells over the interval; the partition into
// `maps` ranges minimises the total squared collage error (dynamic programming over the grid), each range
// with its best domain. RFIF: `maps` equal ranges, each domain a union of two or more consecutive ranges.
#pragma once

#include "runtime/fit/data.hpp"
#include "runtime/fit/model.hpp"

#include <functional>
#include <string>

namespace frac::rt::fit {

struct LeastSquaresOptions {
    int maps = 7;
    int grid = 54;          // PFIF: cells of the grid of segment end points
    bool recurrent = false; // RFIF instead of PFIF
    bool coupled = true;    // curves: ten-parameter maps (eq. 9); false: eight (eq. 8)
    double max_scaling = 0.95;
    double seconds = 0; // time budget (0: none); past it throws BudgetExceeded
    std::function<void(const std::string&)> progress;
};

FractalFunction fit_least_squares(const Samples& data, const LeastSquaresOptions& options);

// Keeps the ranges, domains and orientations of f and refits the vertical part of each map by least
// squares (maps recovered from quantised histograms are crude; seed 001 sec. 3.1). A range with too few
// samples keeps its map.
void refit_least_squares(FractalFunction& f, const Samples& data, const LeastSquaresOptions& options);

// Moves each join between consecutive ranges to the sample within `window` of it where the two maps,
// refitted by least squares, have the least collage error (the joins of recovered maps are known only to
// quantisation error), and refits the two maps there.
void refit_joins(FractalFunction& f, const Samples& data, const LeastSquaresOptions& options, double window);

} // namespace frac::rt::fit
