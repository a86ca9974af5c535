#include "runtime/fit/least_squares.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <tbb/parallel_for.h>

namespace frac::rt::fit {

namespace {

constexpr double infinity = std::numeric_limits<double>::infinity();

// The data as a piecewise linear function of t.
struct Interpolant {
    const Samples& s;
    std::array<double, 2> operator()(double u) const {
        const auto it = std::upper_bound(s.t.begin(), s.t.end(), u);
        std::size_t i = it == s.t.begin() ? 0 : std::size_t(it - s.t.begin()) - 1;
        i = std::min(i, s.size() - 2);
        const double w = std::clamp((u - s.t[i]) / (s.t[i + 1] - s.t[i]), 0.0, 1.0);
        const double x = s.x[i] + w * (s.x[i + 1] - s.x[i]);
        const double y = s.curve() ? s.y[i] + w * (s.y[i + 1] - s.y[i]) : 0;
        return {x, y};
    }
};

struct RowFit {
    double b = 0, e = 0, sse = infinity;
    std::array<double, 2> c{};
};

// Least squares of target ≈ b u + Σ c_k v_k + e over the samples, with Σ |c_k| <= max_scaling (else the c are
// scaled down to it and b, e refitted).
RowFit fit_row(const std::vector<double>& u, const std::vector<std::array<double, 2>>& v,
               const std::vector<double>& target, const std::array<bool, 2>& uses, double max_scaling) {
    const std::size_t m = u.size();
    const int p = 2 + int(uses[0]) + int(uses[1]);
    auto features = [&](std::size_t i, double* f) {
        int q = 0;
        f[q++] = u[i];
        for (int k = 0; k < 2; ++k)
            if (uses[k]) f[q++] = v[i][k];
        f[q] = 1;
    };
    Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
    Eigen::Vector4d rhs = Eigen::Vector4d::Zero();
    for (std::size_t i = 0; i < m; ++i) {
        double f[4];
        features(i, f);
        for (int r = 0; r < p; ++r) {
            rhs[r] += f[r] * target[i];
            for (int c = 0; c < p; ++c) normal(r, c) += f[r] * f[c];
        }
    }
    const Eigen::VectorXd sol =
        normal.topLeftCorner(p, p).completeOrthogonalDecomposition().solve(rhs.head(p));
    RowFit r;
    r.b = sol[0];
    int q = 1;
    for (int k = 0; k < 2; ++k)
        if (uses[k]) r.c[k] = sol[q++];
    r.e = sol[q];
    const double sum = std::abs(r.c[0]) + std::abs(r.c[1]);
    if (!std::isfinite(sum)) return RowFit{};
    if (sum > max_scaling) {
        for (double& c : r.c) c *= max_scaling / sum;
        // b, e for the fixed scalings: a line fit of the rest.
        double su = 0, suu = 0, sy = 0, suy = 0;
        for (std::size_t i = 0; i < m; ++i) {
            const double y = target[i] - r.c[0] * v[i][0] - r.c[1] * v[i][1];
            su += u[i], suu += u[i] * u[i], sy += y, suy += u[i] * y;
        }
        const double det = double(m) * suu - su * su;
        if (!(std::abs(det) > 0)) return RowFit{};
        r.b = (double(m) * suy - su * sy) / det;
        r.e = (sy - r.b * su) / double(m);
    }
    r.sse = 0;
    for (std::size_t i = 0; i < m; ++i) {
        const double d = r.b * u[i] + r.c[0] * v[i][0] + r.c[1] * v[i][1] + r.e - target[i];
        r.sse += d * d;
    }
    return r;
}

struct Match {
    double sse = infinity;
    Piece piece;
};

struct Fitter {
    const Samples& s;
    const LeastSquaresOptions& o;
    Interpolant data{s};

    int unknowns_per_row() const { return !s.curve() ? 3 : o.coupled ? 4 : 3; }

    // The best shear from one of the domains onto the range [lo, hi] (data samples `first`..`last`).
    // orientation: 0 (a > 0), 1 (a < 0) or -1 (either).
    Match best(double lo, double hi, std::size_t first, std::size_t last,
               const std::vector<std::pair<double, double>>& domains, int only_orientation = -1) const {
        Match best;
        const std::size_t m = last - first + 1;
        if (last < first || m < std::size_t(unknowns_per_row()) + 1) return best;
        std::vector<double> u(m), tx(m), ty(m);
        std::vector<std::array<double, 2>> v(m);
        for (std::size_t i = 0; i < m; ++i) {
            tx[i] = s.x[first + i];
            ty[i] = s.curve() ? s.y[first + i] : 0;
        }
        for (const auto& [alpha, beta] : domains) {
            // Longer than the range by more than rounding (grid cuts of equal length differ in the last
            // bits, and an equal-length domain would not contract: |a| = 1).
            if (!(beta - alpha > (hi - lo) * (1 + 1e-9))) continue;
            for (int orientation = 0; orientation < 2; ++orientation) {
                if (only_orientation >= 0 && orientation != only_orientation) continue;
                const double scale = (beta - alpha) / (hi - lo);
                for (std::size_t i = 0; i < m; ++i) {
                    const double w = (s.t[first + i] - lo) * scale;
                    u[i] = orientation == 0 ? alpha + w : beta - w;
                    v[i] = data(u[i]);
                }
                Piece piece{{}, alpha, beta, lo, hi};
                Shear& sh = piece.map;
                sh.a = (orientation == 0 ? 1 : -1) / scale;
                sh.d = (orientation == 0 ? lo : hi) - sh.a * alpha;
                double sse = 0;
                if (!s.curve()) {
                    const RowFit r = fit_row(u, v, tx, {true, false}, o.max_scaling);
                    sse = r.sse;
                    sh.b[0] = r.b, sh.c[0][0] = r.c[0], sh.e[0] = r.e;
                } else {
                    for (int k = 0; k < 2 && sse < best.sse; ++k) {
                        const std::array<bool, 2> uses =
                            o.coupled ? std::array<bool, 2>{true, true} : std::array<bool, 2>{k == 0, k == 1};
                        const RowFit r = fit_row(u, v, k == 0 ? tx : ty, uses, o.max_scaling);
                        sse += r.sse;
                        sh.b[k] = r.b, sh.c[k] = r.c, sh.e[k] = r.e;
                    }
                }
                if (sse < best.sse) best = {sse, piece};
            }
        }
        return best;
    }

    // The samples with t in [lo, hi]: first and last index.
    std::pair<std::size_t, std::size_t> samples_in(double lo, double hi) const {
        const double slack = 1e-12 * (s.t.back() - s.t.front());
        const std::size_t first =
            std::size_t(std::lower_bound(s.t.begin(), s.t.end(), lo - slack) - s.t.begin());
        const std::size_t end =
            std::size_t(std::upper_bound(s.t.begin(), s.t.end(), hi + slack) - s.t.begin());
        return {first, end == 0 ? 0 : end - 1};
    }
};

} // namespace

void refit_least_squares(FractalFunction& f, const Samples& s, const LeastSquaresOptions& o) {
    const Fitter fitter{s, o};
    for (Piece& p : f.pieces) {
        const auto [first, last] = fitter.samples_in(p.lo, p.hi);
        const Match m = fitter.best(p.lo, p.hi, first, last, {{p.alpha, p.beta}}, p.map.a > 0 ? 0 : 1);
        if (std::isfinite(m.sse)) p = m.piece;
    }
}

void refit_joins(FractalFunction& f, const Samples& s, const LeastSquaresOptions& o, double window) {
    const Fitter fitter{s, o};
    auto collage = [&](const Piece& p) {
        const auto [first, last] = fitter.samples_in(p.lo, p.hi);
        return fitter.best(p.lo, p.hi, first, last, {{p.alpha, p.beta}}, p.map.a > 0 ? 0 : 1);
    };
    for (std::size_t i = 0; i + 1 < f.pieces.size(); ++i) {
        Piece& left = f.pieces[i];
        Piece& right = f.pieces[i + 1];
        const double join = left.hi;
        Match best_left, best_right;
        double best = infinity;
        for (double t : s.t) {
            if (std::abs(t - join) > window || !(t > left.lo) || !(t < right.hi)) continue;
            Piece l = left, r = right;
            set_range(l, l.lo, t);
            set_range(r, t, r.hi);
            const Match ml = collage(l), mr = collage(r);
            if (ml.sse + mr.sse < best) {
                best = ml.sse + mr.sse;
                best_left = ml;
                best_right = mr;
            }
        }
        if (std::isfinite(best)) {
            left = best_left.piece;
            right = best_right.piece;
        }
    }
}

FractalFunction fit_least_squares(const Samples& s, const LeastSquaresOptions& o) {
    using clock = std::chrono::steady_clock;
    const auto started = clock::now();
    auto late = [&] {
        return o.seconds > 0 && std::chrono::duration<double>(clock::now() - started).count() > o.seconds;
    };
    if (o.maps < 2) throw std::invalid_argument("a fit needs at least 2 maps");
    const Fitter fitter{s, o};
    FractalFunction f;
    f.t0 = s.t.front();
    f.t1 = s.t.back();
    f.curve = s.curve();
    const double span = f.t1 - f.t0;
    auto say = [&](const std::string& line) {
        if (o.progress) o.progress(line);
    };

    if (o.recurrent) {
        const int k = o.maps;
        std::vector<double> cut(std::size_t(k) + 1);
        for (int q = 0; q <= k; ++q) cut[std::size_t(q)] = f.t0 + span * q / k;
        std::vector<std::pair<double, double>> domains;
        for (int p = 0; p < k; ++p)
            for (int q = p + 2; q <= k; ++q) domains.emplace_back(cut[std::size_t(p)], cut[std::size_t(q)]);
        for (int r = 0; r < k; ++r) {
            if (late()) throw BudgetExceeded(fmt::format("the fit ran past its budget of {} s", o.seconds));
            const auto [first, last] = fitter.samples_in(cut[std::size_t(r)], cut[std::size_t(r) + 1]);
            const Match m = fitter.best(cut[std::size_t(r)], cut[std::size_t(r) + 1], first, last, domains);
            if (!std::isfinite(m.sse))
                throw std::runtime_error(fmt::format(
                    "range {} of {} holds too few samples for a least-squares fit ({} maps over {} samples)",
                    r + 1, k, k, s.size()));
            f.pieces.push_back(m.piece);
            say(fmt::format("rfif: range {}/{}: squared error {:.4g}", r + 1, k, m.sse));
        }
    } else {
        const int g = std::min(o.grid, int(s.size()) - 1);
        if (o.maps > g)
            throw std::runtime_error(
                fmt::format("{} maps need a grid of at least as many cells (--grid)", o.maps));
        std::vector<double> cut(std::size_t(g) + 1);
        for (int q = 0; q <= g; ++q) cut[std::size_t(q)] = f.t0 + span * q / g;
        std::vector<std::pair<double, double>> domains;
        for (int p = 0; p < g; ++p)
            for (int q = p + 1; q <= g; ++q) domains.emplace_back(cut[std::size_t(p)], cut[std::size_t(q)]);
        // The best match of every candidate range [cut p, cut q] but the whole interval.
        std::vector<Match> table(std::size_t(g + 1) * std::size_t(g + 1));
        std::atomic<bool> out_of_time{false};
        tbb::parallel_for(0, g, [&](int p) {
            for (int q = p + 1; q <= g && !out_of_time; ++q) {
                if (p == 0 && q == g) continue;
                if (late()) out_of_time = true;
                const auto [first, last] = fitter.samples_in(cut[std::size_t(p)], cut[std::size_t(q)]);
                table[std::size_t(p) * std::size_t(g + 1) + std::size_t(q)] =
                    fitter.best(cut[std::size_t(p)], cut[std::size_t(q)], first, last, domains);
            }
        });
        if (out_of_time) throw BudgetExceeded(fmt::format("the fit ran past its budget of {} s", o.seconds));
        say(fmt::format("pfif: {} candidate ranges matched against {} domains", g * (g + 1) / 2 - 1,
                        domains.size()));
        // cost[k][q]: the least total error of k ranges covering [cut 0, cut q].
        const std::size_t width = std::size_t(g) + 1;
        std::vector<double> cost(std::size_t(o.maps + 1) * width, infinity);
        std::vector<int> from(cost.size(), -1);
        cost[0] = 0;
        for (int k = 1; k <= o.maps; ++k)
            for (int q = 1; q <= g; ++q)
                for (int p = 0; p < q; ++p) {
                    const double before = cost[std::size_t(k - 1) * width + std::size_t(p)];
                    const double here = table[std::size_t(p) * width + std::size_t(q)].sse;
                    if (before + here < cost[std::size_t(k) * width + std::size_t(q)]) {
                        cost[std::size_t(k) * width + std::size_t(q)] = before + here;
                        from[std::size_t(k) * width + std::size_t(q)] = p;
                    }
                }
        if (!std::isfinite(cost[std::size_t(o.maps) * width + std::size_t(g)]))
            throw std::runtime_error(fmt::format(
                "no partition into {} ranges fits: the ranges hold too few samples ({} samples, grid of {})",
                o.maps, s.size(), g));
        for (int k = o.maps, q = g; k > 0; --k) {
            const int p = from[std::size_t(k) * width + std::size_t(q)];
            f.pieces.push_back(table[std::size_t(p) * width + std::size_t(q)].piece);
            q = p;
        }
        std::reverse(f.pieces.begin(), f.pieces.end());
        say(fmt::format("pfif: {} ranges, total squared collage error {:.4g}", o.maps,
                        cost[std::size_t(o.maps) * width + std::size_t(g)]));
    }
    const std::string why = make_consistent(f, 1e-9 * span);
    if (!why.empty()) throw std::runtime_error("the fitted maps do not make a fractal function: " + why);
    return f;
}

} // namespace frac::rt::fit
