#include "runtime/automata/tree.hpp"

#include "ir/automaton_check.hpp"
#include "runtime/automata/points.hpp"
#include "runtime/limits.hpp"
#include "support/atomic_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace frac::rt {

namespace {

// out = a * b without allocating when out already has the shape.
void multiply_into(const num::Matrix<double>& a, const num::Matrix<double>& b, num::Matrix<double>& out) {
    if (out.rows() != a.rows() || out.cols() != b.cols()) out = num::Matrix<double>(a.rows(), b.cols());
    for (std::size_t r = 0; r < a.rows(); ++r)
        for (std::size_t c = 0; c < b.cols(); ++c) {
            double s = 0;
            for (std::size_t k = 0; k < a.cols(); ++k) s += a(r, k) * b(k, c);
            out(r, c) = s;
        }
}

std::string row_text(const num::Matrix<double>& m) {
    std::string out = "[";
    for (std::size_t r = 0; r < m.rows(); ++r) {
        out += r ? "; " : "";
        for (std::size_t c = 0; c < m.cols(); ++c) out += fmt::format("{}{:.6g}", c ? " " : "", m(r, c));
    }
    return out + "]";
}

// The plane view of a drawing: the output-space matrix applied to a leaf's composite, and the
// bounding box of what was drawn.
struct Plane {
    num::Matrix<double> out; // output matrix (projection or identity)
    int dims = 2;            // output dimension
    // Homogeneous column of the initial space -> (x, y).
    std::array<double, 2> at(const std::vector<double>& column) const {
        std::array<double, 2> xy{0, 0};
        for (int k = 0; k < std::min(dims, 2); ++k) {
            double s = 0;
            for (std::size_t c = 0; c < column.size(); ++c)
                s += out(static_cast<std::size_t>(k), c) * column[c];
            xy[static_cast<std::size_t>(k)] = s;
        }
        return xy;
    }
};

// Whether a state's primitive is drawn as it is (else a state with arcs shows its attractor point).
bool drawable(const ir::Primitive& p) {
    return (p.kind == ir::Primitive::Kind::points || p.kind == ir::Primitive::Kind::polyline ||
            p.kind == ir::Primitive::Kind::polygon) &&
           p.points.cols() > 0;
}

// Calls shape(state, kind, points in the plane) for every leaf.
template <typename Shape>
void leaf_shapes(const ir::Automaton& a, int depth, Shape&& shape) {
    const Plane plane{output_matrix(a), a.output_dimension()};
    // Per state: the homogeneous columns of what it draws.
    std::vector<std::vector<std::vector<double>>> columns(a.states.size());
    std::vector<ir::Primitive::Kind> kinds(a.states.size());
    for (std::size_t s = 0; s < a.states.size(); ++s) {
        const ir::Primitive& p = a.states[s].primitive;
        kinds[s] = drawable(p) ? p.kind : ir::Primitive::Kind::points;
        if (drawable(p)) {
            if (p.points.rows() != static_cast<std::size_t>(a.states[s].space.coordinates()))
                throw std::invalid_argument(
                    fmt::format("the primitive of state {} has points of the wrong size", a.states[s].name));
            for (std::size_t c = 0; c < p.points.cols(); ++c) {
                std::vector<double> col(p.points.rows());
                for (std::size_t r = 0; r < p.points.rows(); ++r) col[r] = p.points(r, c);
                columns[s].push_back(std::move(col));
            }
        } else if (!a.arcs_from(s).empty()) {
            columns[s].push_back(attractor_point(a, s));
        } // a state without arcs and without a primitive draws nothing
    }
    std::vector<std::array<double, 2>> pts;
    std::vector<double> image;
    walk_tree(a, {depth, false}, [&](const TreeNode& node) {
        if (!node.leaf) return;
        pts.clear();
        for (const auto& col : columns[node.state]) {
            image.assign(node.op->rows(), 0.0);
            for (std::size_t r = 0; r < node.op->rows(); ++r)
                for (std::size_t c = 0; c < col.size(); ++c) image[r] += (*node.op)(r, c) * col[c];
            pts.push_back(plane.at(image));
        }
        shape(node.state, kinds[node.state], pts);
    });
}

struct View {
    double x0 = 0, y0 = 0, scale = 1;
    int w = 1, h = 1;
    std::array<double, 2> pixel(std::array<double, 2> p) const {
        return {(p[0] - x0) * scale, static_cast<double>(h) - (p[1] - y0) * scale};
    }
};

View view_of(const ir::Automaton& a, int depth, int pixels) {
    double x0 = num::inf, x1 = -num::inf, y0 = num::inf, y1 = -num::inf;
    bool finite = true;
    leaf_shapes(a, depth,
                [&](std::size_t, ir::Primitive::Kind, const std::vector<std::array<double, 2>>& pts) {
                    for (const auto& p : pts) {
                        finite = finite && std::isfinite(p[0]) && std::isfinite(p[1]);
                        x0 = std::min(x0, p[0]);
                        x1 = std::max(x1, p[0]);
                        y0 = std::min(y0, p[1]);
                        y1 = std::max(y1, p[1]);
                    }
                });
    if (!finite || (x0 <= x1 && (!std::isfinite(x1 - x0) || !std::isfinite(y1 - y0))))
        throw RangeError(fmt::format("the evaluation tree of '{}' leaves the range of doubles (what its "
                                     "leaves draw is not finite): scale its coordinates down",
                                     a.name));
    if (!(x0 <= x1))
        throw std::invalid_argument(fmt::format("the evaluation tree of '{}' to depth {} draws nothing: its "
                                                "leaves have no primitive",
                                                a.name, depth));
    // A margin of 2% and at least a tiny extent, so flat or single-point drawings still have a view.
    const double span = std::max({x1 - x0, y1 - y0, 1e-9});
    const double margin = 0.02 * span;
    x0 -= margin, x1 += margin, y0 -= margin, y1 += margin;
    View v;
    const double wx = std::max(x1 - x0, 1e-9 * span), wy = std::max(y1 - y0, 1e-9 * span);
    v.scale = pixels / std::max(wx, wy);
    v.x0 = x0;
    v.y0 = y0;
    v.w = std::max(1, static_cast<int>(std::lround(wx * v.scale)));
    v.h = std::max(1, static_cast<int>(std::lround(wy * v.scale)));
    return v;
}

struct Canvas {
    Image img;
    void set(long x, long y, const std::array<std::uint8_t, 3>& c) {
        if (x < 0 || y < 0 || x >= img.width || y >= img.height) return;
        std::uint8_t* px = &img.rgb[(static_cast<std::size_t>(y) * static_cast<std::size_t>(img.width) +
                                     static_cast<std::size_t>(x)) *
                                    3];
        px[0] = c[0], px[1] = c[1], px[2] = c[2];
    }
    void line(std::array<double, 2> p, std::array<double, 2> q, const std::array<std::uint8_t, 3>& c) {
        const double steps = std::ceil(std::max(std::abs(q[0] - p[0]), std::abs(q[1] - p[1])));
        const long n = static_cast<long>(std::min(steps, 1e5));
        for (long i = 0; i <= n; ++i) {
            const double t = n ? static_cast<double>(i) / static_cast<double>(n) : 0.0;
            set(static_cast<long>(std::floor(p[0] + t * (q[0] - p[0]))),
                static_cast<long>(std::floor(p[1] + t * (q[1] - p[1]))), c);
        }
    }
    // Even-odd scanline fill at pixel centres.
    void fill(const std::vector<std::array<double, 2>>& poly, const std::array<std::uint8_t, 3>& c) {
        double top = num::inf, bottom = -num::inf;
        for (const auto& p : poly) top = std::min(top, p[1]), bottom = std::max(bottom, p[1]);
        std::vector<double> xs;
        const long y_from = std::max(0L, static_cast<long>(std::floor(top)));
        const long y_to = std::min(static_cast<long>(img.height) - 1, static_cast<long>(std::ceil(bottom)));
        for (long y = y_from; y <= y_to; ++y) {
            const double yc = static_cast<double>(y) + 0.5;
            xs.clear();
            for (std::size_t i = 0; i < poly.size(); ++i) {
                const auto& p = poly[i];
                const auto& q = poly[(i + 1) % poly.size()];
                if ((p[1] <= yc) != (q[1] <= yc))
                    xs.push_back(p[0] + (yc - p[1]) / (q[1] - p[1]) * (q[0] - p[0]));
            }
            std::sort(xs.begin(), xs.end());
            for (std::size_t i = 0; i + 1 < xs.size(); i += 2) {
                const long x_from = std::max(0L, static_cast<long>(std::ceil(xs[i] - 0.5)));
                const long x_to = std::min(static_cast<long>(img.width) - 1,
                                           static_cast<long>(std::floor(xs[i + 1] - 0.5)));
                for (long x = x_from; x <= x_to; ++x) set(x, y, c);
            }
        }
    }
};

} // namespace

std::array<std::uint8_t, 3> state_colour(std::size_t state) {
    static constexpr std::array<std::array<std::uint8_t, 3>, 8> palette{{{31, 119, 180},
                                                                         {214, 39, 40},
                                                                         {44, 160, 44},
                                                                         {255, 127, 14},
                                                                         {148, 103, 189},
                                                                         {140, 86, 75},
                                                                         {227, 119, 194},
                                                                         {23, 190, 207}}};
    return palette[state % palette.size()];
}

TreeSize tree_size(const ir::Automaton& a, int depth) {
    if (depth < 0 || depth > 64)
        throw std::invalid_argument(fmt::format("tree depth {} is outside [0, 64]", depth));
    require_well_formed(a);
    const std::size_t n = a.states.size();
    // Per state: whether it has arcs, and the SVG bytes of one leaf in it (write_tree_svg: a circle of
    // about 60 bytes per point; a polyline or polygon of about 70 bytes and 16 per point).
    std::vector<bool> inner(n, false);
    for (const ir::Arc& arc : a.arcs) inner[arc.from] = true;
    std::vector<double> bytes(n, 0.0);
    for (std::size_t s = 0; s < n; ++s) {
        const ir::Primitive& p = a.states[s].primitive;
        const double points = static_cast<double>(p.points.cols());
        if (drawable(p))
            bytes[s] = p.kind == ir::Primitive::Kind::points || points == 1 ? 60 * points : 70 + 16 * points;
        else if (inner[s])
            bytes[s] = 60; // its attractor point
    }
    TreeSize size;
    std::vector<double> count(n, 0.0), next(n, 0.0); // nodes of the level in each state
    count[a.initial] = 1;
    for (int k = 0;; ++k) {
        for (std::size_t s = 0; s < n; ++s) {
            size.nodes += count[s];
            if (k < depth && inner[s]) continue;
            size.leaves += count[s];
            size.svg_bytes += count[s] * bytes[s];
        }
        if (k == depth) break;
        std::fill(next.begin(), next.end(), 0.0);
        for (const ir::Arc& arc : a.arcs) next[arc.to] += count[arc.from];
        count.swap(next);
    }
    return size;
}

TreeStats walk_tree(const ir::Automaton& a, const TreeOptions& options,
                    const std::function<void(const TreeNode&)>& visit) {
    if (options.depth < 0 || options.depth > 64)
        throw std::invalid_argument(fmt::format("tree depth {} is outside [0, 64]", options.depth));
    const std::size_t n = a.states.size();
    require_well_formed(a);
    std::vector<std::vector<std::size_t>> out(n);
    for (std::size_t i = 0; i < a.arcs.size(); ++i) out[a.arcs[i].from].push_back(i);
    const std::size_t levels = static_cast<std::size_t>(options.depth) + 1;
    std::vector<num::Matrix<double>> op(levels);
    std::vector<num::Matrix<num::Interval>> enc(options.intervals ? levels : 0);
    std::vector<std::size_t> address;
    address.reserve(levels);
    std::vector<std::size_t> next(levels, 0); // per level: the position among the state's arcs
    std::vector<std::size_t> state(levels, a.initial);
    const std::size_t root = static_cast<std::size_t>(a.states[a.initial].space.coordinates());
    op[0] = num::Matrix<double>::identity(root);
    if (options.intervals) enc[0] = num::Matrix<num::Interval>::identity(root);

    TreeStats stats;
    TreeNode node;
    node.address = &address;
    auto emit = [&](std::size_t k) {
        node.depth = static_cast<int>(k);
        node.state = state[k];
        node.op = &op[k];
        node.enclosure = options.intervals ? &enc[k] : nullptr;
        node.leaf = k == levels - 1 || out[state[k]].empty();
        ++stats.nodes;
        stats.leaves += node.leaf ? 1 : 0;
        visit(node);
    };
    emit(0);
    std::size_t k = 0; // the current level
    while (true) {
        const auto& arcs = out[state[k]];
        if (k + 1 < levels && next[k] < arcs.size()) {
            const std::size_t i = arcs[next[k]++];
            multiply_into(op[k], a.arcs[i].op.nearest, op[k + 1]);
            if (options.intervals) enc[k + 1] = enc[k] * a.arcs[i].op.enclosure;
            state[k + 1] = a.arcs[i].to;
            next[k + 1] = 0;
            address.push_back(i);
            ++k;
            emit(k);
            continue;
        }
        if (k == 0) break;
        address.pop_back();
        --k;
    }
    for (std::size_t l = 0; l < levels; ++l) {
        stats.stack_bytes += op[l].rows() * op[l].cols() * sizeof(double);
        if (options.intervals) stats.stack_bytes += enc[l].rows() * enc[l].cols() * sizeof(num::Interval);
    }
    stats.stack_bytes += levels * (3 * sizeof(std::size_t) + sizeof(num::Matrix<double>));
    return stats;
}

void write_tree_text(const ir::Automaton& a, int depth, std::ostream& os, bool matrices) {
    os << fmt::format("tree of {} to depth {}\n", a.name, depth);
    walk_tree(a, {depth, false}, [&](const TreeNode& node) {
        std::string line(static_cast<std::size_t>(2 * node.depth), ' ');
        if (node.depth == 0)
            line += a.states[node.state].name;
        else
            line += fmt::format("{} -> {}", ir::arc_name(a, node.address->back()), a.states[node.state].name);
        if (node.leaf) line += " (leaf)";
        if (matrices) line += "  " + row_text(*node.op);
        os << line << '\n';
    });
}

std::string tree_text(const ir::Automaton& a, int depth, bool matrices) {
    std::ostringstream os;
    write_tree_text(a, depth, os, matrices);
    return os.str();
}

Image draw_tree(const ir::Automaton& a, int depth, int pixels) {
    if (pixels < 16 || pixels > 16384)
        throw std::invalid_argument(fmt::format("pixels {} is outside [16, 16384]", pixels));
    const View v = view_of(a, depth, pixels);
    Canvas canvas;
    canvas.img.width = v.w;
    canvas.img.height = v.h;
    canvas.img.rgb.assign(static_cast<std::size_t>(v.w) * static_cast<std::size_t>(v.h) * 3, 255);
    std::vector<std::array<double, 2>> px;
    leaf_shapes(a, depth,
                [&](std::size_t s, ir::Primitive::Kind kind, const std::vector<std::array<double, 2>>& pts) {
                    const auto colour = state_colour(s);
                    px.clear();
                    for (const auto& p : pts) px.push_back(v.pixel(p));
                    if (kind == ir::Primitive::Kind::polygon && px.size() >= 3) canvas.fill(px, colour);
                    if (kind == ir::Primitive::Kind::points || px.size() == 1) {
                        for (const auto& p : px)
                            canvas.set(static_cast<long>(std::floor(p[0])),
                                       static_cast<long>(std::floor(p[1])), colour);
                        return;
                    }
                    for (std::size_t i = 0; i + 1 < px.size(); ++i) canvas.line(px[i], px[i + 1], colour);
                    if (kind == ir::Primitive::Kind::polygon) canvas.line(px.back(), px.front(), colour);
                });
    return std::move(canvas.img);
}

void write_tree_png(const ir::Automaton& a, int depth, const std::string& path, int pixels) {
    write_png(draw_tree(a, depth, pixels), path);
}

void write_tree_svg(const ir::Automaton& a, int depth, const std::string& path) {
    const View v = view_of(a, depth, 1024);
    support::AtomicFile out(path, "SVG"); // a failed or interrupted write leaves the old file
    std::string os;
    const auto spill = [&] { // the text goes out by the megabyte, never whole in memory
        if (os.size() < (1u << 20)) return;
        out.write(os);
        os.clear();
    };
    os += fmt::format(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" viewBox=\"0 0 {} {}\">\n", v.w,
        v.h, v.w, v.h);
    os += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
    leaf_shapes(
        a, depth,
        [&](std::size_t s, ir::Primitive::Kind kind, const std::vector<std::array<double, 2>>& pts) {
            const auto c = state_colour(s);
            const std::string colour = fmt::format("#{:02x}{:02x}{:02x}", c[0], c[1], c[2]);
            if (kind == ir::Primitive::Kind::points || pts.size() == 1) {
                for (const auto& p : pts) {
                    const auto q = v.pixel(p);
                    os += fmt::format("<circle cx=\"{:.3f}\" cy=\"{:.3f}\" r=\"0.8\" fill=\"{}\"/>\n", q[0],
                                      q[1], colour);
                }
                spill();
                return;
            }
            std::string list;
            for (const auto& p : pts) {
                const auto q = v.pixel(p);
                list += fmt::format("{}{:.3f},{:.3f}", list.empty() ? "" : " ", q[0], q[1]);
            }
            if (kind == ir::Primitive::Kind::polygon)
                os += fmt::format("<polygon points=\"{}\" fill=\"{}\" stroke=\"{}\" stroke-width=\"0.3\"/>\n",
                                  list, colour, colour);
            else
                os +=
                    fmt::format("<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"1\"/>\n",
                                list, colour);
            spill();
        });
    os += "</svg>\n";
    out.write(os);
    out.commit();
}

} // namespace frac::rt
