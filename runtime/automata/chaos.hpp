// The chaos game for IFS and graph-directed CIFS, seeded and reproducible.
//
// Each state q keeps a current point x_q of its attractor A_q. A step updates every state reachable
// from the initial state: it draws one of q's arcs q -> b with its probability and sets
// x_q = T(x_b), so the current state of each point follows the arc taken. Unrolled, x_initial after
// k steps is T_1 T_2 ... T_k x_end along a random path of k arcs from the initial state with the
// arcs drawn independently per step: the graph-directed (Markov) measure on A_initial, also for
// automata whose initial state is transient (a projected B-spline) or whose graph is not strongly
// connected (the fern with a Sierpinski state). For a one-state IFS this is the classical chaos game.
// The points start at attractor points (address 0^infinity), and a transient is skipped anyway.
//
// Random numbers come from xoshiro256** seeded by splitmix64 (not std:: distributions, whose output
// differs across standard libraries): the same seed and thread count give the same density anywhere.
// Thread t runs its own stream, seeded from (seed, t), its own transient and its share of the points.
#pragma once

#include "ir/automaton.hpp"
#include "runtime/cover.hpp"
#include "runtime/picture.hpp"

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace frac::rt {

// splitmix64: seeds and mixes.
inline std::uint64_t splitmix64(std::uint64_t& state) {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

// xoshiro256** (Blackman and Vigna), seeded from a 64-bit seed and a stream index through splitmix64.
class Xoshiro256 {
public:
    explicit Xoshiro256(std::uint64_t seed, std::uint64_t stream = 0) {
        std::uint64_t sm = seed ^ (0xd1b54a32d192ed03ULL * (stream + 1));
        for (auto& w : s_) w = splitmix64(sm);
    }
    std::uint64_t operator()() {
        const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
        const std::uint64_t t = s_[1] << 17;
        s_[2] ^= s_[0];
        s_[3] ^= s_[1];
        s_[1] ^= s_[2];
        s_[0] ^= s_[3];
        s_[2] ^= t;
        s_[3] = rotl(s_[3], 45);
        return result;
    }

private:
    static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
    std::array<std::uint64_t, 4> s_{};
};

// Integer thresholds for drawing among weights with one 64-bit random number: arc i is taken when
// u < thresholds[i] (thresholds increase; the last is 2^64 - 1).
std::vector<std::uint64_t> draw_thresholds(const std::vector<double>& probabilities);

// Per arc: the probability of taking it from its state. The model's probabilities normalised per
// state when given; otherwise |det| of the linear part (the volume factor sqrt(det(L^T L)) when it
// is not square), with a floor of `floor` times the state's largest so that degenerate maps (the
// fern's stem) are still drawn, normalised per state; uniform when all are 0.
// Throws std::invalid_argument when a state's given probabilities are negative or sum to 0.
std::vector<double> chaos_probabilities(const ir::Automaton& a, double floor = 0.01);

struct ChaosOptions {
    std::uint64_t points = 1'000'000; // recorded points, all threads together
    std::uint64_t transient = 1000;   // steps skipped by each thread before recording
    std::uint64_t seed = 1;
    int threads = 1; // in [1, 256]
    int width = 512; // density grid columns, in [1, 16384]
    int height = 0;  // rows; 0: from the box's aspect ratio
    // x0, x1, y0, y1 of the grid; by default the bounding box of a pilot run of 20000 points (its own
    // stream of the same seed) enlarged by 5% on each side.
    std::optional<std::array<double, 4>> box;
    double degenerate_floor = 0.01; // see chaos_probabilities
};

struct Density {
    int width = 0, height = 0;
    double x0 = 0, x1 = 0, y0 = 0, y1 = 0;
    std::vector<std::uint64_t> counts; // row 0 is the lowest y, x fastest
    std::uint64_t recorded = 0;        // points that fell in the grid
    std::uint64_t outside = 0;         // points outside the box
    std::uint64_t count(int ix, int iy) const {
        return counts[static_cast<std::size_t>(iy) * static_cast<std::size_t>(width) +
                      static_cast<std::size_t>(ix)];
    }
};

// The density of the initial state's attractor (through the projection; x, y of the output space,
// y = 0 for a 1D output). Throws std::invalid_argument on an automaton the chaos game cannot run
// (a reachable state without arcs, operators of the wrong size, bad options).
Density chaos_game(const ir::Automaton& a, const ChaosOptions& options = {});

// The stream of points itself (one thread): `visit` gets the output coordinates of each of `points`
// points after `transient` steps.
void chaos_points(const ir::Automaton& a, std::uint64_t points, std::uint64_t transient, std::uint64_t seed,
                  const std::function<void(const std::vector<double>&)>& visit,
                  double degenerate_floor = 0.01);

// The density as a cover (runtime/cover.hpp), so that pictures and box counting (runtime/dimension.hpp)
// work on chaos-game attractors: the grid must be 2^depth x 2^depth (depth in [0, 12]); a cell of
// level k is occupied when a point fell in it, occupied cells are subdivided (boundary at the last
// level), empty ones outside. With keep_cells, the cells are listed as the cover's order requires.
Cover density_cover(const Density& d, bool keep_cells = true);
// chaos_game on a 2^depth grid (options.width and height are replaced), as a cover.
Cover chaos_cover(const ir::Automaton& a, int depth, ChaosOptions options = {}, bool keep_cells = true);

// Grey levels, log-scaled from white (no point) to black (the densest cell), y up.
Image density_image(const Density& d);
void write_density_png(const Density& d, const std::string& path);

} // namespace frac::rt
