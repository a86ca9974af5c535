#include "runtime/automata/distance.hpp"

#include "runtime/automata/distance_bounds.hpp"
#include "runtime/limits.hpp"

#include "numeric/matrix.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <fmt/format.h>
#include <limits>
#include <stdexcept>

namespace frac::rt {

namespace {

using bounds::frobenius_upper;
using bounds::up_add;
using bounds::up_mul;
using num::Matrix;

bool is_bary(const ir::Space& s) {
    return s.kind == ir::Space::Kind::barycentric;
}

// The linear part of an operator `to` <- `from` acting on differences of points (see the header), as
// rows x cols intervals containing it for every real matrix inside `m`. Barycentric columns are
// centred: (m - (m 1/n) 1^T) v = m v when the weights v sum to 0, and the centred matrix kills 1,
// so its norm is the norm restricted to such v.
std::vector<Interval> linear_part(const Matrix<Interval>& m, ir::Space to, ir::Space from, std::size_t& rows,
                                  std::size_t& cols) {
    rows = is_bary(to) ? m.rows() : m.rows() - 1;
    cols = is_bary(from) ? m.cols() : m.cols() - 1;
    std::vector<Interval> out(rows * cols);
    for (std::size_t r = 0; r < rows; ++r) {
        Interval mean(0.0);
        if (is_bary(from)) {
            for (std::size_t c = 0; c < m.cols(); ++c) mean = num::add(mean, m(r, c));
            mean = num::div(mean, Interval(static_cast<double>(m.cols())));
        }
        for (std::size_t c = 0; c < cols; ++c)
            out[r * cols + c] = is_bary(from) ? num::sub(m(r, c), mean) : m(r, c);
    }
    return out;
}

// Whether mu I - g is positive definite for every symmetric g inside the interval matrix (n x n):
// an interval Cholesky factorisation whose pivots stay positive proves it.
bool cholesky_positive(const std::vector<Interval>& g, std::size_t n, double mu) {
    std::vector<Interval> l(n * n, Interval(0.0));
    for (std::size_t j = 0; j < n; ++j) {
        Interval d = num::sub(Interval(mu), g[j * n + j]);
        for (std::size_t k = 0; k < j; ++k) d = num::sub(d, num::sqr(l[j * n + k]));
        if (!(d.lo > 0)) return false;
        l[j * n + j] = num::sqrt(d);
        for (std::size_t i = j + 1; i < n; ++i) {
            Interval s = num::neg(g[i * n + j]);
            for (std::size_t k = 0; k < j; ++k) s = num::sub(s, num::mul(l[i * n + k], l[j * n + k]));
            l[i * n + j] = num::div(s, l[j * n + j]);
        }
    }
    return true;
}

// Homogeneous point exactly on the space's hyperplane: R^d gets a last coordinate 1; bary(n) weights
// are rounded to multiples of 2^-30 and the last one is 1 minus the others, which is then exact.
std::vector<double> snap(std::vector<double> x, ir::Space s) {
    if (!is_bary(s)) {
        x.back() = 1.0;
        return x;
    }
    double sum = 0;
    for (std::size_t i = 0; i + 1 < x.size(); ++i) {
        if (!std::isfinite(x[i]) || std::fabs(x[i]) > 1e6)
            throw std::invalid_argument("attractor too far out");
        x[i] = std::ldexp(std::nearbyint(std::ldexp(x[i], 30)), -30);
        sum += x[i];
    }
    x.back() = 1.0 - sum;
    // The sum of multiples of 2^-30 below 2^22 in magnitude is exact, so is 1 - sum; check anyway.
    num::UpwardRounding up;
    Interval check(0.0);
    for (double v : x) check = num::add(check, Interval(v));
    if (!(check.lo == 1.0 && check.hi == 1.0))
        throw std::logic_error("barycentric point not on its hyperplane");
    return x;
}

std::vector<Interval> mat_vec(const Matrix<Interval>& m, const std::vector<Interval>& x) {
    std::vector<Interval> y(m.rows(), Interval(0.0));
    for (std::size_t r = 0; r < m.rows(); ++r)
        for (std::size_t c = 0; c < m.cols(); ++c) y[r] = num::add(y[r], num::mul(m(r, c), x[c]));
    return y;
}

// Upper bound of the euclidean norm of a - b over the space's coordinates (R^d: the last one is 1 in
// both and dropped). The differences are scaled by a power of two near the largest first (exactly), so
// their squares neither overflow (differences past 1e154) nor underflow (below 1e-162) at any scale.
double distance_upper(const std::vector<Interval>& a, const std::vector<Interval>& b, ir::Space s) {
    const std::size_t n = is_bary(s) ? a.size() : a.size() - 1;
    std::vector<double> magnitude(n); // of each difference, an upper bound
    double largest = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const Interval d = num::sub(a[i], b[i]);
        magnitude[i] = std::max(std::fabs(d.lo), std::fabs(d.hi));
        largest = std::max(largest, magnitude[i]);
    }
    if (!(largest > 0) || !std::isfinite(largest)) return largest; // 0, inf or NaN (never a bound)
    int exponent = 0;
    std::frexp(largest, &exponent); // largest < 2^exponent
    Interval acc(0.0);
    for (const double m : magnitude) {
        double scaled = std::ldexp(m, -exponent); // exact, but where a small one falls to subnormals
        if (std::ldexp(scaled, exponent) < m) scaled = std::nextafter(scaled, num::inf);
        acc = num::add(acc, num::sqr(Interval(scaled)));
    }
    // sqrt(acc) <= sqrt(n): times 2^exponent it stays finite unless the distance itself is not.
    return std::ldexp(num::sqrt(acc).hi, exponent);
}

std::vector<Interval> thin(const std::vector<double>& v) {
    return {v.begin(), v.end()};
}

// States with a nonempty attractor: those with an infinite path. Repeatedly drop states whose arcs
// all lead to dropped states.
std::vector<bool> live_states(const ir::Automaton& a) {
    std::vector<bool> live(a.states.size(), true);
    for (bool changed = true; changed;) {
        changed = false;
        for (std::size_t s = 0; s < a.states.size(); ++s) {
            if (!live[s]) continue;
            bool any = false;
            for (const ir::Arc& arc : a.arcs)
                if (arc.from == s && live[arc.to]) any = true;
            if (!any) live[s] = false, changed = true;
        }
    }
    return live;
}

std::vector<bool> reachable_live(const ir::Automaton& a, const std::vector<bool>& live) {
    std::vector<bool> seen(a.states.size(), false);
    if (!live[a.initial]) return seen;
    std::vector<std::size_t> todo{a.initial};
    seen[a.initial] = true;
    while (!todo.empty()) {
        const std::size_t s = todo.back();
        todo.pop_back();
        for (const ir::Arc& arc : a.arcs)
            if (arc.from == s && live[arc.to] && !seen[arc.to]) seen[arc.to] = true, todo.push_back(arc.to);
    }
    return seen;
}

void check_shapes(const ir::Automaton& a) {
    if (a.states.empty() || a.initial >= a.states.size())
        throw std::invalid_argument("automaton without states");
    for (const ir::Arc& arc : a.arcs) {
        if (arc.from >= a.states.size() || arc.to >= a.states.size())
            throw std::invalid_argument("arc to a missing state");
        const ir::Space from = a.states[arc.from].space, to = a.states[arc.to].space;
        const Matrix<Interval>& m = arc.op.enclosure;
        if (m.rows() != static_cast<std::size_t>(from.coordinates()) ||
            m.cols() != static_cast<std::size_t>(to.coordinates()))
            throw std::invalid_argument(fmt::format(
                "operator of arc {} -> {} is {}x{}, the spaces need {}x{}", a.states[arc.from].name,
                a.states[arc.to].name, m.rows(), m.cols(), from.coordinates(), to.coordinates()));
        // Affine: w_from^T m = w_to^T, needed for the balls (differences of points stay differences).
        num::UpwardRounding up;
        for (std::size_t c = 0; c < m.cols(); ++c) {
            Interval s(0.0);
            for (std::size_t r = 0; r < m.rows(); ++r)
                if (is_bary(from) || r + 1 == m.rows()) s = num::add(s, m(r, c));
            const double want = (is_bary(to) || c + 1 == m.cols()) ? 1.0 : 0.0;
            if (!s.contains(want))
                throw std::invalid_argument(fmt::format("operator of arc {} -> {} is not affine",
                                                        a.states[arc.from].name, a.states[arc.to].name));
        }
    }
}

// Proven Lipschitz bound of an operator (upward rounding held by the caller).
double operator_lip(const Matrix<Interval>& m, ir::Space to, ir::Space from) {
    std::size_t rows = 0, cols = 0;
    const std::vector<Interval> lin = linear_part(m, to, from, rows, cols);
    return spectral_norm_upper(lin, rows, cols);
}

Matrix<Interval> product(const Matrix<Interval>& a, const Matrix<Interval>& b) {
    return a * b; // outward (num/matrix.cpp)
}

// Shortest cycle through s (arc indices in order), empty when none.
std::vector<std::size_t> shortest_cycle(const ir::Automaton& a, const std::vector<bool>& live,
                                        std::size_t s) {
    std::vector<std::ptrdiff_t> via(a.states.size(), -1); // arc reaching each state first
    std::deque<std::size_t> queue;
    for (std::size_t i = 0; i < a.arcs.size(); ++i) {
        const ir::Arc& arc = a.arcs[i];
        if (arc.from != s || !live[arc.to]) continue;
        if (arc.to == s) return {i};
        if (via[arc.to] < 0) via[arc.to] = static_cast<std::ptrdiff_t>(i), queue.push_back(arc.to);
    }
    while (!queue.empty()) {
        const std::size_t v = queue.front();
        queue.pop_front();
        for (std::size_t i = 0; i < a.arcs.size(); ++i) {
            const ir::Arc& arc = a.arcs[i];
            if (arc.from != v || !live[arc.to]) continue;
            if (arc.to == s) {
                std::vector<std::size_t> path{i};
                for (std::size_t u = v; u != s; u = a.arcs[static_cast<std::size_t>(via[u])].from)
                    path.push_back(static_cast<std::size_t>(via[u]));
                std::reverse(path.begin(), path.end());
                return path;
            }
            if (via[arc.to] < 0) via[arc.to] = static_cast<std::ptrdiff_t>(i), queue.push_back(arc.to);
        }
    }
    return {};
}

// A point of A_c: the fixed point of the composite along a cycle through c, enclosed with the
// contraction bound |x* - x| <= |T x - x| / (1 - rho). Returns false when no power of the cycle up to
// 2^5 is proven contracting.
bool cycle_witness(const ir::Automaton& a, const std::vector<std::size_t>& cycle, std::size_t c,
                   std::vector<Interval>& point, double& radius) {
    const ir::Space sp = a.states[c].space;
    Matrix<Interval> t = a.arcs[cycle.front()].op.enclosure;
    for (std::size_t i = 1; i < cycle.size(); ++i) t = product(t, a.arcs[cycle[i]].op.enclosure);
    const std::size_t n = t.rows();
    // (T - I) x = 0 with the last row replaced by w^T x = 1.
    Matrix<double> lhs(n, n), rhs(n, 1);
    for (std::size_t r = 0; r < n; ++r)
        for (std::size_t k = 0; k < n; ++k) lhs(r, k) = num::midpoint(t(r, k)) - (r == k ? 1.0 : 0.0);
    for (std::size_t k = 0; k < n; ++k) lhs(n - 1, k) = (is_bary(sp) || k + 1 == n) ? 1.0 : 0.0;
    rhs(n - 1, 0) = 1.0;
    const auto sol = num::solve(lhs, rhs);
    if (!sol) return false;
    std::vector<double> x(n);
    for (std::size_t r = 0; r < n; ++r) x[r] = (*sol)(r, 0);
    for (double v : x)
        if (!std::isfinite(v)) return false;
    x = snap(x, sp);
    num::UpwardRounding up;
    const std::vector<Interval> xi = thin(x);
    Matrix<Interval> power = t;
    for (int k = 0; k <= 5; ++k) {
        const double rho = operator_lip(power, sp, sp);
        if (rho < 1) {
            const double moved = distance_upper(mat_vec(power, xi), xi, sp);
            radius = num::div(Interval(moved), num::sub(Interval(1.0), Interval(rho))).hi;
            point = xi;
            return std::isfinite(radius);
        }
        power = product(power, power);
    }
    return false;
}

} // namespace

double spectral_norm_upper(const std::vector<Interval>& m, std::size_t rows, std::size_t cols) {
    if (rows == 0 || cols == 0) return 0;
    num::UpwardRounding up;
    const double frob = frobenius_upper(m);
    if (!std::isfinite(frob)) return frob;
    // g = m^T m (cols x cols), enclosed.
    std::vector<Interval> g(cols * cols, Interval(0.0));
    for (std::size_t i = 0; i < cols; ++i)
        for (std::size_t j = 0; j <= i; ++j) {
            Interval s(0.0);
            for (std::size_t r = 0; r < rows; ++r)
                s = num::add(s, num::mul(m[r * cols + i], m[r * cols + j]));
            g[i * cols + j] = g[j * cols + i] = s;
        }
    // Power iteration on the midpoints for an estimate of the largest eigenvalue.
    std::vector<double> v(cols, 1.0), w(cols);
    double lambda = 0;
    for (int it = 0; it < 60; ++it) {
        for (std::size_t i = 0; i < cols; ++i) {
            double s = 0;
            for (std::size_t j = 0; j < cols; ++j) s += num::midpoint(g[i * cols + j]) * v[j];
            w[i] = s;
        }
        double nv = 0;
        for (double x : w) nv += x * x;
        nv = std::sqrt(nv);
        if (!(nv > 0)) break;
        lambda = nv;
        for (std::size_t i = 0; i < cols; ++i) v[i] = w[i] / nv;
    }
    double width = 0;
    for (const Interval& x : g) width = std::max(width, num::width(x));
    double mu = lambda * (1 + 1e-9) + width * static_cast<double>(cols) + 1e-300;
    for (int attempt = 0; attempt < 4; ++attempt, mu = mu * 1.001 + 1e-300) {
        if (mu >= frob * frob) break;
        if (cholesky_positive(g, cols, mu)) return std::min(frob, num::sqrt(Interval(mu)).hi);
    }
    return frob;
}

std::vector<StateBall> bounding_balls(const ir::Automaton& a) {
    check_shapes(a);
    const std::vector<bool> live = live_states(a);
    const std::vector<bool> used = reachable_live(a, live);
    const std::size_t ns = a.states.size();
    std::vector<StateBall> balls(ns);
    for (StateBall& b : balls) b.radius = b.witness_radius = -1;

    std::vector<std::size_t> arcs; // arcs between used states
    for (std::size_t i = 0; i < a.arcs.size(); ++i)
        if (used[a.arcs[i].from] && used[a.arcs[i].to]) arcs.push_back(i);
    std::vector<double> lip(a.arcs.size(), 0.0);
    {
        num::UpwardRounding up;
        for (std::size_t i : arcs)
            lip[i] = operator_lip(a.arcs[i].op.enclosure, a.states[a.arcs[i].from].space,
                                  a.states[a.arcs[i].to].space);
    }

    // Centres: the fixed point of "each state's centre is the mean of its arcs' images of the
    // targets' centres", iterated from the origin / the barycentre. Any centre is sound; a central
    // one gives small radii.
    std::vector<std::vector<double>> c(ns);
    for (std::size_t s = 0; s < ns; ++s) {
        const ir::Space sp = a.states[s].space;
        const std::size_t n = static_cast<std::size_t>(sp.coordinates());
        c[s].assign(n, is_bary(sp) ? 1.0 / static_cast<double>(n) : 0.0);
        if (!is_bary(sp)) c[s].back() = 1.0;
    }
    auto apply = [&](std::size_t i, const std::vector<double>& x) {
        const Matrix<double>& m = a.arcs[i].op.nearest;
        std::vector<double> y(m.rows(), 0.0);
        for (std::size_t r = 0; r < m.rows(); ++r)
            for (std::size_t k = 0; k < m.cols(); ++k) y[r] += m(r, k) * x[k];
        return y;
    };
    for (int it = 0; it < 300; ++it) {
        std::vector<std::vector<double>> next = c;
        for (std::size_t s = 0; s < ns; ++s) {
            if (!used[s]) continue;
            std::vector<double> sum(c[s].size(), 0.0);
            int count = 0;
            for (std::size_t i : arcs) {
                if (a.arcs[i].from != s) continue;
                const std::vector<double> y = apply(i, c[a.arcs[i].to]);
                for (std::size_t r = 0; r < y.size(); ++r) sum[r] += y[r];
                ++count;
            }
            for (std::size_t r = 0; r < sum.size(); ++r) next[s][r] = sum[r] / count;
        }
        c = next;
    }
    for (std::size_t s = 0; s < ns; ++s)
        if (used[s]) c[s] = snap(c[s], a.states[s].space);

    // Radii: the least fixed point of r_a = max over arcs (lip r_b + |T c_b - c_a|), then verified.
    std::vector<double> gap(a.arcs.size(), 0.0); // |T c_b - c_a|, proven upper bound
    {
        num::UpwardRounding up;
        for (std::size_t i : arcs) {
            const ir::Arc& arc = a.arcs[i];
            gap[i] = distance_upper(mat_vec(arc.op.enclosure, thin(c[arc.to])), thin(c[arc.from]),
                                    a.states[arc.from].space);
        }
    }
    // Every map contracting: the radii are bounded by the largest gap over 1 - the largest contraction,
    // so radii past the doubles come from an attractor past them, not from maps that do not contract.
    bool contracting = true;
    for (std::size_t i : arcs) contracting = contracting && lip[i] < 1;
    std::vector<double> r(ns, 0.0);
    bool settled = false;
    for (int it = 0; it < 100000 && !settled; ++it) {
        settled = true;
        std::vector<double> next(ns, 0.0);
        for (std::size_t i : arcs) {
            const ir::Arc& arc = a.arcs[i];
            next[arc.from] = std::max(next[arc.from], lip[i] * r[arc.to] + gap[i]);
        }
        for (std::size_t s = 0; s < ns; ++s) {
            if (!std::isfinite(next[s]) && contracting)
                throw RangeError(fmt::format("the attractor of '{}' leaves the range of doubles (it has no "
                                             "finite bounding ball): scale its coordinates down",
                                             a.name));
            if (!std::isfinite(next[s]))
                throw std::invalid_argument(
                    fmt::format("no bounding balls for automaton '{}': they diverge, its operators do not "
                                "contract in the euclidean norm of their spaces",
                                a.name));
            // Relative: radii of 1e-300 settle as those of 1e300 do.
            if (std::fabs(next[s] - r[s]) > 1e-14 * next[s]) settled = false;
        }
        r = next;
    }
    auto verified = [&] {
        num::UpwardRounding up;
        for (std::size_t i : arcs) {
            const ir::Arc& arc = a.arcs[i];
            if (!(up_add(up_mul(lip[i], r[arc.to]), gap[i]) <= r[arc.from])) return false;
        }
        return true;
    };
    bool ok = false;
    for (int attempt = 0; attempt < 30 && !ok; ++attempt) {
        for (double& x : r) x = x * (1 + 1e-9 * (1 << std::min(attempt, 20))) + 1e-300;
        ok = verified();
    }
    if (!ok)
        throw std::invalid_argument(fmt::format("no bounding balls for automaton '{}': its operators do not "
                                                "contract in the euclidean norm of their spaces",
                                                a.name));
    for (std::size_t s = 0; s < ns; ++s)
        if (used[s]) balls[s].centre = c[s], balls[s].radius = r[s];

    // Witnesses: follow the shortest path to a state on a cycle, take that cycle's fixed point and
    // map it back along the path. The ball itself is the fallback (some point of A_s lies in it).
    for (std::size_t s = 0; s < ns; ++s) {
        if (!used[s]) continue;
        StateBall& b = balls[s];
        b.witness = thin(b.centre);
        b.witness_radius = b.radius;
        // BFS over states from s for the nearest state on a cycle.
        std::vector<std::ptrdiff_t> via(ns, -1);
        std::vector<bool> seen(ns, false);
        std::deque<std::size_t> queue{s};
        seen[s] = true;
        while (!queue.empty()) {
            const std::size_t v = queue.front();
            queue.pop_front();
            const std::vector<std::size_t> cycle = shortest_cycle(a, used, v);
            if (!cycle.empty()) {
                std::vector<Interval> point;
                double radius = 0;
                if (!cycle_witness(a, cycle, v, point, radius)) break;
                std::vector<std::size_t> path; // arcs from s to v
                for (std::size_t u = v; u != s; u = a.arcs[static_cast<std::size_t>(via[u])].from)
                    path.push_back(static_cast<std::size_t>(via[u]));
                num::UpwardRounding up;
                for (std::size_t p : path) { // innermost arc last in the composite, so map it first
                    const ir::Arc& arc = a.arcs[p];
                    point = mat_vec(arc.op.enclosure, point);
                    radius = up_mul(lip[p], radius);
                }
                if (std::isfinite(radius) && radius < b.witness_radius)
                    b.witness = point, b.witness_radius = radius;
                break;
            }
            for (std::size_t i : arcs)
                if (a.arcs[i].from == v && !seen[a.arcs[i].to])
                    seen[a.arcs[i].to] = true, via[a.arcs[i].to] = static_cast<std::ptrdiff_t>(i),
                    queue.push_back(a.arcs[i].to);
        }
    }
    return balls;
}

AttractorDistance::AttractorDistance(const ir::Automaton& a, DistanceOptions options) : options_(options) {
    if (!(options_.epsilon > 0) || !std::isfinite(options_.epsilon))
        throw std::invalid_argument("distance epsilon must be positive");
    if (options_.max_nodes == 0) throw std::invalid_argument("distance node budget must be positive");
    if (!(options_.box_tolerance >= 0) || !std::isfinite(options_.box_tolerance))
        throw std::invalid_argument("distance box tolerance must be finite and >= 0");
    balls_ = bounding_balls(a);
    if (balls_[a.initial].radius < 0)
        throw std::invalid_argument(fmt::format("the attractor of automaton '{}' is empty (no path from its "
                                                "initial state reaches a cycle)",
                                                a.name));
    initial_ = a.initial;
    const ir::Space init = a.states[a.initial].space;
    if (is_bary(init) && !a.projection)
        throw std::invalid_argument("a barycentric initial state needs a projection for distances");
    dim_ = a.output_dimension();
    num::UpwardRounding up;
    states_.resize(a.states.size());
    for (std::size_t s = 0; s < a.states.size(); ++s)
        states_[s].coords = static_cast<std::size_t>(a.states[s].space.coordinates()),
        states_[s].bary = is_bary(a.states[s].space);
    for (const ir::Arc& arc : a.arcs) {
        if (balls_[arc.from].radius < 0 || balls_[arc.to].radius < 0) continue;
        ArcData d;
        d.to = arc.to;
        const Matrix<Interval>& m = arc.op.enclosure;
        d.op.assign(m.rows() * m.cols(), Interval(0.0));
        d.nearest.assign(m.rows() * m.cols(), 0.0);
        for (std::size_t r = 0; r < m.rows(); ++r)
            for (std::size_t c = 0; c < m.cols(); ++c)
                d.op[r * m.cols() + c] = m(r, c), d.nearest[r * m.cols() + c] = arc.op.nearest(r, c);
        d.lip = operator_lip(m, a.states[arc.from].space, a.states[arc.to].space);
        states_[arc.from].arcs.push_back(arcs_.size());
        arcs_.push_back(std::move(d));
    }
    const std::size_t n = states_[initial_].coords, d = static_cast<std::size_t>(dim_);
    root_.assign(d * n, Interval(0.0));
    if (a.projection) {
        const Matrix<Interval>& p = a.projection->enclosure;
        if (p.cols() != n || p.rows() != d + 1) throw std::invalid_argument("projection of the wrong size");
        for (std::size_t r = 0; r < d; ++r)
            for (std::size_t c = 0; c < n; ++c) root_[r * n + c] = p(r, c);
        root_lip_ = operator_lip(p, ir::Space::euclidean(dim_), init);
    } else {
        for (std::size_t r = 0; r < d; ++r) root_[r * n + r] = Interval(1.0);
        root_lip_ = 1;
    }
}

} // namespace frac::rt
