// Fitting fractal interpolation functions (seed 001): data reading, Hough recovery of Table 1's FIF,
// least-squares PFIF of the hidden-variable Sierpinski curve, models written as Frac source.
#include "driver/pipeline.hpp"
#include "runtime/fit/data.hpp"
#include "runtime/fit/generate.hpp"
#include "runtime/fit/hough.hpp"
#include "runtime/fit/least_squares.hpp"
#include "runtime/fit/model.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>

using namespace frac::rt::fit;

namespace {

void require_error(const std::string& text, std::size_t line, std::size_t column, const std::string& part) {
    try {
        parse_csv(text);
        FAIL("no error for: " << text);
    } catch (const SamplesError& e) {
        CHECK(e.line == line);
        CHECK(e.column == column);
        CHECK_THAT(e.what(), Catch::Matchers::Contains(part));
    }
}

// Whether a recovered map is the true one within `bins` quantisation steps in every parameter.
bool matches(const Shear& got, const Shear& want, const HoughSteps& st, double bins) {
    return std::abs(got.a - want.a) <= bins * st.a && std::abs(got.b[0] - want.b[0]) <= bins * st.b &&
           std::abs(got.c[0][0] - want.c[0][0]) <= bins * st.c && std::abs(got.d - want.d) <= bins * st.d &&
           std::abs(got.e[0] - want.e[0]) <= bins * st.e;
}

void require_table1_recovered(int level, std::size_t points) {
    const FractalFunction truth = table1_fif();
    const Samples s = feature_points(truth, level);
    REQUIRE(s.size() == points);
    const HoughResult r = hough_recover(s, HoughOptions{});
    REQUIRE(r.clusters.size() >= 2);
    // The two most popular clusters are the two maps of Table 1 (in either order), each parameter within one
    // quantisation step (the bin holding it or, by spill-over, its neighbour).
    const Shear &t1 = truth.pieces[0].map, &t2 = truth.pieces[1].map;
    const Shear &p = r.clusters[0].map, &q = r.clusters[1].map;
    CHECK(((matches(p, t1, r.steps, 1) && matches(q, t2, r.steps, 1)) ||
           (matches(p, t2, r.steps, 1) && matches(q, t1, r.steps, 1))));
    // No third cluster is either map again (spill-over into adjacent bins is not a cluster).
    for (std::size_t i = 2; i < r.clusters.size(); ++i) {
        CHECK_FALSE(matches(r.clusters[i].map, t1, r.steps, 2));
        CHECK_FALSE(matches(r.clusters[i].map, t2, r.steps, 2));
    }
    // The FIF of the two clusters, its join and maps refined by least squares, is close to the data.
    FractalFunction f = fif_from_clusters(r, s, 2);
    refit_joins(f, s, LeastSquaresOptions{}, join_tolerance(r, s));
    CHECK(measure(f, s).max_error < 0.01);
}

} // namespace

TEST_CASE("fit data: CSV of functions and curves", "[fit]") {
    const Samples f = parse_csv("# a profile\nt,x\n0, 1\n0.25,2\n0.5 ,3\n\n0.75,2\n1,1e0\n");
    CHECK_FALSE(f.curve());
    REQUIRE(f.size() == 5);
    CHECK(f.x[1] == 2);
    const Samples c = parse_csv("x,y\n0,0\n1,0\n1,1\n0,1\n0,0\n");
    REQUIRE(c.curve());
    CHECK(c.t == std::vector<double>{0, 0.25, 0.5, 0.75, 1});
    const Samples blanks = parse_csv("0 0 0\n0.5 1 2\n1 2 3\n1.5 3 4\n2 4 5\n");
    CHECK(blanks.curve());
    CHECK(blanks.y[4] == 5);
    CHECK(parse_csv("0,0\n1,1\n2,0\n3,1\n4,0\n", DataKind::curve).curve());
}

TEST_CASE("fit data: malformed rows are located", "[fit]") {
    require_error("0,0\n1,1\n2,1,5\n3,3\n4,4\n", 3, 5, "a row of 3 fields where the rows have 2");
    require_error("0,0\n1,nan\n2,1\n3,3\n4,4\n", 2, 3, "'nan' is not a finite number");
    require_error("0,0\n1,1x\n2,1\n3,3\n4,4\n", 2, 3, "'1x' is not a number");
    require_error("0,0\n1,1\n0.5,1\n3,3\n4,4\n", 3, 1, "the parameter 0.5 does not increase");
    require_error("0,0\n1,\n", 2, 3, "an empty field");
    require_error("t,z\n", 1, 3, "'z' is not a column name");
    require_error("0,0\n1,1\n2,2\n", 3, 0, "3 data points: a fit needs at least 5");
}

TEST_CASE("fit: compositions of shears", "[fit]") {
    const FractalFunction s = sierpinski_space_curve();
    const Shear& p = s.pieces[0].map;
    const Shear& q = s.pieces[2].map;
    const Shear pq = p.after(q);
    const double t = 0.3, x = 0.7, y = -0.2;
    const double qt = q.map_t(t), qx = q.c[0][0] * x + q.c[0][1] * y + q.e[0],
                 qy = q.c[1][0] * x + q.c[1][1] * y + q.e[1];
    CHECK(pq.map_t(t) == Approx(p.map_t(qt)));
    CHECK(pq.c[0][0] * x + pq.c[0][1] * y + pq.b[0] * t + pq.e[0] ==
          Approx(p.c[0][0] * qx + p.c[0][1] * qy + p.b[0] * qt + p.e[0]));
    CHECK(pq.c[1][0] * x + pq.c[1][1] * y + pq.b[1] * t + pq.e[1] ==
          Approx(p.c[1][0] * qx + p.c[1][1] * qy + p.b[1] * qt + p.e[1]));
}

TEST_CASE("fit: the Sierpinski space curve runs through the gasket's corners", "[fit]") {
    const FractalFunction f = sierpinski_space_curve();
    const auto start = f(0), third = f(1.0 / 3), two_thirds = f(2.0 / 3), end = f(1);
    CHECK(start[0] == Approx(0).margin(1e-12));
    CHECK(start[1] == Approx(0).margin(1e-12));
    CHECK(third[0] == Approx(0.25));
    CHECK(third[1] == Approx(std::sqrt(3.0) / 4));
    CHECK(two_thirds[0] == Approx(0.75));
    CHECK(end[0] == Approx(1));
    CHECK(end[1] == Approx(0).margin(1e-12));
    // Continuous: values on both sides of a piece boundary agree.
    const auto left = f(1.0 / 3 - 1e-9), right = f(1.0 / 3 + 1e-9);
    CHECK(std::hypot(left[0] - right[0], left[1] - right[1]) < 1e-4);
}

TEST_CASE("fit: Hough recovery of Table 1 from 65 feature points", "[fit][hough]") {
    require_table1_recovered(6, 65);
}

TEST_CASE("fit: Hough recovery of Table 1 from 129 feature points", "[fit][hough]") {
    require_table1_recovered(7, 129);
}

TEST_CASE("fit: least-squares PFIF of the Sierpinski curve's top projection with 7 maps", "[fit][pfif]") {
    const Samples curve = sample(sierpinski_space_curve(), 163);
    const Samples top{curve.t, curve.x, {}};
    LeastSquaresOptions o;
    o.maps = 7;
    const FractalFunction f = fit_least_squares(top, o);
    REQUIRE(f.pieces.size() == 7);
    const FitError e = measure(f, top);
    // Seed 001 Fig. 6: max error 0.0858, mean squared error 0.000180 with 7 maps.
    CHECK(e.max_error <= 0.0858);
    CHECK(e.mse <= 0.00018);
    for (const Piece& p : f.pieces) CHECK(std::abs(p.map.c[0][0]) < 1);
}

TEST_CASE("fit: least-squares RFIF of the Sierpinski curve, eight and ten parameters", "[fit][rfif]") {
    const Samples s = sample(sierpinski_space_curve(), 244);
    LeastSquaresOptions o;
    o.maps = 9;
    o.recurrent = true;
    const FractalFunction coupled = fit_least_squares(s, o);
    o.coupled = false;
    const FractalFunction separable = fit_least_squares(s, o);
    CHECK(coupled.domains_are_unions_of_ranges(1e-12));
    const FitError ec = measure(coupled, s), es = measure(separable, s);
    // Both find maps that reproduce the curve: ten-parameter maps through the compositions of its own maps
    // (which mix x and y), eight-parameter ones through domains where the mixing cancels.
    CHECK(ec.max_error < 1e-6);
    CHECK(es.max_error < 1e-6);
    for (const Piece& p : separable.pieces) {
        CHECK(p.map.c[0][1] == 0);
        CHECK(p.map.c[1][0] == 0);
    }
    CHECK(separable.parameter_count() == 9 * (2 + 6 + 2));
    CHECK(coupled.parameter_count() == 9 * (2 + 8 + 2));
}

TEST_CASE("fit: models written as Frac source compile with their contraction proven", "[fit]") {
    FractalFunction fif = table1_fif();
    auto c = frac::driver::compile_source("fif.frac", to_frac(fif, "table1", "// Table 1\n"));
    INFO(c->diags.render(c->sources));
    CHECK(c->ok());
    const Samples s = sample(sierpinski_space_curve(), 244);
    LeastSquaresOptions o;
    o.maps = 9;
    o.recurrent = true;
    const FractalFunction rfif = fit_least_squares(s, o);
    auto r = frac::driver::compile_source("rfif.frac", to_frac(rfif, "curve", ""));
    INFO(r->diags.render(r->sources));
    CHECK(r->ok());
}

TEST_CASE("fit: 8-bit quantisation keeps a usable model", "[fit]") {
    const Samples curve = sample(sierpinski_space_curve(), 163);
    const Samples top{curve.t, curve.x, {}};
    LeastSquaresOptions o;
    o.maps = 7;
    FractalFunction f = fit_least_squares(top, o);
    quantize8(f, top);
    REQUIRE(make_consistent(f, 1e-9).empty());
    const FitError e = measure(f, top);
    CHECK(e.max_error > 0);
    CHECK(e.max_error < 0.1);
}

TEST_CASE("fit: a budget too small stops the fit", "[fit]") {
    const Samples s = feature_points(table1_fif(), 6);
    HoughOptions h;
    h.seconds = 1e-9;
    CHECK_THROWS_AS(hough_recover(s, h), BudgetExceeded);
}

TEST_CASE("fit: PFIF of a real EEG signal, domains longer than their ranges", "[fit][pfif]") {
    // python-matplotlib-data's EEG recording (800 x 4 float64, channel 0; installed by
    // scripts/install-deps.sh). On a grid of 48 cells, cuts of equal length differ in their last bits, and
    // a domain of its range's own length (|a| = 1, no contraction) was once taken for 16 maps.
    std::ifstream in("/usr/share/matplotlib/mpl-data/sample_data/eeg.dat", std::ios::binary);
    REQUIRE(in);
    std::vector<double> rows(800 * 4);
    in.read(reinterpret_cast<char*>(rows.data()), static_cast<std::streamsize>(rows.size() * sizeof(double)));
    REQUIRE(in.gcount() == static_cast<std::streamsize>(rows.size() * sizeof(double)));
    Samples eeg;
    for (std::size_t i = 0; i < 800; ++i) {
        eeg.t.push_back(static_cast<double>(i) / 799.0);
        eeg.x.push_back(rows[4 * i]);
    }
    LeastSquaresOptions options;
    options.maps = 16;
    options.grid = 48;
    const FractalFunction f = fit_least_squares(eeg, options);
    REQUIRE(f.pieces.size() == 16);
    for (const Piece& p : f.pieces) {
        CHECK(std::abs(p.map.a) < 1);
        CHECK(p.beta - p.alpha > p.hi - p.lo);
    }
    // The fit is close to the signal (the benchmark's table: PSNR about 26 dB, max error below 4).
    const FitError e = measure(f, eeg);
    CHECK(e.psnr > 24);
}
