// Automata of the papers built directly in C++, shared by the ir and runtime unit tests.
#pragma once

#include "ir/automaton.hpp"

#include <cmath>
#include <string>
#include <type_traits>
#include <vector>

namespace frac::test {

using num::Interval;
using num::Matrix;
using num::Rational;

inline Rational q(long n, long d = 1) {
    return Rational(n, d);
}

// Homogeneous affine map of R^d from its linear part rows and translation.
inline Matrix<Rational> affine(const std::vector<std::vector<Rational>>& linear,
                               const std::vector<Rational>& shift) {
    const std::size_t d = shift.size();
    Matrix<Rational> m(d + 1, d + 1);
    for (std::size_t r = 0; r < d; ++r) {
        for (std::size_t c = 0; c < d; ++c) m(r, c) = linear[r][c];
        m(r, d) = shift[r];
    }
    m(d, d) = 1;
    return m;
}

// An arc with an exact (Matrix<Rational>) or enclosed (Matrix<Interval>) operator.
template <typename M>
ir::Arc arc(std::size_t from, std::size_t to, const M& m, std::string label) {
    ir::Arc a;
    a.from = from;
    a.to = to;
    if constexpr (std::is_same_v<M, Matrix<Rational>>)
        a.op = ir::Operator::from_exact(m);
    else
        a.op = ir::Operator::from_enclosure(m);
    a.label = std::move(label);
    return a;
}

inline ir::State state(std::string name, ir::Space space) {
    ir::State s;
    s.name = std::move(name);
    s.space = space;
    return s;
}

// Sierpinski triangle: three maps x/2 + t of R2 onto the corners (0,0), (1,0), (1/2, 1).
inline ir::Automaton sierpinski() {
    ir::Automaton a;
    a.name = "sierpinski";
    a.states.push_back(state("s", ir::Space::euclidean(2)));
    const std::vector<std::vector<Rational>> half{{q(1, 2), 0}, {0, q(1, 2)}};
    a.arcs.push_back(arc(0, 0, affine(half, {0, 0}), "f0"));
    a.arcs.push_back(arc(0, 0, affine(half, {q(1, 2), 0}), "f1"));
    a.arcs.push_back(arc(0, 0, affine(half, {q(1, 4), q(1, 2)}), "f2"));
    return a;
}

// Cantor set in R1: x/3 and x/3 + 2/3.
inline ir::Automaton cantor() {
    ir::Automaton a;
    a.name = "cantor";
    a.states.push_back(state("c", ir::Space::euclidean(1)));
    a.arcs.push_back(arc(0, 0, affine({{q(1, 3)}}, {0}), "f0"));
    a.arcs.push_back(arc(0, 0, affine({{q(1, 3)}}, {q(2, 3)}), "f1"));
    return a;
}

// Homogeneous 3x3 enclosure of x -> r R(angle) x + t, with angle = k pi / m.
inline Matrix<Interval> similitude(Interval r, int k, int m, Interval tx, Interval ty) {
    const num::UpwardRounding up;
    const Interval angle = num::div(num::mul(num::pi(), Interval(k)), Interval(m));
    const Interval c = num::mul(r, num::cos(angle)), s = num::mul(r, num::sin(angle));
    Matrix<Interval> t(3, 3);
    t(0, 0) = c;
    t(0, 1) = num::neg(s);
    t(0, 2) = tx;
    t(1, 0) = s;
    t(1, 1) = c;
    t(1, 2) = ty;
    t(2, 2) = Interval(1.0);
    return t;
}

// Koch curve from (0,0) to (1,0): four similitudes of ratio 1/3 (two rotated by +-60 degrees).
inline ir::Automaton koch() {
    const num::UpwardRounding up;
    const Interval third = num::div(Interval(1.0), Interval(3.0));
    const Interval two_thirds = num::div(Interval(2.0), Interval(3.0));
    const Interval h = num::div(num::sqrt(Interval(3.0)), Interval(6.0)); // height of the peak
    ir::Automaton a;
    a.name = "koch";
    a.states.push_back(state("k", ir::Space::euclidean(2)));
    a.arcs.push_back(arc(0, 0, similitude(third, 0, 1, 0.0, 0.0), "f0"));
    a.arcs.push_back(arc(0, 0, similitude(third, 1, 3, third, 0.0), "f1"));
    a.arcs.push_back(arc(0, 0, similitude(third, -1, 3, Interval(0.5), h), "f2"));
    a.arcs.push_back(arc(0, 0, similitude(third, 0, 1, two_thirds, 0.0), "f3"));
    return a;
}

// Barnsley fern with its decimal coefficients, exact.
inline ir::Automaton fern() {
    auto d = [](const char* t) { return *Rational::parse_decimal(t); };
    ir::Automaton a;
    a.name = "fern";
    a.states.push_back(state("f", ir::Space::euclidean(2)));
    a.arcs.push_back(arc(0, 0, affine({{0, 0}, {0, d("0.16")}}, {0, 0}), "f1"));
    a.arcs.push_back(
        arc(0, 0, affine({{d("0.85"), d("0.04")}, {d("-0.04"), d("0.85")}}, {0, d("1.6")}), "f2"));
    a.arcs.push_back(
        arc(0, 0, affine({{d("0.2"), d("-0.26")}, {d("0.23"), d("0.22")}}, {0, d("1.6")}), "f3"));
    a.arcs.push_back(
        arc(0, 0, affine({{d("-0.15"), d("0.28")}, {d("0.26"), d("0.24")}}, {0, d("0.44")}), "f4"));
    return a;
}

// Penrose kite (a) and dart (b) of Bandt and Gummelt (seed 002, Example 1): ratio 2 / (1 + sqrt 5).
inline ir::Automaton penrose() {
    const num::UpwardRounding up;
    const Interval phi = num::div(num::add(Interval(1.0), num::sqrt(Interval(5.0))), Interval(2.0));
    const Interval r = num::div(Interval(1.0), phi);
    const Interval angle = num::div(num::mul(num::pi(), Interval(4.0)), Interval(5.0));
    ir::Automaton a;
    a.name = "penrose";
    a.states.push_back(state("a", ir::Space::euclidean(2)));
    a.states.push_back(state("b", ir::Space::euclidean(2)));
    a.arcs.push_back(arc(0, 1, similitude(Interval(1.0), 0, 1, 0.0, 0.0), "T0a"));
    a.arcs.push_back(arc(0, 0, similitude(r, 3, 5, 0.0, 1.0), "T1a"));
    a.arcs.push_back(arc(1, 1,
                         similitude(r, 4, 5, num::mul(phi, num::sin(angle)),
                                    num::add(Interval(1.0), num::mul(phi, num::cos(angle)))),
                         "T0b"));
    a.arcs.push_back(arc(1, 0, similitude(r, 7, 5, 0.0, 1.0), "T1b"));
    return a;
}

// A graph-directed set in R1 with a closed-form dimension: A = A/2 u (B/2 + 1/2), B = A/2, so
// M(s) = [[u, u], [u, 0]] with u = 2^-s and rho = 1 at u = 1/phi: s = log2(phi).
inline ir::Automaton golden() {
    ir::Automaton a;
    a.name = "golden";
    a.states.push_back(state("a", ir::Space::euclidean(1)));
    a.states.push_back(state("b", ir::Space::euclidean(1)));
    a.arcs.push_back(arc(0, 0, affine({{q(1, 2)}}, {0}), "f"));
    a.arcs.push_back(arc(0, 1, affine({{q(1, 2)}}, {q(1, 2)}), "g"));
    a.arcs.push_back(arc(1, 0, affine({{q(1, 2)}}, {0}), "h"));
    return a;
}

// Control points (x, y) as the columns of a homogeneous projection bary(k) -> R2.
inline Matrix<Rational> control_points(const std::vector<std::pair<long, long>>& p, std::size_t first,
                                       std::size_t count) {
    Matrix<Rational> m(3, count);
    for (std::size_t j = 0; j < count; ++j) {
        m(0, j) = p[first + j].first;
        m(1, j) = p[first + j].second;
        m(2, j) = 1;
    }
    return m;
}

// Uniform B-spline of degree 2 or 3 as a projected CIFS (seed 002 Fig. 4): state a in R2 with one
// arc per segment (the projection onto that segment's degree + 1 control points) into state b in
// bary(degree + 1), whose two subdivision matrices map the basis to its halves.
inline ir::Automaton bspline(int degree, const std::vector<std::pair<long, long>>& points) {
    ir::Automaton a;
    a.name = degree == 2 ? "quadratic" : "cubic";
    const std::size_t k = static_cast<std::size_t>(degree) + 1;
    a.states.push_back(state("a", ir::Space::euclidean(2)));
    a.states.push_back(state("b", ir::Space::barycentric(static_cast<int>(k))));
    for (std::size_t seg = 0; seg + k <= points.size(); ++seg)
        a.arcs.push_back(arc(0, 1, control_points(points, seg, k), "T" + std::to_string(seg) + "a"));
    Matrix<Rational> t0, t1;
    if (degree == 2) {
        t0 = Matrix<Rational>{{q(3, 4), q(1, 4), 0}, {q(1, 4), q(3, 4), q(3, 4)}, {0, 0, q(1, 4)}};
        t1 = Matrix<Rational>{{q(1, 4), 0, 0}, {q(3, 4), q(3, 4), q(1, 4)}, {0, q(1, 4), q(3, 4)}};
    } else {
        // Columns: the control points of each half in the weights of the segment's four points.
        t0 = Matrix<Rational>{{q(1, 2), q(1, 8), 0, 0},
                              {q(1, 2), q(6, 8), q(1, 2), q(1, 8)},
                              {0, q(1, 8), q(1, 2), q(6, 8)},
                              {0, 0, 0, q(1, 8)}};
        t1 = Matrix<Rational>{{q(1, 8), 0, 0, 0},
                              {q(6, 8), q(1, 2), q(1, 8), 0},
                              {q(1, 8), q(1, 2), q(6, 8), q(1, 2)},
                              {0, 0, q(1, 8), q(1, 2)}};
    }
    a.arcs.push_back(arc(1, 1, t0, "T0b"));
    a.arcs.push_back(arc(1, 1, t1, "T1b"));
    return a;
}

// One quadratic segment as Guérin's projected IFS P A: the initial state is bary(3) with the two
// subdivision matrices, drawn through the control points.
inline ir::Automaton projected_quadratic(const std::vector<std::pair<long, long>>& points) {
    ir::Automaton a = bspline(2, points);
    a.arcs.erase(a.arcs.begin()); // the one segment arc of state a
    for (auto& arc : a.arcs) arc.from = arc.to = 0;
    a.states.erase(a.states.begin());
    a.initial = 0;
    a.projection = ir::Operator::from_exact(control_points(points, 0, 3));
    return a;
}

// A tensor-product B-spline patch of degree 2 or 3 as a one-state IFS in bary((degree + 1)^2):
// T_(sigma, tau) = T_sigma (x) T_tau of the curve's subdivision matrices, arc sigma * 2 + tau, weight
// index a * (degree + 1) + b. No projection.
inline ir::Automaton tensor_patch(int degree) {
    const std::size_t k = static_cast<std::size_t>(degree) + 1;
    std::vector<std::pair<long, long>> points;
    for (std::size_t i = 0; i < k; ++i) points.emplace_back(static_cast<long>(i), 0);
    const ir::Automaton curve = bspline(degree, points);
    const Matrix<Rational> t[2] = {*curve.arcs[1].op.exact, *curve.arcs[2].op.exact};
    ir::Automaton patch;
    patch.name = "patch";
    patch.states.push_back(state("p", ir::Space::barycentric(static_cast<int>(k * k))));
    for (int s = 0; s < 2; ++s)
        for (int u = 0; u < 2; ++u) {
            Matrix<Rational> m(k * k, k * k);
            for (std::size_t r = 0; r < k * k; ++r)
                for (std::size_t c = 0; c < k * k; ++c) m(r, c) = t[s](r / k, c / k) * t[u](r % k, c % k);
            patch.arcs.push_back(arc(0, 0, m, "T" + std::to_string(s) + std::to_string(u)));
        }
    return patch;
}

} // namespace frac::test
