#include "runtime/automata/chaos.hpp"

#include "ir/automaton_check.hpp"
#include "runtime/automata/points.hpp"
#include "runtime/limits.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <thread>

namespace frac::rt {

namespace {

double volume_factor(const num::Matrix<double>& l) {
    if (l.rows() == 0 || l.cols() == 0) return 0;
    const bool tall = l.rows() >= l.cols();
    const num::Matrix<double> g = tall ? num::transpose(l) * l : l * num::transpose(l);
    return std::sqrt(std::max(0.0, num::determinant(g)));
}

// The automaton laid out for the inner loop: every live state's point padded to N coordinates and
// every arc's matrix to N x N (row-major), the arcs of a state contiguous.
struct Prepared {
    std::size_t n = 0;   // padded coordinates (the template's N)
    bool affine = false; // every live state is R^d with the same d = n - 1: the last row is (0 ... 0 1)
    bool direct = false; // no projection: the output is the first one or two coordinates
    std::vector<std::size_t> order;         // live states, updated in this order each step
    std::vector<std::size_t> first, count;  // per state: its arcs in `to`, `thresholds`, `m`
    std::vector<std::size_t> to;            // per arc
    std::vector<std::uint64_t> thresholds;  // per arc
    std::vector<double> m;                  // per arc, n * n
    std::vector<double> start;              // per state, n: attractor points
    std::array<std::vector<double>, 2> out; // the output rows x, y (n each)
    std::size_t initial = 0;
    int dims = 2;
};

Prepared prepare(const ir::Automaton& a, double floor) {
    const std::size_t ns = a.states.size();
    require_well_formed(a);
    const std::vector<bool> live = ir::reachable_states(a);
    Prepared p;
    p.initial = a.initial;
    p.dims = a.output_dimension();
    std::size_t coords = 0;
    p.affine = true;
    for (std::size_t s = 0; s < ns; ++s) {
        if (!live[s]) continue;
        const ir::Space sp = a.states[s].space;
        coords = std::max(coords, static_cast<std::size_t>(sp.coordinates()));
        p.affine = p.affine && sp == a.states[a.initial].space && sp.kind == ir::Space::Kind::euclidean;
        if (a.arcs_from(s).empty())
            throw std::invalid_argument(fmt::format(
                "state {} has no transitions, so the chaos game cannot continue from it", a.states[s].name));
        p.order.push_back(s);
    }
    std::size_t n = 2;
    for (std::size_t c : {2, 3, 4, 6, 8, 16})
        if (c >= coords) {
            n = c;
            break;
        }
    if (coords > 16) throw std::invalid_argument("the chaos game supports spaces of at most 16 coordinates");
    // The affine kernel keeps the homogeneous 1 in the last coordinate, so it needs n == coords.
    p.affine = p.affine && n == coords;
    p.n = n;
    const std::vector<double> prob = chaos_probabilities(a, floor);
    p.first.assign(ns, 0);
    p.count.assign(ns, 0);
    for (std::size_t s : p.order) {
        const std::vector<std::size_t> arcs = a.arcs_from(s);
        std::vector<double> w;
        for (std::size_t i : arcs) w.push_back(prob[i]);
        const std::vector<std::uint64_t> t = draw_thresholds(w);
        p.first[s] = p.to.size();
        p.count[s] = arcs.size();
        for (std::size_t k = 0; k < arcs.size(); ++k) {
            const ir::Arc& arc = a.arcs[arcs[k]];
            p.to.push_back(arc.to);
            p.thresholds.push_back(t[k]);
            std::vector<double> mat(n * n, 0.0);
            for (std::size_t r = 0; r < arc.op.rows(); ++r)
                for (std::size_t c = 0; c < arc.op.cols(); ++c) mat[r * n + c] = arc.op.nearest(r, c);
            p.m.insert(p.m.end(), mat.begin(), mat.end());
        }
    }
    p.start.assign(ns * n, 0.0);
    for (std::size_t s : p.order) {
        const std::vector<double> x = attractor_point(a, s);
        std::copy(x.begin(), x.end(), p.start.begin() + static_cast<std::ptrdiff_t>(s * n));
    }
    const num::Matrix<double> o = output_matrix(a);
    p.direct = !a.projection;
    for (std::size_t r = 0; r < 2; ++r) {
        p.out[r].assign(n, 0.0);
        if (r + 1 < o.rows())
            for (std::size_t c = 0; c < o.cols(); ++c) p.out[r][c] = o(r, c);
    }
    return p;
}

// `steps` steps of the game; after the first `transient`, record(x, y) for the initial state's point.
// y = M x for an N x N matrix; affine maps skip the last row (0 ... 0 1) and add the last column
// without multiplying it by the homogeneous 1 (the same bits, fewer operations).
template <std::size_t N, bool Affine>
inline std::array<double, N> apply(const double* m, const std::array<double, N>& x) {
    std::array<double, N> y;
    constexpr std::size_t rows = Affine ? N - 1 : N, cols = Affine ? N - 1 : N;
    for (std::size_t r = 0; r < rows; ++r) {
        double s = m[r * N] * x[0];
        for (std::size_t c = 1; c < cols; ++c) s += m[r * N + c] * x[c];
        if constexpr (Affine) s += m[r * N + N - 1];
        y[r] = s;
    }
    if constexpr (Affine) y[N - 1] = 1.0;
    return y;
}

// `transient` steps, then `points` steps each followed by record(x, y) of the initial state's point.
// The generator and the pointers are copied to locals so that the compiler keeps them in registers
// (the density's counter increments could otherwise alias them).
template <std::size_t N, bool Affine, bool Direct, typename Record>
[[gnu::flatten]] void run(const Prepared& p, Xoshiro256& shared_rng, std::uint64_t transient,
                          std::uint64_t points, Record&& record) {
    Xoshiro256 rng = shared_rng;
    const std::uint64_t* thresholds = p.thresholds.data();
    const std::size_t* to = p.to.data();
    const double* mats = p.m.data();
    const std::array<double, 2 * N> out = [&] {
        std::array<double, 2 * N> o{};
        for (std::size_t c = 0; c < N; ++c) o[c] = p.out[0][c], o[N + c] = p.out[1][c];
        return o;
    }();
    const bool plane = p.dims >= 2;
    auto emit = [&](const std::array<double, N>& x) {
        if constexpr (Direct) {
            record(x[0], plane ? x[1] : 0.0);
        } else {
            double px = 0, py = 0;
            for (std::size_t c = 0; c < N; ++c) px += out[c] * x[c], py += out[N + c] * x[c];
            record(px, py);
        }
    };
    auto draw = [&](std::size_t first) {
        const std::uint64_t u = rng();
        std::size_t i = first;
        while (u > thresholds[i]) ++i;
        return i;
    };
    if (p.order.size() == 1) {
        // One live state (an IFS): its point stays in registers.
        const std::size_t first = p.first[p.initial];
        std::array<double, N> x;
        for (std::size_t c = 0; c < N; ++c) x[c] = p.start[p.initial * N + c];
        for (std::uint64_t t = 0; t < transient; ++t) x = apply<N, Affine>(mats + draw(first) * N * N, x);
        for (std::uint64_t t = 0; t < points; ++t) {
            x = apply<N, Affine>(mats + draw(first) * N * N, x);
            emit(x);
        }
    } else {
        std::vector<std::array<double, N>> x(p.start.size() / N);
        for (std::size_t s = 0; s < x.size(); ++s)
            for (std::size_t c = 0; c < N; ++c) x[s][c] = p.start[s * N + c];
        auto step = [&] {
            for (std::size_t q : p.order) {
                const std::size_t i = draw(p.first[q]);
                x[q] = apply<N, Affine>(mats + i * N * N, x[to[i]]);
            }
        };
        for (std::uint64_t t = 0; t < transient; ++t) step();
        for (std::uint64_t t = 0; t < points; ++t) {
            step();
            emit(x[p.initial]);
        }
    }
    shared_rng = rng;
}

template <typename Record>
void dispatch(const Prepared& p, Xoshiro256& rng, std::uint64_t transient, std::uint64_t points,
              Record&& record) {
    auto with_n = [&]<std::size_t N>() {
        if (p.affine && p.direct)
            run<N, true, true>(p, rng, transient, points, record);
        else if (p.affine)
            run<N, true, false>(p, rng, transient, points, record);
        else if (p.direct)
            run<N, false, true>(p, rng, transient, points, record);
        else
            run<N, false, false>(p, rng, transient, points, record);
    };
    switch (p.n) {
    case 2: with_n.template operator()<2>(); break;
    case 3: with_n.template operator()<3>(); break;
    case 4: with_n.template operator()<4>(); break;
    case 6: with_n.template operator()<6>(); break;
    case 8: with_n.template operator()<8>(); break;
    default: with_n.template operator()<16>(); break;
    }
}

} // namespace

std::vector<std::uint64_t> draw_thresholds(const std::vector<double>& probabilities) {
    double total = 0;
    for (double w : probabilities) total += w;
    std::vector<std::uint64_t> t(probabilities.size());
    double cumulative = 0;
    for (std::size_t i = 0; i < t.size(); ++i) {
        cumulative += probabilities[i];
        // u in [0, 2^64) is compared with cumulative * 2^64 - 1; the last threshold takes the rest.
        const double scaled = cumulative / total * 18446744073709551616.0;
        if (scaled >= 18446744073709551616.0) {
            t[i] = std::numeric_limits<std::uint64_t>::max();
        } else {
            const auto v = static_cast<std::uint64_t>(std::max(scaled, 0.0));
            t[i] = v ? v - 1 : 0;
        }
    }
    if (!t.empty()) t.back() = std::numeric_limits<std::uint64_t>::max();
    return t;
}

std::vector<double> chaos_probabilities(const ir::Automaton& a, double floor) {
    std::vector<double> p(a.arcs.size(), 0.0);
    for (std::size_t s = 0; s < a.states.size(); ++s) {
        const std::vector<std::size_t> arcs = a.arcs_from(s);
        if (arcs.empty()) continue;
        const bool given =
            std::all_of(arcs.begin(), arcs.end(), [&](std::size_t i) { return a.arcs[i].probability; });
        std::vector<double> w;
        if (given) {
            for (std::size_t i : arcs) {
                const double v = *a.arcs[i].probability;
                if (!(std::isfinite(v) && v >= 0))
                    throw std::invalid_argument(
                        fmt::format("arc {} has the probability {}", ir::arc_name(a, i), v));
                w.push_back(v);
            }
        } else {
            double largest = 0;
            for (std::size_t i : arcs) {
                const num::Matrix<num::Interval> l = ir::linear_part(a, i);
                num::Matrix<double> m(l.rows(), l.cols());
                for (std::size_t r = 0; r < l.rows(); ++r)
                    for (std::size_t c = 0; c < l.cols(); ++c) m(r, c) = num::midpoint(l(r, c));
                w.push_back(volume_factor(m));
                largest = std::max(largest, w.back());
            }
            for (double& v : w) v = largest > 0 ? std::max(v, floor * largest) : 1.0;
        }
        double total = 0;
        for (double v : w) total += v;
        if (!(total > 0))
            throw std::invalid_argument(
                fmt::format("the probabilities of the transitions of state {} sum to 0", a.states[s].name));
        for (std::size_t k = 0; k < arcs.size(); ++k) p[arcs[k]] = w[k] / total;
    }
    return p;
}

void chaos_points(const ir::Automaton& a, std::uint64_t points, std::uint64_t transient, std::uint64_t seed,
                  const std::function<void(const std::vector<double>&)>& visit, double degenerate_floor) {
    const Prepared p = prepare(a, degenerate_floor);
    Xoshiro256 rng(seed, 0);
    std::vector<double> xy(static_cast<std::size_t>(std::min(p.dims, 2)));
    dispatch(p, rng, transient, points, [&](double x, double y) {
        xy[0] = x;
        if (xy.size() > 1) xy[1] = y;
        visit(xy);
    });
}

Density chaos_game(const ir::Automaton& a, const ChaosOptions& o) {
    if (o.threads < 1 || o.threads > 256)
        throw std::invalid_argument(fmt::format("threads {} is outside [1, 256]", o.threads));
    if (o.width < 1 || o.width > 16384 || o.height < 0 || o.height > 16384)
        throw std::invalid_argument("the density grid must have 1 to 16384 columns and rows");
    const Prepared p = prepare(a, o.degenerate_floor);
    Density d;
    if (o.box) {
        const auto& b = *o.box;
        if (!(b[0] < b[1] && b[2] < b[3]) || !std::isfinite(b[1] - b[0]) || !std::isfinite(b[3] - b[2]))
            throw std::invalid_argument("the density box needs x0 < x1 and y0 < y1, finite");
        d.x0 = b[0], d.x1 = b[1], d.y0 = b[2], d.y1 = b[3];
    } else {
        double x0 = num::inf, x1 = -num::inf, y0 = num::inf, y1 = -num::inf;
        Xoshiro256 pilot(o.seed, 0xb0c5);
        dispatch(p, pilot, o.transient, 20000, [&](double x, double y) {
            x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
        });
        if (!std::isfinite(x1 - x0) || !std::isfinite(y1 - y0))
            throw RangeError(
                fmt::format("the attractor of '{}' leaves the range of doubles (the chaos game's "
                            "points are not finite): scale its coordinates down",
                            a.name));
        const double span = std::max({x1 - x0, y1 - y0, 1e-12});
        // Flat attractors (a curve on y = 0, the Cantor set) still get a band of rows.
        const double mx = std::max(0.05 * (x1 - x0), 0.005 * span),
                     my = std::max(0.05 * (y1 - y0), 0.005 * span);
        d.x0 = x0 - mx, d.x1 = x1 + mx, d.y0 = y0 - my, d.y1 = y1 + my;
    }
    d.width = o.width;
    d.height = o.height ? o.height
                        : std::clamp(static_cast<int>(std::lround(o.width * (d.y1 - d.y0) / (d.x1 - d.x0))),
                                     1, 16384);
    const std::size_t cells = static_cast<std::size_t>(d.width) * static_cast<std::size_t>(d.height);
    const double sx = d.width / (d.x1 - d.x0), sy = d.height / (d.y1 - d.y0);
    const double w = d.width, h = d.height;
    const auto threads = static_cast<std::uint64_t>(o.threads);
    // Each thread counts into its own grid (no shared writes in the loop), of 32-bit counters when its
    // share cannot overflow them: half the cache footprint of 64-bit ones, which matters once two
    // threads share the caches. The grids are added up at the end.
    std::vector<std::vector<std::uint32_t>> narrow(threads);
    std::vector<std::vector<std::uint64_t>> wide(threads);
    std::vector<std::uint64_t> outside(threads, 0);
    auto work = [&](std::uint64_t t) {
        std::uint64_t out = 0;
        Xoshiro256 rng(o.seed, t);
        const std::uint64_t share = o.points / threads + (t < o.points % threads ? 1 : 0);
        const std::size_t width = static_cast<std::size_t>(d.width);
        const double x0 = d.x0, y0 = d.y0;
        auto count_into = [&](auto* cells_of) {
            dispatch(p, rng, o.transient, share, [&](double x, double y) {
                const double fx = (x - x0) * sx, fy = (y - y0) * sy;
                if (fx >= 0 && fx < w && fy >= 0 && fy < h)
                    ++cells_of[static_cast<std::size_t>(fy) * width + static_cast<std::size_t>(fx)];
                else
                    ++out;
            });
        };
        if (share <= std::numeric_limits<std::uint32_t>::max()) {
            narrow[t].assign(cells, 0);
            count_into(narrow[t].data());
        } else {
            wide[t].assign(cells, 0);
            count_into(wide[t].data());
        }
        outside[t] = out;
    };
    if (threads == 1) {
        work(0);
    } else {
        std::vector<std::thread> pool;
        for (std::uint64_t t = 0; t < threads; ++t) pool.emplace_back(work, t);
        for (auto& th : pool) th.join();
    }
    d.counts.assign(cells, 0);
    for (std::uint64_t t = 0; t < threads; ++t) {
        if (!narrow[t].empty())
            for (std::size_t i = 0; i < cells; ++i) d.counts[i] += narrow[t][i];
        if (!wide[t].empty())
            for (std::size_t i = 0; i < cells; ++i) d.counts[i] += wide[t][i];
    }
    for (std::uint64_t v : outside) d.outside += v;
    d.recorded = o.points - d.outside;
    return d;
}

Cover density_cover(const Density& d, bool keep_cells) {
    int depth = 0;
    while (depth <= 12 && (1 << depth) < d.width) ++depth;
    if (depth > 12 || d.width != (1 << depth) || d.height != d.width)
        throw std::invalid_argument(fmt::format(
            "a density cover needs a 2^k x 2^k grid with k <= 12, not {} x {}", d.width, d.height));
    Cover c;
    c.root = {num::Interval(d.x0, d.x1), num::Interval(d.y0, d.y1)};
    c.depth = depth;
    c.split = 2;
    c.levels.assign(static_cast<std::size_t>(depth) + 1, LevelCounts{});
    // Occupancy per level, finest first, coarser ones by OR over 2 x 2 children.
    std::vector<std::vector<std::uint8_t>> occupied(static_cast<std::size_t>(depth) + 1);
    occupied[static_cast<std::size_t>(depth)].resize(d.counts.size());
    for (std::size_t i = 0; i < d.counts.size(); ++i)
        occupied[static_cast<std::size_t>(depth)][i] = d.counts[i] > 0;
    for (int k = depth - 1; k >= 0; --k) {
        const std::size_t n = std::size_t{1} << k;
        auto& level = occupied[static_cast<std::size_t>(k)];
        const auto& finer = occupied[static_cast<std::size_t>(k) + 1];
        level.assign(n * n, 0);
        for (std::size_t y = 0; y < 2 * n; ++y)
            for (std::size_t x = 0; x < 2 * n; ++x) level[(y / 2) * n + x / 2] |= finer[y * 2 * n + x];
    }
    for (int k = 0; k <= depth; ++k) {
        const std::size_t n = std::size_t{1} << k;
        LevelCounts& lc = c.levels[static_cast<std::size_t>(k)];
        for (std::size_t y = 0; y < n; ++y)
            for (std::size_t x = 0; x < n; ++x) {
                if (k > 0 && !occupied[static_cast<std::size_t>(k) - 1][(y / 2) * (n / 2) + x / 2]) continue;
                ++lc.evaluated;
                const bool full = occupied[static_cast<std::size_t>(k)][y * n + x];
                CellClass cls = CellClass::outside;
                if (full) {
                    ++lc.undecided;
                    cls = k < depth ? CellClass::subdivided : CellClass::boundary;
                } else {
                    ++lc.outside;
                }
                if (keep_cells)
                    c.cells.push_back({static_cast<std::uint8_t>(k), cls, static_cast<std::uint32_t>(x),
                                       static_cast<std::uint32_t>(y), 0});
            }
        c.evaluated += lc.evaluated;
        c.outside += lc.outside;
        if (k < depth)
            c.subdivided += lc.undecided;
        else
            c.boundary = lc.undecided;
    }
    return c;
}

Cover chaos_cover(const ir::Automaton& a, int depth, ChaosOptions options, bool keep_cells) {
    if (depth < 0 || depth > 12)
        throw std::invalid_argument(fmt::format("cover depth {} is outside [0, 12]", depth));
    options.width = options.height = 1 << depth;
    return density_cover(chaos_game(a, options), keep_cells);
}

Image density_image(const Density& d) {
    Image img;
    img.width = d.width;
    img.height = d.height;
    img.rgb.assign(static_cast<std::size_t>(d.width) * static_cast<std::size_t>(d.height) * 3, 255);
    std::uint64_t most = 0;
    for (std::uint64_t c : d.counts) most = std::max(most, c);
    if (most == 0) return img;
    const double scale = 1.0 / std::log1p(static_cast<double>(most));
    for (int iy = 0; iy < d.height; ++iy)
        for (int ix = 0; ix < d.width; ++ix) {
            const std::uint64_t c = d.count(ix, iy);
            if (!c) continue;
            // Any point at all is visibly grey; the densest cell black.
            const double level = 0.25 + 0.75 * std::log1p(static_cast<double>(c)) * scale;
            const auto v = static_cast<std::uint8_t>(std::lround(255.0 * (1.0 - std::min(level, 1.0))));
            const std::size_t row = static_cast<std::size_t>(d.height - 1 - iy); // y up
            std::uint8_t* px =
                &img.rgb[(row * static_cast<std::size_t>(d.width) + static_cast<std::size_t>(ix)) * 3];
            px[0] = px[1] = px[2] = v;
        }
    return img;
}

void write_density_png(const Density& d, const std::string& path) {
    write_png(density_image(d), path);
}

} // namespace frac::rt
