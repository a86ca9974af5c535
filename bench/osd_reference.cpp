#include "bench/osd_reference.hpp"

#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

namespace frac::osd {

namespace {

using namespace OpenSubdiv;
using Clock = std::chrono::steady_clock;

double since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

// A primvar: the position and the grid coordinates (a, b), whose limit on the central face is
// (1 + s, 1 + t) (B-splines reproduce linear functions): that places each limit vertex on the grid.
struct Vertex {
    double v[5];
    void Clear(void* = nullptr) {
        for (double& x : v) x = 0;
    }
    void AddWithWeight(const Vertex& src, double weight) {
        for (int k = 0; k < 5; ++k) v[k] += weight * src.v[k];
    }
};

} // namespace

RefinedPatch refine_bicubic_patch(const std::array<std::array<double, 3>, 16>& controls, int level) {
    if (level < 1 || level > 10) throw std::invalid_argument("refine_bicubic_patch: level in [1, 10]");
    RefinedPatch out;
    out.level = level;
    int vertices_per_face[9];
    int face_vertices[36];
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
            const int f = a * 3 + b;
            vertices_per_face[f] = 4;
            const int corner[4] = {a * 4 + b, (a + 1) * 4 + b, (a + 1) * 4 + b + 1, a * 4 + b + 1};
            for (int k = 0; k < 4; ++k) face_vertices[f * 4 + k] = corner[k];
        }
    Far::TopologyDescriptor desc;
    desc.numVertices = 16;
    desc.numFaces = 9;
    desc.numVertsPerFace = vertices_per_face;
    desc.vertIndicesPerFace = face_vertices;
    Sdc::Options options;
    options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);

    auto t0 = Clock::now();
    std::unique_ptr<Far::TopologyRefiner> refiner(
        Far::TopologyRefinerFactory<Far::TopologyDescriptor>::Create(
            desc,
            Far::TopologyRefinerFactory<Far::TopologyDescriptor>::Options(Sdc::SCHEME_CATMARK, options)));
    Far::TopologyRefiner::UniformOptions uniform(level);
    uniform.fullTopologyInLastLevel = true; // Limit() refuses a last level without it
    refiner->RefineUniform(uniform);
    out.topology_seconds = since(t0);

    std::vector<Vertex> buffer(static_cast<std::size_t>(refiner->GetNumVerticesTotal()));
    for (int c = 0; c < 16; ++c) {
        Vertex& v = buffer[static_cast<std::size_t>(c)];
        for (int k = 0; k < 3; ++k)
            v.v[k] = controls[static_cast<std::size_t>(c)][static_cast<std::size_t>(k)];
        v.v[3] = c / 4;
        v.v[4] = c % 4;
    }
    t0 = Clock::now();
    const Far::PrimvarRefinerReal<double> primvar(*refiner);
    Vertex* src = buffer.data();
    for (int l = 1; l <= level; ++l) {
        Vertex* dst = src + refiner->GetLevel(l - 1).GetNumVertices();
        primvar.Interpolate(l, src, dst);
        src = dst;
    }
    out.interpolate_seconds = since(t0);

    const auto last = static_cast<std::size_t>(refiner->GetLevel(level).GetNumVertices());
    out.refined_vertices = last;
    std::vector<Vertex> limit(last);
    t0 = Clock::now();
    Vertex* dst = limit.data();
    primvar.Limit(src, dst);
    out.limit_seconds = since(t0);

    const std::size_t n = std::size_t{1} << level, side = n + 1;
    out.grid.assign(side * side, {NAN, NAN, NAN});
    std::size_t placed = 0;
    for (const Vertex& v : limit) {
        const double s = (v.v[3] - 1) * static_cast<double>(n), t = (v.v[4] - 1) * static_cast<double>(n);
        const double i = std::round(s), j = std::round(t);
        if (i < 0 || j < 0 || i > static_cast<double>(n) || j > static_cast<double>(n)) continue;
        if (std::abs(s - i) > 1e-6 || std::abs(t - j) > 1e-6)
            throw std::runtime_error("refine_bicubic_patch: a limit vertex is off the parameter grid");
        auto& slot = out.grid[static_cast<std::size_t>(i) * side + static_cast<std::size_t>(j)];
        if (!std::isnan(slot[0]))
            throw std::runtime_error("refine_bicubic_patch: two vertices at one grid point");
        slot = {v.v[0], v.v[1], v.v[2]};
        ++placed;
    }
    if (placed != side * side)
        throw std::runtime_error("refine_bicubic_patch: the central face is incomplete");
    return out;
}

std::array<std::array<double, 3>, 16> patch_controls(const ir::Automaton& a) {
    if (!a.projection || a.projection->rows() != 4 || a.projection->cols() != 16)
        throw std::invalid_argument("patch_controls: the automaton has no projection bary(16) -> R3");
    std::array<std::array<double, 3>, 16> controls{};
    for (std::size_t c = 0; c < 16; ++c)
        for (std::size_t r = 0; r < 3; ++r) controls[c][r] = a.projection->nearest(r, c);
    return controls;
}

double max_difference(const RefinedPatch& reference, const std::vector<std::array<double, 3>>& vertices) {
    if (reference.grid.size() != vertices.size()) return INFINITY;
    double worst = 0;
    for (std::size_t v = 0; v < vertices.size(); ++v)
        for (std::size_t r = 0; r < 3; ++r)
            worst = std::max(worst, std::abs(reference.grid[v][r] - vertices[v][r]));
    return worst;
}

} // namespace frac::osd
