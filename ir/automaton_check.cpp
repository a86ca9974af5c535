#include "ir/automaton_check.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>

namespace frac::ir {

namespace {

using num::Interval;
using num::Matrix;
using num::Rational;

AutomatonProblem problem(AutomatonProblem::Kind kind, std::optional<std::size_t> state,
                         std::optional<std::size_t> arc, std::string message, bool warning = false) {
    AutomatonProblem p;
    p.severity = warning ? AutomatonProblem::Severity::warning : AutomatonProblem::Severity::error;
    p.kind = kind;
    p.state = state;
    p.arc = arc;
    p.message = std::move(message);
    return p;
}

std::string arc_title(const Automaton& a, std::size_t i) {
    const Arc& arc = a.arcs[i];
    return fmt::format("arc {} ({} -> {})", arc_name(a, i), a.states[arc.from].name, a.states[arc.to].name);
}

} // namespace

// For any x > 0 and M >= 0: min (Mx)_i / x_i <= rho(M) <= max (Mx)_i / x_i.
Interval spectral_radius_bracket(const Matrix<Interval>& m) {
    const std::size_t n = m.rows();
    if (n == 0) return {0.0, 0.0};
    // Power iteration on M + I (aperiodic, same Perron vector) with the midpoints, round to nearest.
    std::vector<double> x(n, 1.0), y(n);
    for (int it = 0; it < 20000; ++it) {
        double norm = 0;
        for (std::size_t i = 0; i < n; ++i) {
            double s = x[i];
            for (std::size_t j = 0; j < n; ++j) s += num::midpoint(m(i, j)) * x[j];
            y[i] = s;
            norm = std::max(norm, s);
        }
        double change = 0;
        for (std::size_t i = 0; i < n; ++i) {
            // Keep every entry positive: a zero entry would make the quotient useless.
            const double v = std::max(y[i] / norm, 1e-300);
            change = std::max(change, std::abs(v - x[i]));
            x[i] = v;
        }
        if (change < 1e-17) break;
    }
    const num::UpwardRounding up;
    double lo = num::inf, hi = 0;
    for (std::size_t i = 0; i < n; ++i) {
        Interval s(0.0);
        for (std::size_t j = 0; j < n; ++j) s = num::add(s, num::mul(m(i, j), Interval(x[j])));
        const Interval q = num::div(s, Interval(x[i]));
        lo = std::min(lo, q.lo);
        hi = std::max(hi, q.hi);
    }
    return {std::max(lo, 0.0), hi};
}

namespace {

// Largest eigenvalue modulus of a double matrix, estimated from ||P^(2^k)||^(1/2^k).
double spectral_radius_estimate(Matrix<double> p) {
    const std::size_t n = p.rows();
    if (n == 0) return 0;
    double log_scale = 0; // log of the factor divided out so far, per unit power
    double power = 1;
    for (int k = 0; k < 12; ++k) {
        double norm = 0;
        for (std::size_t i = 0; i < n; ++i)
            for (std::size_t j = 0; j < n; ++j) norm = std::max(norm, std::abs(p(i, j)));
        if (norm == 0) return 0;
        for (std::size_t i = 0; i < n; ++i)
            for (std::size_t j = 0; j < n; ++j) p(i, j) /= norm;
        log_scale += std::log(norm) / power;
        p = p * p;
        power *= 2;
    }
    double norm = 0;
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < n; ++j) norm = std::max(norm, std::abs(p(i, j)));
    if (norm == 0) return 0;
    return std::exp(log_scale + std::log(norm) / power);
}

Matrix<double> nearest(const Matrix<Interval>& m) {
    Matrix<double> out(m.rows(), m.cols());
    for (std::size_t r = 0; r < m.rows(); ++r)
        for (std::size_t c = 0; c < m.cols(); ++c) out(r, c) = num::midpoint(m(r, c));
    return out;
}

} // namespace

std::string arc_name(const Automaton& a, std::size_t arc) {
    const std::string& label = a.arcs.at(arc).label;
    return label.empty() ? fmt::format("#{}", arc) : label;
}

std::string path_text(const Automaton& a, const std::vector<std::size_t>& arcs) {
    if (arcs.empty()) return a.states.at(a.initial).name;
    std::string out = a.states.at(a.arcs.at(arcs.front()).from).name;
    for (std::size_t i : arcs)
        out += fmt::format(" -{}-> {}", arc_name(a, i), a.states.at(a.arcs.at(i).to).name);
    return out;
}

Matrix<Rational> direction_basis(Space s) {
    const std::size_t d = static_cast<std::size_t>(s.dimension), n = d + 1;
    Matrix<Rational> b(n, d);
    for (std::size_t i = 0; i < d; ++i) {
        b(i, i) = 1;
        // bary(n): e_i - e_n, so that the weights still sum to zero.
        if (s.kind == Space::Kind::barycentric) b(n - 1, i) = -1;
    }
    return b;
}

Matrix<Rational> direction_coordinates(Space s) {
    const std::size_t d = static_cast<std::size_t>(s.dimension);
    Matrix<Rational> c(d, d + 1);
    for (std::size_t i = 0; i < d; ++i) c(i, i) = 1;
    return c;
}

Matrix<Interval> linear_part(const Automaton& a, std::size_t arc) {
    const Arc& t = a.arcs.at(arc);
    return num::enclose(direction_coordinates(a.states.at(t.from).space)) * t.op.enclosure *
           num::enclose(direction_basis(a.states.at(t.to).space));
}

std::optional<Matrix<Rational>> exact_linear_part(const Automaton& a, std::size_t arc) {
    const Arc& t = a.arcs.at(arc);
    if (!t.op.exact) return std::nullopt;
    return direction_coordinates(a.states.at(t.from).space) * *t.op.exact *
           direction_basis(a.states.at(t.to).space);
}

std::vector<bool> reachable_states(const Automaton& a) {
    std::vector<bool> seen(a.states.size(), false);
    if (a.initial >= a.states.size()) return seen;
    std::vector<std::size_t> stack{a.initial};
    seen[a.initial] = true;
    while (!stack.empty()) {
        const std::size_t s = stack.back();
        stack.pop_back();
        for (const Arc& arc : a.arcs)
            if (arc.from == s && arc.to < a.states.size() && !seen[arc.to]) {
                seen[arc.to] = true;
                stack.push_back(arc.to);
            }
    }
    return seen;
}

std::vector<int> strongly_connected_components(const Automaton& a, const std::vector<bool>& keep,
                                               int* count) {
    const std::size_t n = a.states.size();
    auto kept = [&](std::size_t s) { return keep.empty() || keep[s]; };
    std::vector<std::vector<std::size_t>> next(n);
    for (const Arc& arc : a.arcs)
        if (arc.from < n && arc.to < n && kept(arc.from) && kept(arc.to)) next[arc.from].push_back(arc.to);
    // Tarjan's algorithm, iterative so deep automata cannot overflow the stack.
    std::vector<int> index(n, -1), low(n, 0), comp(n, -1);
    std::vector<bool> on_stack(n, false);
    std::vector<std::size_t> stack;
    int counter = 0, components = 0;
    for (std::size_t root = 0; root < n; ++root) {
        if (!kept(root) || index[root] >= 0) continue;
        std::vector<std::pair<std::size_t, std::size_t>> work{{root, 0}};
        index[root] = low[root] = counter++;
        stack.push_back(root);
        on_stack[root] = true;
        while (!work.empty()) {
            auto& [v, k] = work.back();
            if (k < next[v].size()) {
                const std::size_t w = next[v][k++];
                if (index[w] < 0) {
                    index[w] = low[w] = counter++;
                    stack.push_back(w);
                    on_stack[w] = true;
                    work.emplace_back(w, 0);
                } else if (on_stack[w]) {
                    low[v] = std::min(low[v], index[w]);
                }
                continue;
            }
            if (low[v] == index[v]) {
                std::size_t w;
                do {
                    w = stack.back();
                    stack.pop_back();
                    on_stack[w] = false;
                    comp[w] = components;
                } while (w != v);
                ++components;
            }
            const std::size_t done = v;
            work.pop_back();
            if (!work.empty()) low[work.back().first] = std::min(low[work.back().first], low[done]);
        }
    }
    if (count) *count = components;
    return comp;
}

// The induced 1-norm (largest column sum of magnitudes) or max-norm (largest row sum), rounded up.
// The operator norm, rounded up, of a linear part L (direction coordinates, see direction_basis) when
// every space's directions carry the 1-norm of their full coordinates: for bary(n) the zero-sum
// weights x = (y, -sum y), |x|_1 = |y|_1 + |sum y|. The extreme points of a unit ball are +-e_j
// (euclidean) or (e_j - e_k) / 2 (barycentric), so the norm is the largest image norm among them
// (for bary, Dobrushin's ergodicity coefficient of the full matrix).
static double zero_sum_l1_upper(const Matrix<Interval>& m, bool target_bary, bool source_bary) {
    const num::UpwardRounding up;
    const auto image_norm = [&](std::size_t j, std::optional<std::size_t> k) { // |L e_j - L e_k|
        double sum = 0;
        Interval total(0.0);
        for (std::size_t r = 0; r < m.rows(); ++r) {
            const Interval v = k ? num::sub(m(r, j), m(r, *k)) : m(r, j);
            sum = num::add(Interval(sum), Interval(num::magnitude(v))).hi;
            total = num::add(total, v);
        }
        return target_bary ? num::add(Interval(sum), Interval(num::magnitude(total))).hi : sum;
    };
    double best = 0;
    for (std::size_t j = 0; j < m.cols(); ++j) {
        if (!source_bary) {
            best = std::max(best, image_norm(j, std::nullopt));
            continue;
        }
        // e_j - e_n has coordinates e_j; e_j - e_k (k < n) has e_j - e_k; each of 1-norm 2.
        best = std::max(best, num::mul(Interval(image_norm(j, std::nullopt)), Interval(0.5)).hi);
        for (std::size_t k = j + 1; k < m.cols(); ++k)
            best = std::max(best, num::mul(Interval(image_norm(j, k)), Interval(0.5)).hi);
    }
    return best;
}

static double induced_norm_upper(const Matrix<Interval>& m, bool rows) {
    const num::UpwardRounding up;
    double best = 0;
    const std::size_t outer = rows ? m.rows() : m.cols(), inner = rows ? m.cols() : m.rows();
    for (std::size_t i = 0; i < outer; ++i) {
        double sum = 0;
        for (std::size_t j = 0; j < inner; ++j)
            sum = num::add(Interval(sum), Interval(num::magnitude(rows ? m(i, j) : m(j, i)))).hi;
        best = std::max(best, sum);
    }
    return best;
}

double norm2_upper(const Matrix<Interval>& m) {
    if (m.rows() == 0 || m.cols() == 0) return 0;
    const Matrix<Interval> g = num::transpose(m) * m; // outward rounded
    const num::UpwardRounding up;
    double gershgorin = 0;
    for (std::size_t i = 0; i < g.rows(); ++i) {
        double row = std::max(g(i, i).hi, 0.0);
        for (std::size_t j = 0; j < g.cols(); ++j)
            if (j != i) row = num::add(Interval(row), Interval(num::magnitude(g(i, j)))).hi;
        gershgorin = std::max(gershgorin, row);
    }
    double frobenius = 0;
    for (std::size_t r = 0; r < m.rows(); ++r)
        for (std::size_t c = 0; c < m.cols(); ++c) {
            const double v = num::magnitude(m(r, c));
            frobenius = num::add(Interval(frobenius), num::mul(Interval(v), Interval(v))).hi;
        }
    return num::sqrt(Interval(std::min(gershgorin, frobenius))).hi;
}

ContractivityResult prove_contractive(const Automaton& a, const ContractivityOptions& options) {
    const std::size_t n = a.states.size();
    if (a.initial >= n) throw std::invalid_argument("prove_contractive: the initial state does not exist");
    for (const Arc& arc : a.arcs)
        if (arc.from >= n || arc.to >= n)
            throw std::invalid_argument("prove_contractive: an arc leads nowhere");
    const std::vector<bool> live = reachable_states(a);
    std::vector<std::size_t> arcs;
    std::vector<Matrix<Interval>> lin(a.arcs.size());
    for (std::size_t i = 0; i < a.arcs.size(); ++i) {
        const Arc& arc = a.arcs[i];
        if (!live[arc.from]) continue;
        if (arc.op.rows() != static_cast<std::size_t>(a.states[arc.from].space.coordinates()) ||
            arc.op.cols() != static_cast<std::size_t>(a.states[arc.to].space.coordinates()))
            throw std::invalid_argument("prove_contractive: " + arc_title(a, i) + " has the wrong size");
        lin[i] = linear_part(a, i);
        arcs.push_back(i);
    }
    std::vector<std::vector<std::size_t>> out(n);
    for (std::size_t i : arcs) out[a.arcs[i].from].push_back(i);
    int components = 0;
    const std::vector<int> comp = strongly_connected_components(a, live, &components);

    ContractivityResult result;
    double cube = 1; // d^3 for the largest direction dimension d: the cost of one product
    for (std::size_t i : arcs) cube = std::max(cube, std::pow(static_cast<double>(lin[i].rows()), 3.0));
    // Paths of length L from each state, counted in doubles to respect the product budget.
    std::vector<double> paths(n, 1.0);
    std::size_t products = 0;
    double best_bound = num::inf;
    int tried = 0; // the longest length whose paths were all bounded
    for (int length = 1; length <= options.max_length; ++length) {
        std::vector<double> more(n, 0.0);
        double total = 0;
        for (std::size_t s = 0; s < n; ++s) {
            for (std::size_t i : out[s]) more[s] += paths[a.arcs[i].to];
            total += more[s];
        }
        paths = more;
        if (static_cast<double>(products) + total > static_cast<double>(options.max_products) ||
            (static_cast<double>(products) + total) * cube > options.max_work)
            break;
        products += static_cast<std::size_t>(total);
        result.work = static_cast<double>(products) * cube;
        // M_L[a][b]: the largest bound over the paths a -> ... -> b of this length, in each of four
        // norm families (every state's direction coordinates with the 2-norm, the 1-norm or the max-norm,
        // or its full coordinates with the 1-norm): a family is one norm per state, so its products
        // bound composites; the proof takes whichever family gives the smaller spectral radius.
        Matrix<Interval> family[4] = {Matrix<Interval>(n, n), Matrix<Interval>(n, n), Matrix<Interval>(n, n),
                                      Matrix<Interval>(n, n)};
        std::vector<Matrix<Interval>> prefix(static_cast<std::size_t>(length) + 1);
        std::function<void(std::size_t, std::size_t, int)> walk = [&](std::size_t start, std::size_t s,
                                                                      int depth) {
            if (depth == length) {
                const Matrix<Interval>& p = prefix[static_cast<std::size_t>(depth)];
                const auto bary = [&](std::size_t state) {
                    return a.states[state].space.kind == Space::Kind::barycentric;
                };
                const double bounds[std::size(family)] = {norm2_upper(p), induced_norm_upper(p, false),
                                                          induced_norm_upper(p, true),
                                                          zero_sum_l1_upper(p, bary(start), bary(s))};
                for (std::size_t f = 0; f < std::size(family); ++f) {
                    const double v = std::max(family[f](start, s).hi, bounds[f]);
                    family[f](start, s) = Interval(v, v);
                }
                return;
            }
            for (std::size_t i : out[s]) {
                prefix[static_cast<std::size_t>(depth) + 1] =
                    depth == 0 ? lin[i] : prefix[static_cast<std::size_t>(depth)] * lin[i];
                walk(start, a.arcs[i].to, depth + 1);
            }
        };
        for (std::size_t s = 0; s < n; ++s)
            if (live[s]) walk(s, s, 0);
        // rho(M_L) is the largest over the diagonal blocks of the strongly connected components.
        double rho = num::inf;
        for (const Matrix<Interval>& m : family) {
            double family_rho = 0;
            for (int c = 0; c < components; ++c) {
                std::vector<std::size_t> members;
                for (std::size_t s = 0; s < n; ++s)
                    if (comp[s] == c) members.push_back(s);
                Matrix<Interval> block(members.size(), members.size());
                for (std::size_t i = 0; i < members.size(); ++i)
                    for (std::size_t j = 0; j < members.size(); ++j) block(i, j) = m(members[i], members[j]);
                family_rho = std::max(family_rho, spectral_radius_bracket(block).hi);
            }
            rho = std::min(rho, family_rho);
        }
        best_bound = std::min(best_bound, rho);
        tried = length;
        if (rho < 1.0) {
            result.proven = true;
            result.bound = rho;
            result.length = length;
            {
                const num::UpwardRounding up;
                result.per_step = num::pow(Interval(rho), num::div(Interval(1.0), Interval(length))).hi;
            }
            result.method = length == 1
                                ? "spectral radius of the matrix of Lipschitz bounds per arc"
                                : fmt::format("spectral radius of the matrix of Lipschitz bounds of the "
                                              "composite operators along all paths of length {}",
                                              length);
            result.message = fmt::format("contractive: {} <= {:.6g} < 1 (at most {:.6g} per transition)",
                                         result.method, rho, result.per_step);
            return result;
        }
    }

    // Refusal: find the simple cycle that contracts slowest (spectral radius of its product, per step).
    std::vector<std::size_t> path;
    std::vector<bool> on_path(n, false);
    double worst = -1;
    std::size_t cycles = 0, steps = 0;
    std::function<void(std::size_t, std::size_t, const Matrix<double>&)> search =
        [&](std::size_t start, std::size_t s, const Matrix<double>& product) {
            // Bounded search: enough to name a cycle, never exponential in the automaton's size.
            if (cycles > 20000 || ++steps > 400000) return;
            for (std::size_t i : out[s]) {
                const std::size_t t = a.arcs[i].to;
                if (t < start || (t != start && on_path[t])) continue;
                const Matrix<double> p = path.empty() ? nearest(lin[i]) : product * nearest(lin[i]);
                path.push_back(i);
                if (t == start) {
                    ++cycles;
                    const double rate =
                        std::pow(spectral_radius_estimate(p), 1.0 / static_cast<double>(path.size()));
                    if (rate > worst) {
                        worst = rate;
                        result.cycle = path;
                    }
                } else if (static_cast<int>(path.size()) < std::max(options.max_length, 1)) {
                    on_path[t] = true;
                    search(start, t, p);
                    on_path[t] = false;
                }
                path.pop_back();
            }
        };
    for (std::size_t s = 0; s < n; ++s)
        if (live[s]) {
            on_path[s] = true;
            search(s, s, Matrix<double>());
            on_path[s] = false;
        }
    result.cycle_rate = std::max(worst, 0.0);
    result.method = "spectral radius of the matrix of Lipschitz bounds along paths";
    if (!result.cycle.empty() && worst >= 1.0) {
        result.message =
            fmt::format("not contractive: the cycle {} does not contract (the spectral radius of its "
                        "composite operator is about {:.6g} per transition)",
                        path_text(a, result.cycle), worst);
    } else if (!result.cycle.empty()) {
        result.message = fmt::format("could not prove contraction with paths up to length {} (best bound "
                                     "{:.6g}); the slowest cycle is {}, "
                                     "contracting by about {:.6g} per transition",
                                     tried, best_bound, path_text(a, result.cycle), worst);
    } else {
        result.message = fmt::format(
            "could not prove contraction with paths up to length {} (best bound {:.6g})", tried, best_bound);
    }
    return result;
}

std::vector<AutomatonProblem> check_automaton(const Automaton& a, const ContractivityOptions& options,
                                              ContractivityResult* proof) {
    using K = AutomatonProblem::Kind;
    std::vector<AutomatonProblem> problems;
    const std::size_t n = a.states.size();
    if (n == 0) {
        problems.push_back(problem(K::structure, std::nullopt, std::nullopt, "the automaton has no states"));
        return problems;
    }
    if (a.initial >= n)
        problems.push_back(
            problem(K::structure, std::nullopt, std::nullopt, "the initial state does not exist"));
    for (std::size_t s = 0; s < n; ++s) {
        const Space sp = a.states[s].space;
        if (sp.dimension < 0 || (sp.kind == Space::Kind::euclidean && sp.dimension < 1))
            problems.push_back(problem(K::structure, s, std::nullopt,
                                       fmt::format("state {} has an invalid space", a.states[s].name)));
    }
    for (std::size_t i = 0; i < a.arcs.size(); ++i) {
        const Arc& arc = a.arcs[i];
        if (arc.from >= n || arc.to >= n)
            problems.push_back(
                problem(K::structure, std::nullopt, i,
                        fmt::format("arc {} connects a state that does not exist", arc_name(a, i))));
    }
    if (!problems.empty()) return problems;

    // Sizes and the affine condition, arc by arc.
    bool arcs_ok = true;
    for (std::size_t i = 0; i < a.arcs.size(); ++i) {
        const Arc& arc = a.arcs[i];
        const Space from = a.states[arc.from].space, to = a.states[arc.to].space;
        const std::size_t rows = static_cast<std::size_t>(from.coordinates()),
                          cols = static_cast<std::size_t>(to.coordinates());
        const bool consistent = arc.op.nearest.rows() == arc.op.enclosure.rows() &&
                                arc.op.nearest.cols() == arc.op.enclosure.cols() &&
                                (!arc.op.exact || (arc.op.exact->rows() == arc.op.enclosure.rows() &&
                                                   arc.op.exact->cols() == arc.op.enclosure.cols()));
        if (!consistent || arc.op.rows() != rows || arc.op.cols() != cols) {
            problems.push_back(problem(
                K::size, arc.from, i,
                fmt::format(
                    "{}: the operator maps {} into {}, so it needs {} rows and {} columns, not {} x {}",
                    arc_title(a, i), space_name(to), space_name(from), rows, cols, arc.op.rows(),
                    arc.op.cols())));
            arcs_ok = false;
            continue;
        }
        bool finite = true;
        for (std::size_t r = 0; r < rows; ++r)
            for (std::size_t c = 0; c < cols; ++c)
                finite = finite && std::isfinite(arc.op.enclosure(r, c).lo) &&
                         std::isfinite(arc.op.enclosure(r, c).hi);
        if (!finite) {
            problems.push_back(
                problem(K::size, arc.from, i,
                        fmt::format("{}: the operator has an entry that is not finite", arc_title(a, i))));
            arcs_ok = false;
            continue;
        }
        // w_from^T T = w_to^T, column by column.
        const Matrix<Rational> wf = affine_functional(from), wt = affine_functional(to);
        for (std::size_t c = 0; c < cols; ++c) {
            std::string got;
            bool bad = false;
            if (arc.op.exact) {
                Rational s;
                for (std::size_t r = 0; r < rows; ++r) s += wf(0, r) * (*arc.op.exact)(r, c);
                bad = s != wt(0, c);
                got = s.to_string();
            } else {
                const num::UpwardRounding up;
                Interval s(0.0);
                for (std::size_t r = 0; r < rows; ++r)
                    s = num::add(s, num::mul(num::enclose(wf(0, r)), arc.op.enclosure(r, c)));
                bad = !s.contains(wt(0, c).to_double());
                got = s.is_thin() ? fmt::format("{}", s.lo) : fmt::format("[{}, {}]", s.lo, s.hi);
            }
            if (!bad) continue;
            std::string what;
            if (from.kind == Space::Kind::barycentric)
                what = fmt::format("column {} sums to {}, not {} (barycentric columns sum to 1)", c + 1, got,
                                   wt(0, c).to_string());
            else
                what = fmt::format("the last row has {} in column {} where an affine map of {} needs {}", got,
                                   c + 1, space_name(from), wt(0, c).to_string());
            problems.push_back(
                problem(K::affine, arc.from, i, fmt::format("{}: not affine: {}", arc_title(a, i), what)));
            arcs_ok = false;
            break;
        }
        if (arc.probability && !(std::isfinite(*arc.probability) && *arc.probability >= 0))
            problems.push_back(
                problem(K::probability, arc.from, i,
                        fmt::format("{}: the probability {} is not a finite non-negative number",
                                    arc_title(a, i), *arc.probability)));
    }
    if (a.projection && a.initial < n) {
        const Space init = a.states[a.initial].space;
        const Operator& p = *a.projection;
        if (init.kind != Space::Kind::barycentric) {
            problems.push_back(
                problem(K::structure, a.initial, std::nullopt,
                        fmt::format("the projection by control points needs a barycentric initial "
                                    "state, and {} is {}",
                                    a.states[a.initial].name, space_name(init))));
        } else if (p.cols() != static_cast<std::size_t>(init.coordinates()) || p.rows() < 2) {
            problems.push_back(
                problem(K::size, a.initial, std::nullopt,
                        fmt::format("the projection of {} needs {} control points (columns), not {}",
                                    space_name(init), init.coordinates(), p.cols())));
        } else {
            for (std::size_t c = 0; c < p.cols(); ++c) {
                const Interval w =
                    p.exact ? num::enclose((*p.exact)(p.rows() - 1, c)) : p.enclosure(p.rows() - 1, c);
                if (!w.contains(1.0)) {
                    problems.push_back(problem(
                        K::affine, a.initial, std::nullopt,
                        fmt::format(
                            "the projection's control point {} is not a point (its homogeneous coordinate "
                            "is not 1)",
                            c + 1)));
                    break;
                }
            }
        }
    }
    // Probabilities: every arc of a state or none.
    for (std::size_t s = 0; s < n; ++s) {
        std::size_t given = 0, total = 0;
        for (const Arc& arc : a.arcs)
            if (arc.from == s) {
                ++total;
                given += arc.probability ? 1 : 0;
            }
        if (given != 0 && given != total)
            problems.push_back(
                problem(K::probability, s, std::nullopt,
                        fmt::format("state {}: {} of its {} transitions have a probability; give one "
                                    "for every transition or for none",
                                    a.states[s].name, given, total)));
    }
    const std::vector<bool> live = reachable_states(a);
    for (std::size_t s = 0; s < n; ++s) {
        bool leaves = false;
        for (const Arc& arc : a.arcs) leaves = leaves || arc.from == s;
        if (!live[s]) {
            problems.push_back(problem(K::unreachable, s, std::nullopt,
                                       fmt::format("state {} is unreachable from the initial state {}",
                                                   a.states[s].name, a.states[a.initial].name),
                                       true));
        } else if (!leaves) {
            problems.push_back(
                problem(K::dead_end, s, std::nullopt,
                        fmt::format("state {} has no transitions, so its attractor would be empty",
                                    a.states[s].name)));
        }
    }
    const bool errors = std::any_of(problems.begin(), problems.end(), [](const AutomatonProblem& p) {
        return p.severity == AutomatonProblem::Severity::error;
    });
    if (!arcs_ok || errors) return problems;

    ContractivityResult r = prove_contractive(a, options);
    if (!r.proven) {
        std::optional<std::size_t> arc, state;
        if (!r.cycle.empty()) {
            arc = r.cycle.front();
            state = a.arcs[r.cycle.front()].from;
        }
        problems.push_back(problem(K::contractivity, state, arc, r.message));
    }
    if (proof) *proof = std::move(r);
    return problems;
}

} // namespace frac::ir
