#include "runtime/automata/analysis.hpp"

#include "ir/automaton_check.hpp"

#include <Eigen/Dense>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>

namespace frac::rt {

namespace {

using num::Interval;
using num::Matrix;
using num::Rational;
using IVector = std::vector<Interval>;

// ---- The Krawczyk test. Unknowns z = (a, α) for a real eigenpair, z = (a, b, α, β) for a complex one
// (v = a + i b, λ = α + i β); equations T v = λ v on real and imaginary parts, and c^T v = 1.

struct EigenSystem {
    const Matrix<Interval>& t;
    std::vector<double> c; // the normalisation row
    bool complex;
    std::size_t n() const { return t.rows(); }
    std::size_t unknowns() const { return complex ? 2 * n() + 2 : n() + 1; }
};

// F(z) with outward rounding (under UpwardRounding).
IVector residual(const EigenSystem& s, const IVector& z) {
    const std::size_t n = s.n(), m = s.complex ? 2 * n : n;
    const Interval alpha = z[m], beta = s.complex ? z[m + 1] : Interval(0.0);
    auto b = [&](std::size_t i) { return s.complex ? z[n + i] : Interval(0.0); };
    IVector f(s.unknowns(), Interval(0.0));
    for (std::size_t i = 0; i < n; ++i) {
        Interval ta(0.0), tb(0.0);
        for (std::size_t j = 0; j < n; ++j) {
            ta = num::add(ta, num::mul(s.t(i, j), z[j]));
            if (s.complex) tb = num::add(tb, num::mul(s.t(i, j), b(j)));
        }
        f[i] = num::add(num::sub(ta, num::mul(alpha, z[i])), num::mul(beta, b(i)));
        if (s.complex) f[n + i] = num::sub(num::sub(tb, num::mul(beta, z[i])), num::mul(alpha, b(i)));
    }
    Interval ca(-1.0), cb(0.0);
    for (std::size_t j = 0; j < n; ++j) {
        ca = num::add(ca, num::mul(Interval(s.c[j]), z[j]));
        if (s.complex) cb = num::add(cb, num::mul(Interval(s.c[j]), b(j)));
    }
    f[m] = ca;
    if (s.complex) f[m + 1] = cb;
    return f;
}

// The Jacobian of F over the box z (its entries are affine in z, so this encloses every Jacobian there).
Matrix<Interval> jacobian(const EigenSystem& s, const IVector& z) {
    const std::size_t n = s.n(), m = s.complex ? 2 * n : n;
    Matrix<Interval> j(s.unknowns(), s.unknowns());
    const Interval alpha = z[m];
    for (std::size_t r = 0; r < n; ++r) {
        for (std::size_t k = 0; k < n; ++k) {
            j(r, k) = s.t(r, k);
            if (s.complex) j(n + r, n + k) = s.t(r, k);
        }
        j(r, r) = num::sub(s.t(r, r), alpha);
        j(r, m) = num::neg(z[r]);
        if (s.complex) {
            const Interval beta = z[m + 1];
            j(n + r, n + r) = j(r, r);
            j(r, n + r) = beta;
            j(n + r, r) = num::neg(beta);
            j(r, m + 1) = z[n + r];
            j(n + r, m) = num::neg(z[n + r]);
            j(n + r, m + 1) = num::neg(z[r]);
        }
    }
    for (std::size_t k = 0; k < n; ++k) {
        j(m, k) = Interval(s.c[k]);
        if (s.complex) j(m + 1, n + k) = Interval(s.c[k]);
    }
    return j;
}

Matrix<Interval> times(const Matrix<Interval>& a, const IVector& v) {
    return a * Matrix<Interval>::column(v);
}

// Krawczyk with ε-inflation (Rump): a box z~ + Y with K(Y) = -R F(z~) + (I - R J(z~ + Y)) Y inside the
// interior of Y holds exactly one zero of F. Returns z~ + K, or nullopt.
std::optional<IVector> krawczyk(const EigenSystem& s, const std::vector<double>& approx) {
    const std::size_t u = s.unknowns();
    // R ~ J(z~)^-1, in doubles (any R works; a good one makes the test succeed).
    IVector point(approx.begin(), approx.end());
    Eigen::MatrixXd jmid(u, u);
    {
        const Matrix<Interval> j0 = [&] {
            num::UpwardRounding up;
            return jacobian(s, point);
        }();
        for (std::size_t r = 0; r < u; ++r)
            for (std::size_t k = 0; k < u; ++k) jmid(r, k) = num::midpoint(j0(r, k));
    }
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(jmid);
    if (!lu.isInvertible()) return std::nullopt;
    const Eigen::MatrixXd rinv = lu.inverse();
    if (!rinv.allFinite()) return std::nullopt;
    Matrix<Interval> r(u, u);
    for (std::size_t i = 0; i < u; ++i)
        for (std::size_t k = 0; k < u; ++k) r(i, k) = Interval(rinv(i, k));

    num::UpwardRounding up;
    const Matrix<Interval> rf = times(r, residual(s, point));
    IVector z0(u), y(u);
    for (std::size_t i = 0; i < u; ++i) z0[i] = y[i] = num::neg(rf(i, 0));
    const Matrix<Interval> identity = Matrix<Interval>::identity(u);
    for (int iteration = 0; iteration < 12; ++iteration) {
        for (Interval& yi : y) { // inflate: 10% of the width and a tiny absolute margin
            const double grow = num::mul(Interval(num::width(yi)), Interval(0.1)).hi + 1e-290;
            yi = Interval(num::sub(Interval(yi.lo), Interval(grow)).lo,
                          num::add(Interval(yi.hi), Interval(grow)).hi);
        }
        IVector box(u);
        for (std::size_t i = 0; i < u; ++i) box[i] = num::add(point[i], y[i]);
        const Matrix<Interval> c = identity - r * jacobian(s, box);
        const Matrix<Interval> cy = times(c, y);
        IVector k(u);
        bool inside = true;
        for (std::size_t i = 0; i < u; ++i) {
            k[i] = num::add(z0[i], cy(i, 0));
            if (k[i].is_empty() || !(y[i].lo < k[i].lo && k[i].hi < y[i].hi)) inside = false;
        }
        if (inside) {
            for (std::size_t i = 0; i < u; ++i) k[i] = num::add(point[i], k[i]);
            return k;
        }
        y = k;
    }
    return std::nullopt;
}

IVector enclose_vector(const std::vector<Rational>& x) {
    IVector out;
    for (const Rational& r : x) out.push_back(num::enclose(r));
    return out;
}

// ---- Exact side.

Rational evaluate(const std::vector<Rational>& p, const Rational& x) {
    Rational v;
    for (auto it = p.rbegin(); it != p.rend(); ++it) v = v * x + *it;
    return v;
}

std::vector<Rational> derivative(const std::vector<Rational>& p) {
    std::vector<Rational> d;
    for (std::size_t i = 1; i < p.size(); ++i) d.push_back(p[i] * Rational(static_cast<long>(i)));
    return d;
}

// The convergents of x's continued fraction in order; the first inside [lo, hi] is the simplest
// candidate for a rational there.
std::optional<Rational> simple_rational_in(double x, double lo, double hi) {
    if (!std::isfinite(x) || !std::isfinite(lo) || !std::isfinite(hi)) return std::nullopt;
    const Rational rlo = Rational::from_double(lo), rhi = Rational::from_double(hi);
    Rational rest = Rational::from_double(x);
    mpz_class p0 = 1, q0 = 0, p1 = 0, q1 = 1; // h(-1)/k(-1), h(-2)/k(-2)
    std::swap(p0, p1);
    std::swap(q0, q1);
    for (int step = 0; step < 40; ++step) {
        mpz_class a;
        mpz_fdiv_q(a.get_mpz_t(), rest.numerator().get_mpz_t(), rest.denominator().get_mpz_t());
        const mpz_class p = a * p1 + p0, q = a * q1 + q0;
        const Rational candidate{mpq_class(p, q)};
        if (rlo <= candidate && candidate <= rhi) return candidate;
        const Rational fraction = rest - Rational{mpq_class(a)};
        if (fraction.is_zero()) return std::nullopt;
        rest = Rational(1) / fraction;
        p0 = p1, q0 = q1, p1 = p, q1 = q;
    }
    return std::nullopt;
}

// The eigenvector of the exact eigenvalue r when its eigenspace is one-dimensional, scaled so that its
// last nonzero entry is 1 (the fixed point: to sum 1).
std::optional<std::vector<Rational>> exact_eigenvector(const Matrix<Rational>& t, const Rational& r,
                                                       bool sum_one) {
    Matrix<Rational> shifted = t;
    for (std::size_t i = 0; i < t.rows(); ++i) shifted(i, i) = shifted(i, i) - r;
    const Matrix<Rational> kernel = num::nullspace(shifted);
    if (kernel.cols() != 1) return std::nullopt;
    std::vector<Rational> v(t.rows());
    Rational scale;
    for (std::size_t i = 0; i < v.size(); ++i) {
        v[i] = kernel(i, 0);
        if (sum_one)
            scale += v[i];
        else if (!v[i].is_zero())
            scale = v[i];
    }
    if (scale.is_zero()) return std::nullopt;
    for (Rational& x : v) x /= scale;
    return v;
}

int geometric_multiplicity(const Matrix<Rational>& t, const Rational& r) {
    Matrix<Rational> shifted = t;
    for (std::size_t i = 0; i < t.rows(); ++i) shifted(i, i) = shifted(i, i) - r;
    return static_cast<int>(t.rows() - num::rank(shifted));
}

// Marks a as the exact eigenvalue r of the polynomial p when p(r) = 0, with its multiplicity.
void recognise(Eigenpair& e, const std::vector<Rational>& p, const Matrix<Rational>& t, bool fixed) {
    // A multiple root: the double approximation is only good to about sqrt(eps), and may even come as
    // a complex pair with a tiny imaginary part.
    const double tol = 1e-6 * std::max(1.0, std::abs(e.re));
    if (e.is_complex() && (e.verified || std::abs(e.im) > tol)) return;
    std::optional<Rational> r;
    if (fixed)
        r = Rational(1);
    else if (e.verified)
        r = simple_rational_in(e.re, e.value_re.lo, e.value_re.hi);
    else
        r = simple_rational_in(e.re, e.re - tol, e.re + tol);
    if (!r || !evaluate(p, *r).is_zero()) return;
    e.exact = *r;
    e.im = 0;
    e.multiplicity = 0;
    for (std::vector<Rational> q = p; !q.empty() && evaluate(q, *r).is_zero(); q = derivative(q))
        ++e.multiplicity;
    e.geometric = geometric_multiplicity(t, *r);
    e.exact_vector = exact_eigenvector(t, *r, fixed);
    e.value_re = num::enclose(*r);
    e.value_im = Interval(0.0);
}

bool disjoint(const Eigenpair& a, const Eigenpair& b) {
    if (a.exact && b.exact) return *a.exact != *b.exact;
    const auto apart = [](Interval x, Interval y) { return x.hi < y.lo || y.hi < x.lo; };
    // b's conjugate too, for complex pairs
    const Interval bim_conj(-b.value_im.hi, -b.value_im.lo);
    return (apart(a.value_re, b.value_re) || apart(a.value_im, b.value_im)) &&
           (apart(a.value_re, b.value_re) || apart(a.value_im, bim_conj) || !b.is_complex());
}

std::string format_value(const Eigenpair& e) {
    if (e.exact) return e.exact->to_string();
    if (e.is_complex()) return fmt::format("{:.6g} ± {:.6g}i", e.re, std::abs(e.im));
    return fmt::format("{:.6g}", e.re);
}

// Decides the behaviour at the fixed point from the sorted spectrum.
void classify(OperatorAnalysis& o, std::size_t n) {
    if (o.others.empty()) {
        o.behaviour = Behaviour::point;
        o.reason = "bary(1): no sub-dominant eigenvalue";
        return;
    }
    // Every eigenvalue accounted for, each enclosure apart from the others.
    std::size_t counted = o.fixed.multiplicity;
    bool sound = o.fixed.verified || o.fixed.exact.has_value();
    for (const Eigenpair& e : o.others) {
        counted += e.exact ? e.multiplicity : e.is_complex() ? 2 : 1;
        sound = sound && (e.verified || e.exact);
    }
    std::vector<const Eigenpair*> all{&o.fixed};
    for (const Eigenpair& e : o.others) all.push_back(&e);
    bool apart = true;
    for (std::size_t i = 0; i < all.size(); ++i)
        for (std::size_t j = i + 1; j < all.size(); ++j) apart = apart && disjoint(*all[i], *all[j]);
    o.separated = sound && apart && counted == n;
    for (const Eigenpair& e : o.others) o.separated = o.separated && e.multiplicity == 1;
    if (o.fixed.multiplicity != 1) {
        o.reason =
            fmt::format("the eigenvalue 1 has multiplicity {}: no unique fixed point", o.fixed.multiplicity);
        return;
    }
    if (!(sound && apart && counted == n)) {
        o.reason = "the eigenvalues could not all be enclosed apart from each other";
        return;
    }
    const Eigenpair& l2 = o.others.front();
    const Interval m2 = l2.modulus();
    if (o.others.size() > 1) {
        const Interval m3 = o.others[1].modulus();
        double rest = 0; // the largest modulus after λ2 (sorted on the approximations, so all are checked)
        for (std::size_t k = 1; k < o.others.size(); ++k) rest = std::max(rest, o.others[k].modulus().hi);
        if (!(m2.lo > rest)) {
            o.reason = fmt::format("|λ2| = |{}| is not proven larger than |λ3| = |{}|", format_value(l2),
                                   format_value(o.others[1]));
            return;
        }
        const Eigenpair& l3 = o.others[1];
        o.reason =
            fmt::format("λ2 = {} dominates |λ3| = {}", format_value(l2),
                        l3.exact ? abs(*l3.exact).to_string() : fmt::format("{:.6g}", num::midpoint(m3)));
    } else {
        o.reason = fmt::format("λ2 = {} is the only sub-dominant eigenvalue", format_value(l2));
    }
    if (l2.multiplicity > 1) {
        // A Jordan block keeps one direction (its k λ^(k-1) term wins); a larger eigenspace does not.
        o.reason = fmt::format("λ2 = {} has multiplicity {} (geometric {})", format_value(l2),
                               l2.multiplicity, l2.geometric);
        if (l2.geometric != 1 || l2.exact->sign() <= 0) return;
        o.behaviour = Behaviour::tangent;
        o.reason += ": a Jordan block, its eigenvector gives the half-tangent";
        return;
    }
    if (l2.is_complex())
        o.behaviour = Behaviour::spiral;
    else if (l2.value_re.lo > 0)
        o.behaviour = Behaviour::tangent;
    else if (l2.value_re.hi < 0)
        o.behaviour = Behaviour::oscillation;
    else {
        o.behaviour = Behaviour::point;
        o.reason = "every sub-dominant eigenvalue is 0";
    }
}

// Seed 002's C1 condition. e_(j+1) - e_j is an eigenvector of T exactly when columns j and j + 1 differ
// only in rows j and j + 1 (columns summing to 1 make those two differences opposite); its eigenvalue is
// then T(j+1, j+1) - T(j+1, j). Exact operators compare exactly; enclosures need the other rows' entries
// thin and equal, and compare by intervals.
void c1_condition(const ir::Operator& t, OperatorAnalysis& o) {
    const std::size_t n = t.rows();
    for (std::size_t j = 0; j + 1 < n && !o.edge; ++j) {
        bool edge = true;
        for (std::size_t r = 0; r < n && edge; ++r) {
            if (r == j || r == j + 1) continue;
            edge = t.exact ? (*t.exact)(r, j) == (*t.exact)(r, j + 1)
                           : t.enclosure(r, j).is_thin() && t.enclosure(r, j) == t.enclosure(r, j + 1);
        }
        if (!edge) continue;
        std::optional<Rational> exact;
        Interval value;
        if (t.exact) {
            exact = (*t.exact)(j + 1, j + 1) - (*t.exact)(j + 1, j);
            value = num::enclose(*exact);
        } else {
            num::UpwardRounding up;
            value = num::sub(t.enclosure(j + 1, j + 1), t.enclosure(j + 1, j));
        }
        // The entry of the spectrum it is: equal, or the only real enclosure meeting it.
        std::optional<std::size_t> match;
        for (std::size_t k = 0; k < o.others.size(); ++k) {
            const Eigenpair& e = o.others[k];
            const bool same = exact && e.exact ? *exact == *e.exact
                                               : !e.is_complex() && (e.verified || e.exact) &&
                                                     !num::intersect(value, e.value_re).is_empty();
            if (!same) continue;
            if (match) return; // two candidates: no verdict
            match = k;
        }
        if (!match) return;
        o.edge = match;
        o.edge_from = j;
    }
    if (!o.edge) return;
    const Eigenpair& edge = o.others[*o.edge];
    Interval rival(0.0); // [largest lower bound, largest upper bound] of the other moduli
    for (std::size_t k = 0; k < o.others.size(); ++k) {
        if (k == *o.edge) continue;
        const Interval m = o.others[k].modulus();
        rival = Interval(std::max(rival.lo, m.lo), std::max(rival.hi, m.hi));
    }
    if (edge.multiplicity > 1) { // its own second copy
        const Interval m = edge.modulus();
        rival = Interval(std::max(rival.lo, m.lo), std::max(rival.hi, m.hi));
    }
    o.c1_rival = rival;
    if (edge.exact &&
        std::all_of(o.others.begin(), o.others.end(), [](const Eigenpair& e) { return e.exact; })) {
        Rational largest;
        for (std::size_t k = 0; k < o.others.size(); ++k)
            if (k != *o.edge || edge.multiplicity > 1) largest = std::max(largest, abs(*o.others[k].exact));
        o.c1_exact_rival = largest;
        o.c1_condition = edge.exact->sign() > 0 && *edge.exact >= largest;
        return;
    }
    const Interval lambda = edge.value_re;
    if (lambda.lo > 0 && lambda.lo >= rival.hi)
        o.c1_condition = true;
    else if (lambda.hi <= 0 || lambda.hi < rival.lo)
        o.c1_condition = false;
}

// The copies' components on v2 (see OperatorAnalysis::Copy): exactly when λ2 and the operators are
// exact, else on a verified left eigenvector.
void copies_along_v2(const ir::Automaton& a, OperatorAnalysis& o) {
    const ir::Operator& t = a.arcs[o.arc].op;
    const Eigenpair& l2 = o.others.front();
    std::optional<std::vector<Rational>> exact_left;
    if (t.exact && l2.exact) exact_left = exact_eigenvector(num::transpose(*t.exact), *l2.exact, false);
    IVector left;
    if (!exact_left) {
        const std::size_t n = t.rows();
        Eigen::MatrixXd tt(n, n);
        for (std::size_t r = 0; r < n; ++r)
            for (std::size_t c = 0; c < n; ++c) tt(r, c) = t.nearest(c, r);
        const Eigen::EigenSolver<Eigen::MatrixXd> solver(tt);
        Eigen::Index nearest = 0;
        for (Eigen::Index i = 0; i < solver.eigenvalues().size(); ++i)
            if (std::abs(solver.eigenvalues()[i] - l2.re) < std::abs(solver.eigenvalues()[nearest] - l2.re))
                nearest = i;
        std::vector<double> w(n), zero(n, 0.0);
        for (std::size_t k = 0; k < n; ++k) w[k] = solver.eigenvectors()(k, nearest).real();
        const Eigenpair e = verify_eigenpair(num::transpose(t.enclosure), l2.re, 0, w, zero, false);
        if (e.verified) left = e.vector_re;
    }
    for (std::size_t i = 0; i < a.arcs.size(); ++i) {
        const ir::Arc& arc = a.arcs[i];
        if (arc.from != o.state || arc.to == o.state) continue;
        OperatorAnalysis::Copy copy{i};
        if (exact_left && arc.op.exact) {
            const Matrix<Rational> comps =
                Matrix<Rational>(num::transpose(Matrix<Rational>::column(*exact_left))) * *arc.op.exact;
            copy.along = OperatorAnalysis::Copy::Along::no;
            for (std::size_t c = 0; c < comps.cols(); ++c)
                if (!comps(0, c).is_zero()) copy.along = OperatorAnalysis::Copy::Along::yes;
        } else if (exact_left || !left.empty()) {
            const IVector w = exact_left ? enclose_vector(*exact_left) : left;
            const Matrix<Interval> comps = num::transpose(Matrix<Interval>::column(w)) * arc.op.enclosure;
            for (std::size_t c = 0; c < comps.cols(); ++c)
                if (comps(0, c).lo > 0 || comps(0, c).hi < 0) copy.along = OperatorAnalysis::Copy::Along::yes;
        }
        o.copies.push_back(copy);
    }
}

OperatorAnalysis analyze_operator(const ir::Automaton& a, std::size_t arc) {
    const ir::Operator& op = a.arcs[arc].op;
    const std::size_t n = op.rows();
    OperatorAnalysis o;
    o.arc = arc;
    o.state = a.arcs[arc].from;
    o.label = ir::arc_name(a, arc);
    Eigen::MatrixXd t(n, n);
    for (std::size_t r = 0; r < n; ++r)
        for (std::size_t c = 0; c < n; ++c) t(r, c) = op.nearest(r, c);
    const Eigen::EigenSolver<Eigen::MatrixXd> solver(t);
    if (solver.info() != Eigen::Success)
        throw std::invalid_argument(fmt::format("{}: no eigenvalues", o.label));
    // The eigenvalue nearest 1 is the fixed point's.
    std::size_t dominant = 0;
    for (Eigen::Index i = 0; i < solver.eigenvalues().size(); ++i)
        if (std::abs(solver.eigenvalues()[i] - 1.0) < std::abs(solver.eigenvalues()[dominant] - 1.0))
            dominant = i;
    if (op.exact && n <= exact_spectrum_limit) o.characteristic = characteristic_polynomial(*op.exact);
    for (Eigen::Index i = 0; i < solver.eigenvalues().size(); ++i) {
        const std::complex<double> l = solver.eigenvalues()[i];
        if (l.imag() < 0) continue; // a complex pair once
        std::vector<double> vr(n), vi(n);
        for (std::size_t k = 0; k < n; ++k) {
            vr[k] = solver.eigenvectors()(k, i).real();
            vi[k] = solver.eigenvectors()(k, i).imag();
        }
        const bool fixed = static_cast<std::size_t>(i) == dominant;
        Eigenpair e = verify_eigenpair(op.enclosure, l.real(), l.imag(), vr, vi, fixed);
        if (o.characteristic) recognise(e, *o.characteristic, *op.exact, fixed);
        if (fixed)
            o.fixed = e;
        else if (!(e.exact && std::any_of(o.others.begin(), o.others.end(),
                                          [&](const Eigenpair& x) { return x.exact == e.exact; })))
            o.others.push_back(e); // a multiple exact eigenvalue once
    }
    if (o.fixed.exact) o.exact_fixed = o.fixed.exact_vector;
    std::stable_sort(o.others.begin(), o.others.end(), [](const Eigenpair& x, const Eigenpair& y) {
        return std::abs(std::complex(x.re, x.im)) > std::abs(std::complex(y.re, y.im));
    });
    classify(o, n);
    c1_condition(op, o);
    if (o.behaviour == Behaviour::tangent) copies_along_v2(a, o);
    return o;
}

// T applied to a vector of intervals.
IVector apply(const Matrix<Interval>& t, const IVector& x) {
    const Matrix<Interval> y = times(t, x);
    IVector out(y.rows());
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = y(i, 0);
    return out;
}

std::vector<Rational> apply(const Matrix<Rational>& t, const std::vector<Rational>& x) {
    const Matrix<Rational> y = t * Matrix<Rational>::column(x);
    std::vector<Rational> out(y.rows());
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = y(i, 0);
    return out;
}

// The junction of the pieces T_i(A) and T_j(A) at T_i x_p = T_j x_q, when they meet there.
std::optional<JunctionAnalysis> junction(const ir::Automaton& a, const std::vector<OperatorAnalysis>& ops,
                                         std::size_t i, std::size_t p, std::size_t j, std::size_t q) {
    const ir::Operator &ti = a.arcs[ops[i].arc].op, &tj = a.arcs[ops[j].arc].op;
    JunctionAnalysis out;
    out.left = i;
    out.right = j;
    out.left_end = p;
    out.right_end = q;
    const auto &xp = ops[p].exact_fixed, &xq = ops[q].exact_fixed;
    if (ti.exact && tj.exact && xp && xq) {
        const std::vector<Rational> pi = apply(*ti.exact, *xp);
        if (pi != apply(*tj.exact, *xq)) return std::nullopt;
        out.meet_exact = true;
        out.point = enclose_vector(pi);
    } else {
        if (ops[p].fixed.vector_re.empty() || ops[q].fixed.vector_re.empty()) return std::nullopt;
        num::UpwardRounding up;
        out.point = apply(ti.enclosure, ops[p].fixed.vector_re);
        const IVector other = apply(tj.enclosure, ops[q].fixed.vector_re);
        for (std::size_t k = 0; k < other.size(); ++k) {
            if (num::intersect(out.point[k], other[k]).is_empty()) return std::nullopt;
            out.point[k] = num::hull(out.point[k], other[k]);
        }
    }
    const Eigenpair *vp = ops[p].others.empty() ? nullptr : &ops[p].others.front(),
                    *vq = ops[q].others.empty() ? nullptr : &ops[q].others.front();
    if (ops[p].behaviour != Behaviour::tangent || ops[q].behaviour != Behaviour::tangent) {
        out.reason = "no half-tangent on both sides";
        return out;
    }
    // The tangents T_i v_p and T_j v_q: collinear when every 2x2 minor of [t1 t2] vanishes.
    if (ti.exact && tj.exact && vp->exact_vector && vq->exact_vector) {
        const std::vector<Rational> t1 = apply(*ti.exact, *vp->exact_vector),
                                    t2 = apply(*tj.exact, *vq->exact_vector);
        for (std::size_t r = 0; r < t1.size(); ++r)
            for (std::size_t s = r + 1; s < t1.size(); ++s)
                if (!(t1[r] * t2[s] - t1[s] * t2[r]).is_zero()) {
                    out.tangents = JunctionAnalysis::Tangents::not_collinear;
                    out.reason = "the half-tangents are not collinear (exact)";
                    return out;
                }
        out.tangents = JunctionAnalysis::Tangents::collinear;
        out.reason = "the half-tangents are collinear (exact): G1";
        return out;
    }
    if (vp->vector_re.empty() || vq->vector_re.empty()) { // an exact Jordan eigenvector, an inexact piece
        out.tangents = JunctionAnalysis::Tangents::undecided;
        out.reason = "the half-tangents have no enclosure to compare";
        return out;
    }
    num::UpwardRounding up;
    const IVector t1 = apply(ti.enclosure, vp->vector_re), t2 = apply(tj.enclosure, vq->vector_re);
    double largest = 0;
    for (std::size_t r = 0; r < t1.size(); ++r)
        for (std::size_t s = r + 1; s < t1.size(); ++s) {
            const Interval minor = num::sub(num::mul(t1[r], t2[s]), num::mul(t1[s], t2[r]));
            if (minor.lo > 0 || minor.hi < 0) {
                out.tangents = JunctionAnalysis::Tangents::not_collinear;
                out.reason = "the half-tangents are not collinear (proven)";
                return out;
            }
            largest = std::max(largest, num::magnitude(minor));
        }
    out.tangents = JunctionAnalysis::Tangents::undecided;
    out.reason =
        fmt::format("the half-tangents are collinear within the enclosures (minors below {:.2g})", largest);
    return out;
}

} // namespace

Interval Eigenpair::modulus() const {
    if (exact) return num::enclose(abs(*exact));
    num::UpwardRounding up;
    return num::sqrt(num::add(num::sqr(value_re), num::sqr(value_im)));
}

const char* behaviour_name(Behaviour b) {
    switch (b) {
    case Behaviour::tangent: return "half-tangent (G1 possible)";
    case Behaviour::oscillation: return "oscillation (no tangent)";
    case Behaviour::spiral: return "spiral (no tangent)";
    case Behaviour::point: return "a point";
    case Behaviour::undecided: return "undecided";
    }
    return "";
}

Eigenpair verify_eigenpair(const Matrix<Interval>& t, double re, double im, const std::vector<double>& v_re,
                           const std::vector<double>& v_im, bool normalise_sum) {
    const std::size_t n = t.rows();
    Eigenpair e;
    e.re = re;
    e.im = im;
    e.value_re = e.value_im = Interval::entire();
    const bool complex = im != 0;
    std::vector<double> c(n, normalise_sum ? 1.0 : 0.0);
    std::vector<std::complex<double>> v(n);
    std::size_t largest = 0;
    for (std::size_t k = 0; k < n; ++k) {
        v[k] = {v_re[k], complex ? v_im[k] : 0.0};
        if (std::abs(v[k]) > std::abs(v[largest])) largest = k;
    }
    std::complex<double> scale = v[largest];
    if (normalise_sum) {
        scale = 0;
        for (const auto& x : v) scale += x;
    } else {
        c[largest] = 1.0;
    }
    if (std::abs(scale) == 0) return e;
    std::vector<double> approx;
    for (const auto& x : v) approx.push_back((x / scale).real());
    if (complex)
        for (const auto& x : v) approx.push_back((x / scale).imag());
    approx.push_back(re);
    if (complex) approx.push_back(im);
    const auto z = krawczyk({t, c, complex}, approx);
    if (!z) return e;
    e.verified = true;
    e.vector_re.assign(z->begin(), z->begin() + static_cast<long>(n));
    if (complex) {
        e.vector_im.assign(z->begin() + static_cast<long>(n), z->begin() + static_cast<long>(2 * n));
        e.value_re = (*z)[2 * n];
        e.value_im = (*z)[2 * n + 1];
    } else {
        e.value_re = (*z)[n];
        e.value_im = Interval(0.0);
    }
    return e;
}

std::vector<Rational> characteristic_polynomial(const Matrix<Rational>& t) {
    const std::size_t n = t.rows();
    // Faddeev–LeVerrier: M_k = T M_(k-1) + c_(n-k+1) I, c_(n-k) = -tr(T M_k) / k.
    std::vector<Rational> c(n + 1);
    c[n] = Rational(1);
    Matrix<Rational> m(n, n);
    for (std::size_t k = 1; k <= n; ++k) {
        m = t * m;
        for (std::size_t i = 0; i < n; ++i) m(i, i) = m(i, i) + c[n - k + 1];
        const Matrix<Rational> tm = t * m;
        Rational trace;
        for (std::size_t i = 0; i < n; ++i) trace += tm(i, i);
        c[n - k] = -trace / Rational(static_cast<long>(k));
    }
    return c;
}

AutomatonAnalysis analyze(const ir::Automaton& a) {
    AutomatonAnalysis out;
    for (std::size_t i = 0; i < a.arcs.size(); ++i) {
        const ir::Arc& arc = a.arcs[i];
        if (arc.from == arc.to && a.states[arc.from].space.kind == ir::Space::Kind::barycentric)
            out.operators.push_back(analyze_operator(a, i));
    }
    if (out.operators.empty())
        throw std::invalid_argument(fmt::format(
            "{} has no subdivision operator to analyse: no arc from a barycentric state to itself", a.name));
    const std::size_t m = out.operators.size();
    for (std::size_t i = 0; i < m; ++i)
        for (std::size_t j = i + 1; j < m; ++j) {
            if (out.operators[i].state != out.operators[j].state) continue;
            // T_i x_p = T_j x_q for fixed points of the state's other operators (p != i, q != j: an end
            // of piece i against an end of piece j).
            for (std::size_t p = 0; p < m; ++p)
                for (std::size_t q = 0; q < m; ++q) {
                    if (p == i || q == j || out.operators[p].state != out.operators[i].state ||
                        out.operators[q].state != out.operators[i].state)
                        continue;
                    if (auto jn = junction(a, out.operators, i, p, j, q)) out.junctions.push_back(*jn);
                }
        }
    return out;
}

} // namespace frac::rt
