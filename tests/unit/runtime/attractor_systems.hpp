// Automata for the attractor tests (distance, covers), built directly as IR, and an independent
// reference distance for them.
#pragma once

#include "ir/automaton.hpp"
#include "numeric/matrix.hpp"
#include "numeric/rational.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace frac::rt::test {

using num::Rational;

// x -> [a b; c d] x + (e, f), exact.
inline ir::Operator affine2(Rational a, Rational b, Rational c, Rational d, Rational e, Rational f) {
    return ir::Operator::from_exact(num::Matrix<Rational>{{a, b, e}, {c, d, f}, {0, 0, 1}});
}
// The same with interval entries (irrational coefficients).
inline ir::Operator affine2i(num::Interval a, num::Interval b, num::Interval c, num::Interval d,
                             num::Interval e, num::Interval f) {
    return ir::Operator::from_enclosure(num::Matrix<num::Interval>{{a, b, e}, {c, d, f}, {0.0, 0.0, 1.0}});
}

inline ir::Automaton ifs(const std::string& name, const std::vector<ir::Operator>& maps) {
    ir::Automaton a;
    a.name = name;
    a.states.push_back({name, ir::Space::euclidean(2), {}});
    for (const ir::Operator& m : maps) a.arcs.push_back({0, 0, m, std::nullopt, ""});
    return a;
}

// Right-angled Sierpinski triangle with vertices (0,0), (1,0), (0,1).
inline ir::Automaton sierpinski() {
    const Rational h(1, 2);
    return ifs("sierpinski",
               {affine2(h, 0, 0, h, 0, 0), affine2(h, 0, 0, h, h, 0), affine2(h, 0, 0, h, 0, h)});
}

// The same attractor from bary(3) with the projection on the three vertices.
inline ir::Automaton sierpinski_bary() {
    ir::Automaton a;
    a.name = "sierpinski_bary";
    a.states.push_back({"s", ir::Space::barycentric(3), {}});
    const Rational h(1, 2);
    // Column j of map i: the image of vertex j, the midpoint of vertices i and j.
    for (int i = 0; i < 3; ++i) {
        num::Matrix<Rational> m(3, 3);
        for (int j = 0; j < 3; ++j) {
            m(static_cast<std::size_t>(i), static_cast<std::size_t>(j)) += h;
            m(static_cast<std::size_t>(j), static_cast<std::size_t>(j)) += h;
        }
        a.arcs.push_back({0, 0, ir::Operator::from_exact(m), std::nullopt, ""});
    }
    a.projection = ir::Operator::from_exact(num::Matrix<Rational>{{0, 1, 0}, {0, 0, 1}, {1, 1, 1}});
    return a;
}

inline ir::Automaton fern() {
    auto r = [](long n) { return Rational(n, 100); };
    return ifs("fern",
               {affine2(0, 0, 0, r(16), 0, 0), affine2(r(85), r(4), r(-4), r(85), 0, Rational(16, 10)),
                affine2(r(20), r(-26), r(23), r(22), 0, Rational(16, 10)),
                affine2(r(-15), r(28), r(26), r(24), 0, r(44))});
}

// Koch curve from (0,0) to (1,0): four similitudes of ratio 1/3, two rotated by +-60 degrees.
inline ir::Automaton koch() {
    num::UpwardRounding up;
    const num::Interval third = num::div(1.0, 3.0), sixth = num::div(1.0, 6.0);
    const num::Interval s = num::div(num::sqrt(3.0), 6.0); // sin(60) / 3
    const num::Interval z(0.0);
    return ifs("koch", {affine2i(third, z, z, third, z, z), affine2i(sixth, num::neg(s), s, sixth, third, z),
                        affine2i(sixth, s, num::neg(s), sixth, num::Interval(0.5), s),
                        affine2i(third, z, z, third, num::div(2.0, 3.0), z)});
}

// Sierpinski tetrahedron in R3: x/2 + v/2 for the vertices v = 0, e1, e2, e3.
inline ir::Automaton tetrahedron() {
    ir::Automaton a;
    a.name = "tetrahedron";
    a.states.push_back({"t", ir::Space::euclidean(3), {}});
    const Rational h(1, 2);
    for (int v = 0; v < 4; ++v) {
        num::Matrix<Rational> m(4, 4);
        for (std::size_t i = 0; i < 3; ++i) m(i, i) = h;
        m(3, 3) = 1;
        if (v > 0) m(static_cast<std::size_t>(v - 1), 3) = h;
        a.arcs.push_back({0, 0, ir::Operator::from_exact(m), std::nullopt, ""});
    }
    return a;
}

// Two states: A = a(A) u b(B), B = c(A) u e(B), with different maps, so the states' attractors differ.
inline ir::Automaton two_state() {
    ir::Automaton a;
    a.name = "two_state";
    a.states.push_back({"A", ir::Space::euclidean(2), {}});
    a.states.push_back({"B", ir::Space::euclidean(2), {}});
    const Rational h(1, 2), t(1, 3);
    a.arcs.push_back({0, 0, affine2(h, 0, 0, h, 0, 0), std::nullopt, "a"});
    a.arcs.push_back({0, 1, affine2(0, -h, h, 0, 1, h), std::nullopt, "b"});
    a.arcs.push_back({1, 0, affine2(t, 0, 0, t, t, t), std::nullopt, "c"});
    a.arcs.push_back({1, 1, affine2(t, t, -t, t, 0, Rational(2, 3)), std::nullopt, "e"});
    return a;
}

// Reference distance to the attractor of a euclidean R2 automaton, to about `tol`: a depth-first search
// in doubles over the evaluation tree with one ball for every state, B(c, R), invariant under every
// map (|T x - c| <= rho |x - c| + |T c - c| <= R), computed here independently of the runtime. Only
// subtrees that provably cannot improve on the best leaf by more than tol are skipped, so the result
// is within tol of the distance.
inline double reference_distance(const ir::Automaton& a, double px, double py, double tol = 1e-10) {
    struct M {
        double a, b, c, d, e, f;
    };
    std::vector<M> maps;
    double rho = 0;
    for (const ir::Arc& arc : a.arcs) {
        const auto& n = arc.op.nearest;
        const M m{n(0, 0), n(0, 1), n(1, 0), n(1, 1), n(0, 2), n(1, 2)};
        maps.push_back(m);
        // Largest singular value of [a b; c d], closed form.
        const double s = (m.a * m.a + m.b * m.b + m.c * m.c + m.d * m.d) / 2;
        const double det = m.a * m.d - m.b * m.c;
        rho = std::max(rho, std::sqrt(s + std::sqrt(std::max(0.0, s * s - det * det))));
    }
    double cx = 0, cy = 0;
    for (const M& m : maps) cx += m.e, cy += m.f;
    cx /= static_cast<double>(maps.size()), cy /= static_cast<double>(maps.size());
    double gap = 0;
    for (const M& m : maps)
        gap = std::max(gap, std::hypot(m.a * cx + m.b * cy + m.e - cx, m.c * cx + m.d * cy + m.f - cy));
    const double big_r = gap / (1 - rho) * 1.001 + 1e-9;

    struct Node {
        M m;
        double lip;
        std::size_t state;
    };
    std::vector<Node> stack{{{1, 0, 0, 1, 0, 0}, 1.0, a.initial}};
    // Start from the nearest of many points of the attractor (a chaos game: x in A_b gives T x in A_a
    // for an arc a -> b), so that the search prunes from the start.
    double best = std::numeric_limits<double>::infinity();
    std::vector<std::pair<double, double>> on(a.states.size()); // a point of each state's attractor
    {
        std::uint64_t seed = 88172645463325252ull;
        double x = cx, y = cy;
        std::size_t state = a.initial;
        for (int i = 0; i < 200000; ++i) {
            seed ^= seed << 13, seed ^= seed >> 7, seed ^= seed << 17;
            std::vector<std::size_t> in;
            for (std::size_t k = 0; k < a.arcs.size(); ++k)
                if (a.arcs[k].to == state) in.push_back(k);
            const std::size_t k = in[seed % in.size()];
            const M& t = maps[k];
            const double nx = t.a * x + t.b * y + t.e, ny = t.c * x + t.d * y + t.f;
            x = nx, y = ny, state = a.arcs[k].from;
            if (i > 200 && state == a.initial) best = std::min(best, std::hypot(px - x, py - y) + 1e-12);
            if (i > 200) on[state] = {x, y};
        }
    }
    while (!stack.empty()) {
        const Node n = stack.back();
        stack.pop_back();
        const double x = n.m.a * cx + n.m.b * cy + n.m.e, y = n.m.c * cx + n.m.d * cy + n.m.f;
        const double dist = std::hypot(px - x, py - y), r = n.lip * big_r;
        // The node's image of a point of A_state is a point of the attractor.
        const auto [qx, qy] = on[n.state];
        best = std::min(
            best, std::hypot(px - (n.m.a * qx + n.m.b * qy + n.m.e), py - (n.m.c * qx + n.m.d * qy + n.m.f)) +
                      1e-12);
        // Cannot hold a point nearer than best - tol: skipped (so d lies within tol of best).
        if (dist - r > best - tol) continue;
        if (r < tol) {
            best = std::min(best, dist);
            continue;
        }
        std::vector<std::pair<double, Node>> kids;
        for (std::size_t i = 0; i < a.arcs.size(); ++i) {
            if (a.arcs[i].from != n.state) continue;
            const M& t = maps[i];
            const M c{n.m.a * t.a + n.m.b * t.c,         n.m.a * t.b + n.m.b * t.d,
                      n.m.c * t.a + n.m.d * t.c,         n.m.c * t.b + n.m.d * t.d,
                      n.m.a * t.e + n.m.b * t.f + n.m.e, n.m.c * t.e + n.m.d * t.f + n.m.f};
            double s = (t.a * t.a + t.b * t.b + t.c * t.c + t.d * t.d) / 2, det = t.a * t.d - t.b * t.c;
            const double lip = n.lip * std::sqrt(s + std::sqrt(std::max(0.0, s * s - det * det)));
            const double kx = c.a * cx + c.b * cy + c.e, ky = c.c * cx + c.d * cy + c.f;
            kids.push_back({std::hypot(px - kx, py - ky), {c, lip, a.arcs[i].to}});
        }
        // Nearest child on top of the stack.
        std::sort(kids.begin(), kids.end(), [](const auto& u, const auto& v) { return u.first > v.first; });
        for (const auto& k : kids) stack.push_back(k.second);
    }
    return best;
}

} // namespace frac::rt::test
