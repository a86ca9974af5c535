// stdlib/lattice.frac and stdlib/noise.frac through the interpreter: lattice distances against
// enumeration on random reduced bases, and enclosures over random boxes that must meet the enclosure
// of every sampled point (which contains the exact value), for noise, lattice distances and eq. (12).
#include "backend/interp/interpreter.hpp"
#include "driver/pipeline.hpp"
#include "ir/tape.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <fmt/format.h>
#include <random>

using namespace frac;

namespace {

struct Model {
    std::unique_ptr<front::Compilation> c;
    std::unique_ptr<ir::Evaluator> eval(const std::string& name) const {
        const front::ShapeInfo* info = c->module.find_shape(name);
        REQUIRE(info);
        return interp::make_interpreter(ir::build_tape(c->module.graph, info->root, info->dimension));
    }
    int dimension(const std::string& name) const { return c->module.find_shape(name)->dimension; }
};

Model compile(const std::string& text) {
    Model m;
    m.c = driver::compile_source("t.frac", text);
    if (!m.c->ok()) FAIL(m.c->diags.render(m.c->sources));
    return m;
}

ir::Interval at_point(ir::Evaluator& e, const double* p, int dim) {
    ir::Interval b[3];
    for (int k = 0; k < dim; ++k) b[k] = ir::Interval(p[k]);
    return e.eval_box(b);
}

// The nearest of the lattice points whose coordinates are within 6 of those of p.
double brute_lattice_distance(double x, double y, double b1x, double b1y, double b2x, double b2y) {
    const double det = b1x * b2y - b1y * b2x;
    const double u = std::floor((b2y * x - b2x * y) / det), v = std::floor((b1x * y - b1y * x) / det);
    double best = INFINITY;
    for (double i = u - 6; i <= u + 6; ++i)
        for (double j = v - 6; j <= v + 6; ++j)
            best = std::min(best, std::hypot(x - i * b1x - j * b2x, y - i * b1y - j * b2y));
    return best;
}

} // namespace

TEST_CASE("lattice_distance_reduced is the distance to the nearest lattice point", "[stdlib][lattice]") {
    std::mt19937_64 rng(4);
    std::uniform_real_distribution<double> u(-1.5, 1.5), pos(-4, 4);
    int bases = 0;
    while (bases < 40) {
        double b1x = u(rng), b1y = u(rng), b2x = u(rng), b2y = u(rng);
        if (std::fabs(b1x * b2y - b1y * b2x) < 0.1) continue;
        // Lagrange reduction, as the precondition asks.
        for (;;) {
            if (b1x * b1x + b1y * b1y > b2x * b2x + b2y * b2y) std::swap(b1x, b2x), std::swap(b1y, b2y);
            const double m = std::nearbyint((b1x * b2x + b1y * b2y) / (b1x * b1x + b1y * b1y));
            if (m == 0) break;
            b2x -= m * b1x;
            b2y -= m * b1y;
        }
        ++bases;
        const Model m = compile(fmt::format("import \"lattice\"; shape d = lattice_distance_reduced((x, y), "
                                            "({:.17g}, {:.17g}), ({:.17g}, {:.17g}), (0, 0));",
                                            b1x, b1y, b2x, b2y));
        auto e = m.eval("d");
        for (int k = 0; k < 25; ++k) {
            const double p[2] = {pos(rng), pos(rng)};
            const ir::Interval v = at_point(*e, p, 2);
            const double want = brute_lattice_distance(p[0], p[1], b1x, b1y, b2x, b2y);
            INFO("basis (" << b1x << ", " << b1y << "), (" << b2x << ", " << b2y << "), point " << p[0]
                           << ", " << p[1]);
            CHECK(v.lo <= want + 1e-12);
            CHECK(v.hi >= want - 1e-12);
            CHECK(v.hi - v.lo < 1e-12);
        }
    }
}

TEST_CASE("lattice_distance is exact on centred lattices", "[stdlib][lattice]") {
    // Bases with 2 (b1.b2) / |b1|^2 an integer: odd (two cosets needed) and even, axis-aligned or not.
    struct Basis {
        double b1x, b1y, b2x, b2y;
    };
    const Basis bases[] = {
        {1, 0, 0.5, std::sqrt(3) / 2}, {2, 0, 1, 3}, {1, 0, 1, 1.2}, {0.6, 0.8, -0.5, 1.0}};
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> pos(-5, 5);
    for (const Basis& b : bases) {
        const Model m =
            compile(fmt::format("import \"lattice\"; shape d = lattice_distance((x, y), ({:.17g}, {:.17g}), "
                                "({:.17g}, {:.17g}), (0, 0));",
                                b.b1x, b.b1y, b.b2x, b.b2y));
        auto e = m.eval("d");
        for (int k = 0; k < 200; ++k) {
            const double p[2] = {pos(rng), pos(rng)};
            const double want = brute_lattice_distance(p[0], p[1], b.b1x, b.b1y, b.b2x, b.b2y);
            INFO("basis (" << b.b1x << ", " << b.b1y << "), (" << b.b2x << ", " << b.b2y << "), point "
                           << p[0] << ", " << p[1]);
            CHECK(std::fabs(num::midpoint(at_point(*e, p, 2)) - want) < 1e-12);
        }
    }
}

TEST_CASE("noise, lattice and eq. (12) enclosures meet every sampled point's enclosure",
          "[stdlib][soundness]") {
    const Model m = compile(R"(import "noise"; import "lattice";
        shape n1 = noise1(x) + y;
        shape n2 = noise2((x, y));
        shape n3(x, y, z) = noise3((x, y, z));
        shape v3(x, y, z) = value_noise3((x, y, z));
        shape g1 = fractal_sum(x, gradient_noise1, 2, 1.5) + y;
        shape g2 = gradient_noise2((x, y));
        shape g3(x, y, z) = gradient_noise3((x, y, z));
        shape tri = lattice_distance((x, y), (1, 0), (1/2, sqrt(3) / 2), (0.1, 0.2));
        shape skew = lattice_distance_reduced((x, y), (1, 0.2), (0.2, 1.3), (0.3, 0));
        shape koch = koch_general((x, y));
        shape dust = cantor_dust_general((x, y));)");
    std::mt19937_64 rng(6);
    std::uniform_real_distribution<double> unit(0, 1);
    for (const char* name : {"n1", "n2", "n3", "v3", "g1", "g2", "g3", "tri", "skew", "koch", "dust"}) {
        auto e = m.eval(name);
        const int dim = m.dimension(name);
        int checked = 0;
        for (int k = 0; k < 400; ++k) {
            // Centres on the lattice, on half-integers and anywhere; widths from 1e-9 to 4.
            ir::Interval box[3];
            for (int a = 0; a < dim; ++a) {
                const double anywhere = -3 + 6 * unit(rng);
                const int kind = static_cast<int>(unit(rng) * 3);
                const double c = kind == 0   ? std::floor(anywhere)
                                 : kind == 1 ? std::floor(anywhere) + 0.5
                                             : anywhere;
                const double w = std::pow(10.0, -9 + 9.6 * unit(rng));
                box[a] = ir::Interval(c - w * unit(rng), c + w * unit(rng));
            }
            const ir::Interval enclosure = e->eval_box(box);
            for (int s = 0; s < 6; ++s) {
                double p[3];
                for (int a = 0; a < dim; ++a) {
                    const double t = s < 2 ? s : unit(rng); // two corners, then random points
                    p[a] = box[a].lo + t * (box[a].hi - box[a].lo);
                    p[a] = std::clamp(p[a], box[a].lo, box[a].hi);
                }
                const ir::Interval v = at_point(*e, p, dim);
                INFO(name << " at (" << p[0] << ", " << p[1] << (dim == 3 ? ", " + std::to_string(p[2]) : "")
                          << "): point " << v.lo << ".." << v.hi << ", box " << enclosure.lo << ".."
                          << enclosure.hi);
                REQUIRE(v.lo <= enclosure.hi);
                REQUIRE(v.hi >= enclosure.lo);
                ++checked;
            }
        }
        CHECK(checked == 2400);
    }
}

TEST_CASE("noise enclosures shrink with the box, also across the lattice", "[stdlib][noise]") {
    const Model m = compile("import \"noise\"; shape v = value_noise2((x, y)); shape n = noise2((x, y));");
    auto v = m.eval("v");
    auto n = m.eval("n");
    for (double c : {2.0, 2.5, -3.0, 0.3}) {
        for (double w : {1e-3, 1e-5, 1e-7}) {
            const ir::Interval box[2] = {ir::Interval(c - w, c + w), ir::Interval(-1 - w, -1 + w)};
            const ir::Interval ev = v->eval_box(box);
            const ir::Interval en = n->eval_box(box);
            INFO("centre " << c << ", half-width " << w);
            CHECK(ev.hi - ev.lo < 40 * w + 1e-8);                     // Lipschitz: about 20 w at worst here
            CHECK(en.hi - en.lo < 200 * w * std::log2(1 / w) + 1e-8); // b = a: ~ w log(1/w)
        }
    }
}
