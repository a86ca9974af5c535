#include "runtime/automata/attractor_cover.hpp"

#include "runtime/automata/distance.hpp"
#include "runtime/limits.hpp"
#include "runtime/rss.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <fmt/format.h>
#include <functional>
#include <stdexcept>

namespace frac::rt {

std::vector<bool> recurrent_vertices(const std::vector<std::uint64_t>& offsets,
                                     const std::vector<std::uint32_t>& targets) {
    const std::size_t n = offsets.empty() ? 0 : offsets.size() - 1;
    constexpr std::uint32_t unvisited = UINT32_MAX;
    std::vector<std::uint32_t> index(n, unvisited), low(n, 0);
    std::vector<bool> on_stack(n, false), recurrent(n, false);
    std::vector<std::uint32_t> stack;                          // Tarjan's stack of vertices
    std::vector<std::pair<std::uint32_t, std::uint64_t>> call; // (vertex, next arc): the recursion, explicit
    std::uint32_t counter = 0;
    for (std::size_t root = 0; root < n; ++root) {
        if (index[root] != unvisited) continue;
        call.push_back({static_cast<std::uint32_t>(root), offsets[root]});
        index[root] = low[root] = counter++;
        stack.push_back(static_cast<std::uint32_t>(root)), on_stack[root] = true;
        while (!call.empty()) {
            auto& [v, next] = call.back();
            if (next < offsets[v + 1]) {
                const std::uint32_t w = targets[next++];
                if (index[w] == unvisited) {
                    index[w] = low[w] = counter++;
                    stack.push_back(w), on_stack[w] = true;
                    call.push_back({w, offsets[w]});
                } else if (on_stack[w]) {
                    low[v] = std::min(low[v], index[w]);
                }
                continue;
            }
            const std::uint32_t done = v;
            call.pop_back();
            if (!call.empty()) low[call.back().first] = std::min(low[call.back().first], low[done]);
            if (low[done] != index[done]) continue;
            // `done` is the root of a component: pop it; several vertices, or a loop, make it recurrent.
            std::size_t size = 0, first = stack.size();
            while (true) {
                const std::uint32_t w = stack[--first];
                ++size;
                if (w == done) break;
            }
            bool loop = false;
            if (size == 1)
                for (std::uint64_t e = offsets[done]; e < offsets[done + 1]; ++e)
                    loop = loop || targets[e] == done;
            for (std::size_t i = first; i < stack.size(); ++i) {
                on_stack[stack[i]] = false;
                recurrent[stack[i]] = size > 1 || loop;
            }
            stack.resize(first);
        }
    }
    return recurrent;
}

namespace {

using Key = std::uint64_t; // (iz * n + iy) * n + ix at the current level

struct Grid {
    std::vector<Interval> root; // per axis: 2 or 3 (states of one automaton may differ)
    std::vector<Interval> width;
    // Whether the state lies on a cycle of the automaton's graph: its cells are kept when they are
    // recurrent. A state on no cycle (a projected spline's initial state) holds the images of the
    // others' attractors: its cells are kept when a kept cell maps onto them.
    bool on_cycle = true;
    int dimension() const { return static_cast<int>(root.size()); }
};

// A target of an image: a state and the box its cell's image lies in.
struct Image {
    std::size_t state;
    std::array<Interval, 3> box;
};

// The images of many cells at once: states[i], boxes (as many intervals per cell as its state has
// axes, one cell after the other) -> appended to `out`, with
// `first[i]` the index of cell i's first image (first has one more entry).
using ImageFn = std::function<void(const std::vector<std::size_t>& states, const std::vector<Interval>& boxes,
                                   std::vector<Image>& out, std::vector<std::size_t>& first)>;

std::array<std::uint32_t, 3> position(Key k, std::uint64_t n) {
    return {static_cast<std::uint32_t>(k % n), static_cast<std::uint32_t>((k / n) % n),
            static_cast<std::uint32_t>(k / n / n)};
}
Key key_of(std::uint64_t ix, std::uint64_t iy, std::uint64_t iz, std::uint64_t n) {
    return (iz * n + iy) * n + ix;
}

// Keeps the recurrent vertices of states on a cycle, then every vertex of a state on no cycle that a
// kept vertex has an arc to (breadth first: such states may feed one another).
std::vector<bool> kept_vertices(const std::vector<std::uint64_t>& offsets,
                                const std::vector<std::uint32_t>& targets,
                                const std::vector<bool>& on_cycle_vertex) {
    std::vector<bool> keep = recurrent_vertices(offsets, targets);
    std::vector<std::uint32_t> queue;
    for (std::size_t v = 0; v < keep.size(); ++v) {
        if (!on_cycle_vertex[v]) keep[v] = false;
        if (keep[v]) queue.push_back(static_cast<std::uint32_t>(v));
    }
    while (!queue.empty()) {
        const std::uint32_t v = queue.back();
        queue.pop_back();
        for (std::uint64_t e = offsets[v]; e < offsets[v + 1]; ++e) {
            const std::uint32_t w = targets[e];
            if (!keep[w] && !on_cycle_vertex[w]) keep[w] = true, queue.push_back(w);
        }
    }
    return keep;
}

// Refuses (LimitError), before the kept cells of `level` are split, a next level of more cells than the
// limit, or a last level foreseen above it: the cells of the next level times the growth of the kept
// cells over the last two graphs (at least 1) for each level after it. The growth of a cover's kept
// cells rises towards 2^dimension as its cells shrink, so the foresight seldom overstates.
void check_next_level(const std::vector<Grid>& grids, const std::vector<bool>& rec,
                      const std::vector<std::size_t>& base, int level, int last, double kept_before,
                      const AttractorCoverOptions& o) {
    double next = 0, kept = 0;
    for (std::size_t s = 0; s < grids.size(); ++s) {
        const double k =
            static_cast<double>(std::count(rec.begin() + static_cast<std::ptrdiff_t>(base[s]),
                                           rec.begin() + static_cast<std::ptrdiff_t>(base[s + 1]), true));
        kept += k;
        next += k * (grids[s].dimension() == 2 ? 4 : 8);
    }
    const double growth = kept_before > 0 ? std::max(1.0, kept / kept_before) : 1.0;
    const double foreseen = next * std::pow(growth, last - level - 1);
    const double limit = static_cast<double>(std::min<std::uint64_t>(o.max_cells, UINT32_MAX - 1));
    if (next > limit)
        throw LimitError(
            fmt::format("attractor cover: level {} would have {} cells, more than the limit of {} "
                        "cells",
                        level + 1, next, o.max_cells),
            next, o.max_cells);
    if (foreseen > limit)
        throw LimitError(
            fmt::format("attractor cover: level {} would have about {:.3g} cells (foreseen after "
                        "level {}), more than the limit of {} cells",
                        last, foreseen, level, o.max_cells),
            foreseen, o.max_cells);
}

AttractorCoverResult build(const std::vector<Grid>& grids, std::size_t initial, const ImageFn& images,
                           const AttractorCoverOptions& o) {
    if (o.initial_level < 0 || o.refinements < 0)
        throw std::invalid_argument("attractor cover: levels must not be negative");
    const int last = o.initial_level + o.refinements;
    const int d = grids[initial].dimension();
    int deepest = d;
    for (const Grid& g : grids) deepest = std::max(deepest, g.dimension());
    if (last > (deepest == 2 ? max_depth_2d : max_depth_3d) || last > 20)
        throw std::invalid_argument(
            fmt::format("attractor cover: level {} is too deep for {}D", last, deepest));
    const std::size_t ns = grids.size();
    AttractorCoverResult out;
    out.root = grids[initial].root;
    out.split = 2;
    out.depth = last;
    out.levels.assign(static_cast<std::size_t>(last + 1), {});
    std::vector<std::vector<Cell>> level_cells(static_cast<std::size_t>(last + 1));

    // The kept cells of every state, sorted keys; first every cell of the initial grid.
    std::uint64_t n = std::uint64_t(1) << o.initial_level;
    auto cells_of = [&](std::size_t s) { return grids[s].dimension() == 2 ? n * n : n * n * n; };
    std::uint64_t all = 0;
    for (std::size_t s = 0; s < ns; ++s) all += cells_of(s);
    if (all > o.max_cells)
        throw LimitError(fmt::format("attractor cover: the first grid (level {}) has {} cells, more than "
                                     "the limit of {} cells",
                                     o.initial_level, all, o.max_cells),
                         static_cast<double>(all), o.max_cells);
    // A large first grid is preceded by a coarse cover (some 256 times fewer cells) whose growth per
    // level foretells the last level: a depth that would not fit is refused before the first grid.
    if (o.refinements > 0 && o.initial_level >= 6 && all > (std::uint64_t(1) << 16)) {
        AttractorCoverOptions coarse = o;
        coarse.initial_level = o.initial_level - 4;
        coarse.refinements = 2;
        const std::vector<CoverStep> steps = build(grids, initial, images, coarse).steps;
        const int at = coarse.initial_level + coarse.refinements;
        const double cells = static_cast<double>(steps.back().cells);
        const double growth = std::max(1.0, cells / std::max(1.0, static_cast<double>(steps[1].cells)));
        const double foreseen = cells * std::pow(growth, last - at);
        if (foreseen > static_cast<double>(o.max_cells))
            throw LimitError(fmt::format("attractor cover: level {} would have about {:.3g} cells (foreseen "
                                         "from a cover to level {}), more than the limit of {} cells",
                                         last, foreseen, at, o.max_cells),
                             foreseen, o.max_cells);
    }
    std::vector<std::vector<Key>> kept(ns);
    double kept_before = 0; // the cells the previous graph kept (0: none yet)
    for (std::size_t s = 0; s < ns; ++s) {
        kept[s].resize(cells_of(s));
        for (Key i = 0; i < kept[s].size(); ++i) kept[s][i] = i;
    }

    for (int level = o.initial_level; level <= last; ++level) {
        const auto t0 = std::chrono::steady_clock::now();
        CoverStep step;
        step.level = level;
        std::vector<std::size_t> base(ns + 1, 0); // vertex ids: base[s] + index in kept[s]
        for (std::size_t s = 0; s < ns; ++s) base[s + 1] = base[s] + kept[s].size();
        const std::size_t total = base[ns];
        step.cells = total;
        if (total > o.max_cells || total >= UINT32_MAX)
            throw LimitError(fmt::format("attractor cover: level {} has {} cells, more than the limit of {} "
                                         "cells",
                                         level, total, o.max_cells),
                             static_cast<double>(total), o.max_cells);
        num::UpwardRounding up;
        auto cell_box = [&](std::size_t s, Key k, int axis) {
            const auto p = position(k, n);
            return grid::cell(grids[s].root[static_cast<std::size_t>(axis)],
                              grids[s].width[static_cast<std::size_t>(axis)],
                              p[static_cast<std::size_t>(axis)], n);
        };

        // Arcs, built in chunks of cells (the images of a chunk are computed in one batch).
        std::vector<std::uint64_t> offsets{0};
        std::vector<std::uint32_t> targets;
        offsets.reserve(total + 1);
        constexpr std::size_t chunk = 8192;
        std::vector<std::size_t> states, first;
        std::vector<Interval> boxes;
        std::vector<Image> imgs;
        std::size_t s_at = 0, i_at = 0; // the next cell: state and index
        while (s_at < ns) {
            states.clear(), boxes.clear(), imgs.clear(), first.clear();
            std::vector<std::pair<std::size_t, std::size_t>> cells;
            while (s_at < ns && cells.size() < chunk) {
                if (i_at >= kept[s_at].size()) {
                    ++s_at, i_at = 0;
                    continue;
                }
                cells.push_back({s_at, i_at});
                states.push_back(s_at);
                for (int a = 0; a < grids[s_at].dimension(); ++a)
                    boxes.push_back(cell_box(s_at, kept[s_at][i_at], a));
                ++i_at;
            }
            if (cells.empty()) break;
            images(states, boxes, imgs, first);
            const num::UpwardRounding again; // evaluators may have changed the rounding mode
            for (std::size_t c = 0; c < cells.size(); ++c) {
                for (std::size_t m = first[c]; m < first[c + 1]; ++m) {
                    Image& img = imgs[m];
                    const Grid& g = grids[img.state];
                    // Candidate index range per axis (one cell of margin; the exact test follows).
                    std::array<std::uint64_t, 3> lo{0, 0, 0}, hi{0, 0, 0};
                    bool empty = false;
                    const int da = g.dimension();
                    for (int a = 0; a < da; ++a) {
                        Interval& b = img.box[static_cast<std::size_t>(a)];
                        const Interval r = g.root[static_cast<std::size_t>(a)];
                        // A NaN bound says nothing: the image may reach anywhere along this axis.
                        if (std::isnan(b.lo)) b.lo = -num::inf;
                        if (std::isnan(b.hi)) b.hi = num::inf;
                        if (b.is_empty() || b.hi < r.lo || b.lo > r.hi) {
                            empty = true;
                            break;
                        }
                        const double scale = static_cast<double>(n) / (r.hi - r.lo);
                        const double fl = std::floor((std::max(b.lo, r.lo) - r.lo) * scale) - 1;
                        const double fh = std::floor((std::min(b.hi, r.hi) - r.lo) * scale) + 1;
                        lo[static_cast<std::size_t>(a)] = static_cast<std::uint64_t>(std::max(0.0, fl));
                        hi[static_cast<std::size_t>(a)] = static_cast<std::uint64_t>(
                            std::min(static_cast<double>(n - 1), std::max(0.0, fh)));
                    }
                    if (empty) continue;
                    const std::vector<Key>& tk = kept[img.state];
                    for (std::uint64_t iz = lo[2]; iz <= hi[2]; ++iz)
                        for (std::uint64_t iy = lo[1]; iy <= hi[1]; ++iy) {
                            const Key from = key_of(lo[0], iy, iz, n), to = key_of(hi[0], iy, iz, n);
                            for (auto it = std::lower_bound(tk.begin(), tk.end(), from);
                                 it != tk.end() && *it <= to; ++it) {
                                bool meets = true;
                                for (int a = 0; a < da && meets; ++a) {
                                    const Interval cb = cell_box(img.state, *it, a);
                                    const Interval b = img.box[static_cast<std::size_t>(a)];
                                    meets = cb.lo <= b.hi && b.lo <= cb.hi;
                                }
                                if (meets)
                                    targets.push_back(
                                        static_cast<std::uint32_t>(base[img.state] + (it - tk.begin())));
                            }
                        }
                    if (targets.size() > o.max_arcs)
                        throw LimitError(fmt::format("attractor cover: level {} has more than the limit of "
                                                     "{} arcs",
                                                     level, o.max_arcs),
                                         static_cast<double>(targets.size()), o.max_arcs);
                }
                offsets.push_back(targets.size());
            }
        }
        step.arcs = targets.size();
        std::vector<bool> on_cycle_vertex(total);
        for (std::size_t s = 0; s < ns; ++s)
            std::fill(on_cycle_vertex.begin() + static_cast<std::ptrdiff_t>(base[s]),
                      on_cycle_vertex.begin() + static_cast<std::ptrdiff_t>(base[s + 1]), grids[s].on_cycle);
        const std::vector<bool> rec = kept_vertices(offsets, targets, on_cycle_vertex);

        // Record the initial state's cells of this level, then split the kept cells of every state.
        const std::uint64_t per_axis = n;
        double cell_volume = 1;
        for (int a = 0; a < d; ++a)
            cell_volume *= (grids[initial].root[static_cast<std::size_t>(a)].hi -
                            grids[initial].root[static_cast<std::size_t>(a)].lo) /
                           static_cast<double>(per_axis);
        std::vector<Cell>& lc = level_cells[static_cast<std::size_t>(level)];
        LevelCounts& counts = out.levels[static_cast<std::size_t>(level)];
        for (std::size_t i = 0; i < kept[initial].size(); ++i) {
            const bool keep = rec[base[initial] + i];
            const auto p = position(kept[initial][i], n);
            lc.push_back(
                {static_cast<std::uint8_t>(level),
                 keep ? (level == last ? CellClass::boundary : CellClass::subdivided) : CellClass::outside,
                 p[0], p[1], p[2]});
            ++counts.evaluated;
            if (keep)
                ++counts.undecided, ++step.kept;
            else
                ++counts.outside;
        }
        step.area = static_cast<double>(step.kept) * cell_volume;
        if (level < last) check_next_level(grids, rec, base, level, last, kept_before, o);
        for (std::size_t s = 0; s < ns; ++s) {
            std::vector<Key> next;
            for (std::size_t i = 0; i < kept[s].size(); ++i) {
                if (!rec[base[s] + i]) continue;
                if (level == last) {
                    next.push_back(kept[s][i]);
                    continue;
                }
                const auto p = position(kept[s][i], n);
                const bool flat = grids[s].dimension() == 2;
                for (std::uint64_t c = 0; c < (flat ? 4u : 8u); ++c)
                    next.push_back(key_of(2 * p[0] + (c & 1), 2 * p[1] + ((c >> 1) & 1),
                                          flat ? 0 : 2 * p[2] + ((c >> 2) & 1), 2 * n));
            }
            std::sort(next.begin(), next.end());
            kept[s] = std::move(next);
        }
        step.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        out.steps.push_back(step);
        kept_before = static_cast<double>(std::count(rec.begin(), rec.end(), true));
        if (level < last) n *= 2;
    }

    // Ancestors of the first graph's cells, above it: subdivided.
    {
        std::vector<Key> keys;
        const std::uint64_t n0 = std::uint64_t(1) << o.initial_level;
        for (const Cell& c : level_cells[static_cast<std::size_t>(o.initial_level)])
            if (c.cls != CellClass::outside) keys.push_back(key_of(c.ix, c.iy, c.iz, n0));
        // Outside cells of the first level are kept only under a listed parent.
        for (int level = o.initial_level - 1; level >= 0; --level) {
            const std::uint64_t m = std::uint64_t(1) << level;
            for (Key& k : keys) {
                const auto p = position(k, 2 * m);
                k = key_of(p[0] / 2, p[1] / 2, p[2] / 2, m);
            }
            std::sort(keys.begin(), keys.end());
            keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
            LevelCounts& counts = out.levels[static_cast<std::size_t>(level)];
            for (Key k : keys) {
                const auto p = position(k, m);
                level_cells[static_cast<std::size_t>(level)].push_back(
                    {static_cast<std::uint8_t>(level), CellClass::subdivided, p[0], p[1], p[2]});
                ++counts.evaluated, ++counts.undecided;
            }
        }
        if (o.initial_level > 0) {
            // Drop outside cells of the first graph whose parent is not listed.
            std::vector<Key> parents;
            const std::uint64_t m = n0 / 2;
            for (const Cell& c : level_cells[static_cast<std::size_t>(o.initial_level - 1)])
                parents.push_back(key_of(c.ix, c.iy, c.iz, m));
            std::vector<Cell>& lc = level_cells[static_cast<std::size_t>(o.initial_level)];
            LevelCounts& counts = out.levels[static_cast<std::size_t>(o.initial_level)];
            std::erase_if(lc, [&](const Cell& c) {
                if (c.cls != CellClass::outside) return false;
                const bool orphan = !std::binary_search(parents.begin(), parents.end(),
                                                        key_of(c.ix / 2, c.iy / 2, c.iz / 2, m));
                if (orphan) --counts.outside, --counts.evaluated;
                return orphan;
            });
        }
    }
    for (std::size_t l = 0; l < level_cells.size(); ++l) {
        for (const Cell& c : level_cells[l]) {
            ++out.evaluated;
            switch (c.cls) {
            case CellClass::outside: ++out.outside; break;
            case CellClass::boundary: ++out.boundary; break;
            case CellClass::subdivided: ++out.subdivided; break;
            case CellClass::inside: ++out.inside; break;
            }
            out.cells.push_back(c);
        }
    }
    return out;
}

Grid make_grid(const std::vector<Interval>& root) {
    Grid g;
    g.root = root;
    num::UpwardRounding up;
    for (const Interval& r : root) g.width.push_back(grid::width(r));
    return g;
}

void check_root(const std::vector<Interval>& root, int d) {
    if (static_cast<int>(root.size()) != d || (d != 2 && d != 3))
        throw std::invalid_argument(
            fmt::format("attractor cover: the box has {} axes, the map {}", root.size(), d));
    for (const Interval& r : root)
        if (!std::isfinite(r.lo) || !std::isfinite(r.hi) || !(r.lo < r.hi))
            throw std::invalid_argument("attractor cover: every axis of the box must be finite with lo < hi");
}

} // namespace

AttractorCoverResult map_attractor_cover(const std::vector<ir::Evaluator*>& components,
                                         const std::vector<Interval>& root,
                                         const AttractorCoverOptions& options) {
    const int d = static_cast<int>(components.size());
    check_root(root, d);
    for (ir::Evaluator* e : components)
        if (!e || e->dimension() != d)
            throw std::invalid_argument(
                fmt::format("attractor cover: each component must take {} coordinates", d));
    std::vector<Interval> values;
    const ImageFn images = [&](const std::vector<std::size_t>& states, const std::vector<Interval>& boxes,
                               std::vector<Image>& out, std::vector<std::size_t>& first) {
        const std::size_t count = states.size();
        values.resize(count);
        out.resize(count);
        for (int a = 0; a < d; ++a) {
            components[static_cast<std::size_t>(a)]->eval_boxes(boxes.data(), count, values.data());
            for (std::size_t i = 0; i < count; ++i) out[i].box[static_cast<std::size_t>(a)] = values[i];
        }
        first.resize(count + 1);
        for (std::size_t i = 0; i <= count; ++i) first[i] = i;
        for (Image& img : out) img.state = 0;
    };
    return build({make_grid(root)}, 0, images, options);
}

namespace {

// The automaton whose initial state is euclidean: a barycentric initial state gets a state of the
// output space in front of it, with the projection as its one arc (A_out = P(A_initial)).
ir::Automaton with_euclidean_initial(const ir::Automaton& a) {
    ir::Automaton out = a;
    if (a.states[a.initial].space.kind != ir::Space::Kind::barycentric) return out;
    if (!a.projection)
        throw std::invalid_argument(fmt::format(
            "attractor cover of automaton '{}': its barycentric initial state has no projection", a.name));
    const std::size_t front = out.states.size();
    out.states.push_back({"projection", ir::Space::euclidean(a.output_dimension()), {}});
    out.arcs.push_back({front, a.initial, *a.projection, std::nullopt, "projection"});
    out.initial = front;
    out.projection.reset();
    return out;
}

// The affine coordinates of a state's points: x for R^d, the first n - 1 weights for bary(n) (the last
// is 1 minus their sum), so that every state's grid has as many axes as its space has dimensions.
// The operator T of an arc a -> b in these coordinates is an affine map, rows(a) x (cols(b) + 1) with
// the translation last: T composed with the embedding of b's coordinates, its redundant rows dropped
// (T maps the hyperplane of b into that of a).
num::Matrix<Interval> chart_operator(const num::Matrix<Interval>& t, ir::Space from, ir::Space to) {
    const auto rows = static_cast<std::size_t>(from.dimension), cols = static_cast<std::size_t>(to.dimension);
    const std::size_t last = static_cast<std::size_t>(to.coordinates()) - 1;
    const bool bary = to.kind == ir::Space::Kind::barycentric;
    num::Matrix<Interval> m(rows, cols + 1);
    for (std::size_t r = 0; r < rows; ++r) {
        // bary(n): the weights (u, 1 - sum u) give T[:, j] - T[:, n-1] per coordinate and T[:, n-1].
        for (std::size_t c = 0; c < cols; ++c) m(r, c) = bary ? num::sub(t(r, c), t(r, last)) : t(r, c);
        m(r, cols) = t(r, last);
    }
    return m;
}

} // namespace

AttractorCoverResult automaton_attractor_cover(const ir::Automaton& input, const std::vector<Interval>& root,
                                               const AttractorCoverOptions& options) {
    if (input.states.empty() || input.initial >= input.states.size())
        throw std::invalid_argument("attractor cover: automaton without states");
    const ir::Automaton a = with_euclidean_initial(input);
    for (const ir::State& s : a.states)
        if (s.space.dimension != 2 && s.space.dimension != 3)
            throw std::invalid_argument(
                fmt::format("attractor cover of automaton '{}': state '{}' is {}; covers need spaces of "
                            "dimension 2 or 3 (R2, R3, bary(3), bary(4))",
                            input.name, s.name, ir::space_name(s.space)));
    const int d = a.states[a.initial].space.dimension;
    // Boxes around the proven bounding balls for the states (also checks the operators and that the
    // system contracts); the initial state's box is the caller's when given. A ball of radius r in a
    // state's norm (the euclidean norm of its homogeneous coordinates) bounds each affine coordinate
    // within r of the centre's.
    const std::vector<StateBall> balls = bounding_balls(a);
    if (balls[a.initial].radius < 0)
        throw std::invalid_argument(
            fmt::format("attractor cover: the attractor of '{}' is empty", input.name));
    std::vector<Grid> grids(a.states.size());
    {
        num::UpwardRounding up;
        for (std::size_t s = 0; s < a.states.size(); ++s) {
            std::vector<Interval> box;
            const double r = std::max(balls[s].radius, 0.0);
            for (int i = 0; i < a.states[s].space.dimension; ++i) {
                const double c = balls[s].radius < 0 ? 0.0 : balls[s].centre[static_cast<std::size_t>(i)];
                box.push_back({num::sub(Interval(c), Interval(r)).lo, num::add(Interval(c), Interval(r)).hi});
                if (!(box.back().lo < box.back().hi)) box.back() = {c - 1, c + 1}; // a point attractor
            }
            grids[s] = make_grid(s == a.initial && !root.empty() ? root : box);
        }
    }
    for (const Interval& r : grids[a.initial].root)
        if (root.empty() && !(std::isfinite(r.lo) && std::isfinite(r.hi)))
            throw RangeError(fmt::format("the attractor of '{}' leaves the range of doubles (its proven "
                                         "bounding box is not finite): scale its coordinates down",
                                         input.name));
    check_root(grids[a.initial].root, d);
    // Arcs in the direction of the points: x in A_b gives T x in A_a for an arc a -> b; states whose
    // attractor is empty get no cells' images (their vertices stay transient).
    std::vector<std::vector<std::size_t>> into(a.states.size()); // arcs a -> b, by b
    std::vector<num::Matrix<Interval>> charts(a.arcs.size());
    for (std::size_t i = 0; i < a.arcs.size(); ++i) {
        const ir::Arc& arc = a.arcs[i];
        if (balls[arc.from].radius < 0 || balls[arc.to].radius < 0) continue;
        into[arc.to].push_back(i);
        num::UpwardRounding up;
        charts[i] = chart_operator(arc.op.enclosure, a.states[arc.from].space, a.states[arc.to].space);
    }
    // The states on a cycle of the graph (of arcs between states with attractors).
    {
        std::vector<std::uint64_t> offsets{0};
        std::vector<std::uint32_t> targets;
        for (std::size_t s = 0; s < a.states.size(); ++s) {
            for (std::size_t i : into[s]) targets.push_back(static_cast<std::uint32_t>(a.arcs[i].from));
            offsets.push_back(targets.size());
        }
        const std::vector<bool> cyclic = recurrent_vertices(offsets, targets);
        for (std::size_t s = 0; s < a.states.size(); ++s) grids[s].on_cycle = cyclic[s];
    }
    const ImageFn images = [&](const std::vector<std::size_t>& states, const std::vector<Interval>& boxes,
                               std::vector<Image>& out, std::vector<std::size_t>& first) {
        num::UpwardRounding up;
        first.assign(1, 0);
        std::size_t at = 0; // the cell's first interval in `boxes`
        for (std::size_t c = 0; c < states.size(); ++c) {
            const auto dim = static_cast<std::size_t>(a.states[states[c]].space.dimension);
            for (std::size_t i : into[states[c]]) {
                const num::Matrix<Interval>& m = charts[i];
                Image img;
                img.state = a.arcs[i].from;
                for (std::size_t r = 0; r < m.rows(); ++r) {
                    Interval v = m(r, dim);
                    for (std::size_t k = 0; k < dim; ++k) v = num::add(v, num::mul(m(r, k), boxes[at + k]));
                    img.box[r] = v;
                }
                out.push_back(img);
            }
            at += dim;
            first.push_back(out.size());
        }
    };
    // Vertices of states the initial one does not reach have no images, so they are transient after
    // the first graph and cost nothing later.
    return build(grids, a.initial, images, options);
}

} // namespace frac::rt
