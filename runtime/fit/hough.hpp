// Recovery of the self-affine maps of a function from its graph by a Hough transform (seed 001 sec. 3.1).
// Every four-tuple of samples i + 1 < k, l + 1 < n with t_k - t_i > t_n - t_l gives the two maps of t
// taking [t_i, t_k] onto [t_l, t_n] (a, d; eq. 10-13); each sample j between i and k, matched to the
// sample m between l and n nearest its image, then fixes b, c, e (eq. 14). The maps are counted in a
// 3-D histogram of (a, b, c) (first pass); the K most popular (a, b, c) clusters get a 2-D histogram of
// (d, e), filled by a second pass over the same maps. Clusters are local maxima of the histograms (so the
// spill-over of a cluster into adjacent bins is not a second cluster), and a cluster whose map is the
// composition of two more popular ones (an "echo") is dropped.
#pragma once

#include "runtime/fit/data.hpp"
#include "runtime/fit/model.hpp"

#include <cstdint>
#include <functional>
#include <vector>

namespace frac::rt::fit {

struct HoughOptions {
    int abc_bins = 128;    // per axis of the first pass (the paper's 128^3)
    int de_bins = 256;     // per axis of the second pass (the paper's 256^2)
    int abc_clusters = 16; // K: the (a, b, c) clusters kept for the second pass
    int results = 10;      // clusters returned
    bool remove_echoes = true;
    // Maps with |c| below this are not counted: such a map flattens its domain into nearly a segment, so it
    // matches any nearly straight stretch of the data from any domain and says nothing of self-affinity
    // (without it, the many maps of long domains onto ranges of 3 samples pile up around c = 0).
    double min_scaling = 0.1;
    double seconds = 0; // time budget (0: none); past it the recovery throws BudgetExceeded
    std::function<void(const std::string&)> progress; // a line of progress, or empty
};

struct HoughCluster {
    std::uint64_t hits = 0; // maps in the cluster's (a, b, c, d, e) bin
    Shear map;              // the bin's centre (a, d, b[0], c[0][0], e[0])
};

// The quantisation step of each parameter (half of it is the error of a bin centre).
struct HoughSteps {
    double a, b, c, d, e;
};

struct HoughResult {
    std::vector<HoughCluster> clusters; // most popular first
    std::uint64_t maps = 0;             // maps generated in a pass (valid or not)
    std::uint64_t valid = 0;            // maps inside the parameter box with |c| < 1
    HoughSteps steps{};
};

// The samples must be of a function (t increasing), at least 5.
HoughResult hough_recover(const Samples& data, const HoughOptions& options);

// The FIF made of the `count` most popular clusters: their ranges must tile the data's interval within
// `join_tolerance` (then they are joined exactly, at midpoints). Throws std::runtime_error saying why not.
FractalFunction fif_from_clusters(const HoughResult& result, const Samples& data, std::size_t count);
// How far a join between the ranges of recovered maps may be from the true one: quantisation of d and a.
double join_tolerance(const HoughResult& result, const Samples& data);

} // namespace frac::rt::fit
