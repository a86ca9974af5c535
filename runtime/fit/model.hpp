// A fractal function fitted to data (seed 001 sec. 2): pieces, each a shear T (eq. 1, or eq. 8/9 for a
// curve with the hidden variable t) from a domain interval [alpha, beta] onto a range interval of t. With
// every domain the whole interval it is a FIF; domains that are unions of ranges make an RFIF; arbitrary
// domains a PFIF. Its graph F satisfies F[range_i] = T_i(F[domain_i]) (eq. 3, 6, 7), which evaluates F at
// any t by descending through the pieces until the product of the vertical scalings is negligible.
#pragma once

#include "runtime/fit/data.hpp"

#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

namespace frac::rt::fit {

// A fit that ran past its time budget: it writes nothing.
struct BudgetExceeded : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// (t, x[, y]) -> (a t + d, b t + C (x[, y]) + e). For a function only b[0], c[0][0], e[0] are used.
struct Shear {
    double a = 0, d = 0;
    std::array<double, 2> b{}, e{};
    std::array<std::array<double, 2>, 2> c{};
    double map_t(double t) const { return a * t + d; }
    // The composition this ∘ other.
    Shear after(const Shear& other) const;
    // Max row sum of |C|: below 1 makes the vertical part contract (for a function, |c|).
    double vertical_norm(bool curve) const;
};

struct Piece {
    Shear map;
    double alpha = 0, beta = 0; // the domain interval of t
    double lo = 0, hi = 0;      // the range: the image of the domain under t -> a t + d
};

struct FractalFunction {
    double t0 = 0, t1 = 1;
    bool curve = false;
    std::vector<Piece> pieces; // sorted by range, the ranges tiling [t0, t1]
    // The value at t (x, and y for a curve).
    std::array<double, 2> operator()(double t) const;
    // Parameters stored per piece: a, d, the vertical part, and 2 domain bounds unless every domain is
    // [t0, t1].
    std::size_t parameter_count() const;
    bool every_domain_whole() const;
    // Whether every domain is a union of consecutive ranges (an RFIF, a recurrent automaton).
    bool domains_are_unions_of_ranges(double tolerance) const;
};

// Makes the piece map its domain onto [lo, hi], keeping its orientation (the sign of a).
void set_range(Piece& piece, double lo, double hi);

// Checks that the ranges of the pieces tile [t0, t1] (within `tolerance`, then made exact) and that each
// shear contracts (|a| < 1, vertical norm < 1); returns "" or what is wrong.
std::string make_consistent(FractalFunction& f, double tolerance);

struct FitError {
    double max_error = 0, mse = 0, psnr = 0; // error per sample, Euclidean for a curve
};
// The attractor against the samples; PSNR from the peak-to-peak range of the data.
FitError measure(const FractalFunction& f, const Samples& data);

// Rounds every parameter to 8 bits over its range (a, c in [-1, 1]; d, e, b and the domain bounds over
// ranges derived from the data), as a stored model would hold them.
void quantize8(FractalFunction& f, const Samples& data);

// The model as Frac source: an `ifs` over R2 (a FIF) or a `cifs` with a state per range (an RFIF, a curve
// over R3 with coordinates (t, x, y)), or else a `fif` of pieces (a PFIF), its interval ends written
// exactly as points of a grid of `grid` cells over [t0, t1] where they lie on one (0: no grid), and each
// map's t part as the exact map of its domain onto its range, so the ranges tile exactly. Whether the
// PFIF's intervals close up into a finite automaton is the compiler's to decide.
std::string to_frac(const FractalFunction& f, const std::string& name, const std::string& comment,
                    std::size_t grid = 0);

// The samples of f at `count` uniform values of t over [t0, t1].
Samples sample(const FractalFunction& f, std::size_t count);

} // namespace frac::rt::fit
