// Differential analysis of subdivision operators: verified eigenpairs, behaviour at fixed points and
// junctions (seed 002 sec. 3.2, seed 004 sec. 4.1), and the soundness of the enclosures.
#include "runtime/automata/analysis.hpp"
#include "tests/unit/automata_examples.hpp"

#include <Eigen/Dense>
#include <catch2/catch.hpp>

#include <complex>
#include <random>

using namespace frac;
using namespace frac::test;

namespace {

// Seed 002, sec. 3.2: the C1 edge with λ and μ.
ir::Automaton c1_edge(const Rational& lambda, const Rational& mu) {
    ir::Automaton a;
    a.name = "c1_edge";
    a.states.push_back(state("e", ir::Space::barycentric(3)));
    const Rational one(1), two(2);
    const Matrix<Rational> t0{{one, one - lambda, (one - lambda) / two},
                              {0, lambda, (lambda + mu) / two},
                              {0, 0, (one - mu) / two}};
    const Matrix<Rational> t1{
        {(one - lambda) / two, 0, 0}, {(lambda + mu) / two, mu, 0}, {(one - mu) / two, one - mu, one}};
    a.arcs.push_back(arc(0, 0, t0, "T0"));
    a.arcs.push_back(arc(0, 0, t1, "T1"));
    return a;
}

// Seed 004, sec. 4.1: T^i of the cubic–quadratic junction, e = 1 - a - b - c - d, p = 1 - k - l - m - n.
Matrix<Rational> junction_operator(const std::vector<Rational>& x) {
    const Rational &a = x[0], &b = x[1], &c = x[2], &d = x[3], &k = x[4], &l = x[5], &m = x[6], &n = x[7];
    const Rational e = Rational(1) - a - b - c - d, p = Rational(1) - k - l - m - n;
    return Matrix<Rational>{{q(1, 8), 0, a, k, 0},
                            {q(3, 4), q(1, 2), b, l, 0},
                            {q(1, 8), q(1, 2), c, m, 0},
                            {0, 0, d, n, q(3, 4)},
                            {0, 0, e, p, q(1, 4)}};
}

ir::Automaton junction(const std::vector<Rational>& x) {
    ir::Automaton a;
    a.name = "junction";
    a.states.push_back(state("i", ir::Space::barycentric(5)));
    a.arcs.push_back(arc(0, 0, junction_operator(x), "Ti"));
    return a;
}

Rational dec(const char* text) {
    return *Rational::parse_decimal(text);
}

std::vector<Rational> exact(std::initializer_list<Rational> v) {
    return v;
}

} // namespace

TEST_CASE("seed 002's C1 edge: λ and μ sub-dominant, half-tangents along the control polygon",
          "[automata][analysis]") {
    const rt::AutomatonAnalysis r = rt::analyze(c1_edge(q(7, 10), q(3, 5)));
    REQUIRE(r.operators.size() == 2);
    const rt::OperatorAnalysis &t0 = r.operators[0], &t1 = r.operators[1];
    CHECK(t0.exact_fixed == exact({1, 0, 0}));
    CHECK(t1.exact_fixed == exact({0, 0, 1}));
    REQUIRE(t0.others.size() == 2);
    CHECK(t0.others[0].exact == q(7, 10));
    CHECK(t0.others[0].exact_vector == exact({-1, 1, 0})); // the first edge of the control polygon
    CHECK(t0.others[1].exact == q(1, 5));                  // (1 - μ)/2
    CHECK(t1.others[0].exact == q(3, 5));
    CHECK(t1.others[0].exact_vector == exact({0, -1, 1}));
    CHECK(t0.separated);
    CHECK(t0.behaviour == rt::Behaviour::tangent);
    CHECK(t1.behaviour == rt::Behaviour::tangent);
    CHECK(t0.c1_condition == true); // λ = 7/10 ≥ (1 - μ)/2 = 1/5
    CHECK(t0.c1_exact_rival == q(1, 5));
    CHECK(t1.c1_condition == true); // μ = 3/5 ≥ (1 - λ)/2 = 3/20
    CHECK(t1.c1_exact_rival == q(3, 20));
    // The pieces T0(A) and T1(A) meet at T0 x1 = T1 x0 with collinear half-tangents.
    REQUIRE(r.junctions.size() == 1);
    CHECK(r.junctions[0].meet_exact);
    CHECK(r.junctions[0].tangents == rt::JunctionAnalysis::Tangents::collinear);
}

TEST_CASE("a copy placed at the fixed point has no component on v2, one beside it has",
          "[automata][analysis]") {
    ir::Automaton a = c1_edge(q(7, 10), q(3, 5));
    a.states.push_back(state("v", ir::Space::barycentric(1)));
    a.arcs.push_back(arc(0, 1, Matrix<Rational>{{1}, {0}, {0}}, "at_x0")); // the fixed point of T0
    a.arcs.push_back(arc(0, 1, Matrix<Rational>{{0}, {1}, {0}}, "beside"));
    const rt::OperatorAnalysis t0 = rt::analyze(a).operators.at(0);
    REQUIRE(t0.copies.size() == 2);
    CHECK(t0.copies[0].along == rt::OperatorAnalysis::Copy::Along::no);
    CHECK(t0.copies[1].along == rt::OperatorAnalysis::Copy::Along::yes);
}

TEST_CASE("seed 002's C1 condition on interval operators (irrational λ, μ)", "[automata][analysis]") {
    // λ = sqrt(2)/2, μ = 1/pi on both sides of the condition, as enclosures (entries of width > 0).
    const auto edge = [](double lambda, double mu) {
        num::UpwardRounding up;
        const Interval l =
            lambda > 0.5 ? num::div(num::sqrt(Interval(2)), Interval(2)) : num::div(Interval(1), num::pi());
        const Interval m =
            mu > 0.5 ? num::div(num::sqrt(Interval(2)), Interval(2)) : num::div(Interval(1), num::pi());
        const Interval one(1), half(0.5);
        const Matrix<Interval> t0{{one, num::sub(one, l), num::mul(half, num::sub(one, l))},
                                  {0, l, num::mul(half, num::add(l, m))},
                                  {0, 0, num::mul(half, num::sub(one, m))}};
        const Matrix<Interval> t1{{num::mul(half, num::sub(one, l)), 0, 0},
                                  {num::mul(half, num::add(l, m)), m, 0},
                                  {num::mul(half, num::sub(one, m)), num::sub(one, m), one}};
        ir::Automaton a;
        a.name = "c1_edge";
        a.states.push_back(state("e", ir::Space::barycentric(3)));
        a.arcs.push_back(arc(0, 0, t0, "T0"));
        a.arcs.push_back(arc(0, 0, t1, "T1"));
        return rt::analyze(a);
    };
    // λ = 0.707 ≥ (1 - μ)/2 = 0.341 and μ = 0.318 ≥ (1 - λ)/2 = 0.146: both hold.
    const rt::AutomatonAnalysis good = edge(0.7, 0.3);
    REQUIRE(good.operators[0].edge);
    CHECK(good.operators[0].edge_from == 0);
    CHECK(good.operators[0].c1_condition == true);
    CHECK(good.operators[1].edge_from == 1);
    CHECK(good.operators[1].c1_condition == true);
    // λ = μ = 1/pi = 0.318 < (1 - μ)/2 = (1 - λ)/2 = 0.341: fails on both sides.
    const rt::AutomatonAnalysis bad = edge(0.3, 0.3);
    CHECK(bad.operators[0].c1_condition == false);
    CHECK(bad.operators[1].c1_condition == false);
}

TEST_CASE("seed 002's C1 edge: λ < (1 - μ)/2 loses the tangent continuity", "[automata][analysis]") {
    // λ = 1/10 < (1 - μ)/2 = 7/20 and μ = 3/10 < (1 - λ)/2 = 9/20: the sub-dominant eigenvalues are the
    // other ones, their eigenvectors leave the control polygon's edges, and the half-tangents at the
    // junction are not collinear.
    const rt::AutomatonAnalysis r = rt::analyze(c1_edge(q(1, 10), q(3, 10)));
    const rt::OperatorAnalysis &t0 = r.operators[0], &t1 = r.operators[1];
    CHECK(t0.others[0].exact == q(7, 20));
    CHECK(t0.others[1].exact == q(1, 10));
    CHECK(t1.others[0].exact == q(9, 20));
    CHECK(t0.others[0].exact_vector != exact({-1, 1, 0}));
    CHECK(t0.c1_condition == false); // λ = 1/10 < (1 - μ)/2 = 7/20
    CHECK(t0.c1_exact_rival == q(7, 20));
    CHECK(t1.c1_condition == false); // μ = 3/10 < (1 - λ)/2 = 9/20
    REQUIRE(r.junctions.size() == 1);
    CHECK(r.junctions[0].tangents == rt::JunctionAnalysis::Tangents::not_collinear);
}

TEST_CASE("seed 002's C1 edge on the boundary λ = (1 - μ)/2: a double eigenvalue", "[automata][analysis]") {
    const rt::AutomatonAnalysis r = rt::analyze(c1_edge(q(1, 5), q(3, 5)));
    const rt::OperatorAnalysis& t0 = r.operators[0];
    REQUIRE(t0.others.size() == 1);
    CHECK(t0.others[0].exact == q(1, 5));
    CHECK(t0.others[0].multiplicity == 2);
    CHECK(t0.others[0].geometric == 1);
    CHECK_FALSE(t0.separated);
    // A Jordan block: the eigenvector (-1, 1, 0) still gives the half-tangent, and the paper's λ ≥ (1 - μ)/2
    // holds with equality.
    CHECK(t0.behaviour == rt::Behaviour::tangent);
    CHECK(t0.c1_condition == true);
    CHECK(t0.c1_exact_rival == q(1, 5));
}

TEST_CASE("seed 004's junction: λ2 = 0.696, G1", "[automata][analysis]") {
    const rt::AutomatonAnalysis r =
        rt::analyze(junction({dec("0.131"), dec("0.2"), dec("0.38"), dec("0.289"), dec("0.11"), dec("0.12"),
                              dec("0.1"), dec("0.12")}));
    const rt::OperatorAnalysis& ti = r.operators.at(0);
    REQUIRE(ti.separated);
    CHECK(ti.behaviour == rt::Behaviour::tangent);
    const rt::Eigenpair& l2 = ti.others.at(0);
    CHECK(l2.verified);
    CHECK_FALSE(l2.exact); // irrational
    CHECK(l2.value_re.lo > 0.6955);
    CHECK(l2.value_re.hi < 0.6965);
    CHECK(l2.value_re.hi - l2.value_re.lo < 1e-12);
    CHECK(ti.fixed.exact == Rational(1));
}

TEST_CASE("seed 004's junction: both copies reach the junction point along v2", "[automata][analysis]") {
    // States i (the junction), l (cubic), r (quadratic): T^l and T^r place the copies whose control
    // polygons have components on v2, so both half-tangents are along ±v2.
    const std::vector<Rational> x{dec("0.131"), dec("0.2"),  dec("0.38"), dec("0.289"),
                                  dec("0.11"),  dec("0.12"), dec("0.1"),  dec("0.12")};
    ir::Automaton a = junction(x);
    a.states.push_back(state("l", ir::Space::barycentric(4)));
    a.states.push_back(state("r", ir::Space::barycentric(3)));
    const Matrix<Rational> t = junction_operator(x);
    Matrix<Rational> tl(5, 4), tr(5, 3);
    for (std::size_t row = 0; row < 5; ++row) {
        for (std::size_t c = 0; c < 3; ++c)
            tl(row, c + 1) = t(row, c); // T^l's last 3 columns = T^i's first 3
        for (std::size_t c = 0; c < 2; ++c) tr(row, c) = t(row, c + 3); // T^r's first 2 = T^i's last 2
    }
    tl(0, 0) = tl(1, 0) = q(1, 2);
    tr(3, 2) = q(1, 4), tr(4, 2) = q(3, 4);
    a.arcs.push_back(arc(0, 1, tl, "Tl"));
    a.arcs.push_back(arc(0, 2, tr, "Tr"));
    const rt::OperatorAnalysis ti = rt::analyze(a).operators.at(0);
    REQUIRE(ti.copies.size() == 2);
    CHECK(ti.copies[0].along == rt::OperatorAnalysis::Copy::Along::yes);
    CHECK(ti.copies[1].along == rt::OperatorAnalysis::Copy::Along::yes);
}

TEST_CASE("seed 004's junction: a complex pair spirals, a negative λ2 oscillates", "[automata][analysis]") {
    const rt::OperatorAnalysis spiral =
        rt::analyze(junction({0, 0, dec("0.1"), dec("0.8"), dec("0.4"), dec("0.2"), 0, dec("0.15")}))
            .operators.at(0);
    CHECK(spiral.behaviour == rt::Behaviour::spiral);
    CHECK_FALSE(spiral.edge); // no eigenvector along an edge of the control polygon
    CHECK(spiral.others.at(0).value_im.lo > 0.48);
    CHECK(spiral.others.at(0).value_re.hi < 0.17);
    const rt::OperatorAnalysis oscillation = rt::analyze(junction({0, dec("0.1"), 0, dec("0.9"), dec("0.15"),
                                                                   dec("0.05"), dec("0.25"), dec("0.2")}))
                                                 .operators.at(0);
    CHECK(oscillation.behaviour == rt::Behaviour::oscillation);
    CHECK(oscillation.others.at(0).value_re.hi < -0.57);
}

TEST_CASE("analysis refuses an automaton without subdivision operators", "[automata][analysis]") {
    CHECK_THROWS_WITH(rt::analyze(sierpinski()), Catch::Contains("no subdivision operator"));
}

TEST_CASE("characteristic polynomial over the rationals", "[automata][analysis]") {
    // [[2, 1], [1, 2]]: x^2 - 4x + 3.
    CHECK(rt::characteristic_polynomial(Matrix<Rational>{{2, 1}, {1, 2}}) == exact({3, -4, 1}));
}

TEST_CASE("a Krawczyk test encloses the true eigenpair or fails", "[automata][analysis]") {
    const Matrix<Interval> t = num::enclose(Matrix<Rational>{{q(3, 4), q(1, 4)}, {q(1, 4), q(3, 4)}});
    const rt::Eigenpair good = rt::verify_eigenpair(t, 0.5, 0, {1, -1}, {0, 0}, false);
    REQUIRE(good.verified);
    CHECK(good.value_re.contains(0.5));
    CHECK(good.vector_re[1].contains(-1));
    // From a poor start the inflated boxes grow until they hold the eigenpair: still 1/2, never 0.3.
    const rt::Eigenpair poor = rt::verify_eigenpair(t, 0.3, 0, {1, -1}, {0, 0}, false);
    if (poor.verified) {
        CHECK(poor.value_re.contains(0.5));
        CHECK_FALSE(poor.value_re.contains(0.3));
    }
    // A double eigenvalue (a Jordan block) cannot be enclosed alone: the test must fail.
    const Matrix<Interval> jordan =
        num::enclose(Matrix<Rational>{{1, q(4, 5), q(2, 5)}, {0, q(1, 5), q(2, 5)}, {0, 0, q(1, 5)}});
    CHECK_FALSE(rt::verify_eigenpair(jordan, 0.2, 0, {-1, 1, 0}, {0, 0, 0}, false).verified);
}

// Soundness: on random barycentric matrices, every eigenvalue computed in long double from the exact
// matrix lies in a verified enclosure, and each real enclosure brackets a sign change of the exact
// characteristic polynomial.
TEST_CASE("eigenvalue enclosures contain the long double eigenvalues of random barycentric matrices",
          "[automata][analysis][soundness]") {
    std::mt19937 rng(20261202);
    int separated = 0, trials = 0;
    for (int n = 2; n <= 6; ++n)
        for (int trial = 0; trial < 40; ++trial, ++trials) {
            Matrix<Rational> t(n, n);
            std::uniform_int_distribution<int> weight(-20, 100);
            for (int c = 0; c < n; ++c) { // columns of integers / their sum: exactly barycentric
                std::vector<long> w(n);
                long sum = 0;
                while (sum <= 0) {
                    sum = 0;
                    for (long& x : w) sum += x = weight(rng);
                }
                for (int r = 0; r < n; ++r) t(r, c) = Rational(w[r], sum);
            }
            ir::Automaton a;
            a.name = "random";
            a.states.push_back(state("s", ir::Space::barycentric(n)));
            a.arcs.push_back(arc(0, 0, t, "T"));
            const rt::OperatorAnalysis o = rt::analyze(a).operators.at(0);
            if (!o.separated) continue;
            ++separated;
            Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic> m(n, n);
            for (int r = 0; r < n; ++r)
                for (int c = 0; c < n; ++c)
                    m(r, c) = static_cast<long double>(t(r, c).numerator().get_si()) /
                              static_cast<long double>(t(r, c).denominator().get_si());
            const Eigen::EigenSolver<decltype(m)> solver(m);
            std::vector<const rt::Eigenpair*> all{&o.fixed};
            for (const rt::Eigenpair& e : o.others) all.push_back(&e);
            for (Eigen::Index i = 0; i < n; ++i) {
                const std::complex<long double> l = solver.eigenvalues()[i];
                bool inside = false;
                for (const rt::Eigenpair* e : all) {
                    const long double slack = 1e-17L; // the long double eigenvalue's own error
                    const auto near = [&](num::Interval x, long double v) {
                        return x.lo - slack <= v && v <= x.hi + slack;
                    };
                    inside =
                        inside || (near(e->value_re, l.real()) && (near(e->value_im, std::abs(l.imag())) ||
                                                                   (l.imag() == 0 && e->value_im.lo <= 0)));
                }
                INFO("n = " << n << ", eigenvalue " << static_cast<double>(l.real()) << " + "
                            << static_cast<double>(l.imag()) << "i");
                CHECK(inside);
            }
            const std::vector<Rational> p = rt::characteristic_polynomial(t);
            const auto at = [&](double x) {
                Rational v;
                for (auto it = p.rbegin(); it != p.rend(); ++it) v = v * Rational::from_double(x) + *it;
                return v.sign();
            };
            for (const rt::Eigenpair* e : all)
                if (!e->exact && !e->is_complex()) CHECK(at(e->value_re.lo) * at(e->value_re.hi) < 0);
        }
    // Random matrices have simple spectra: the test must separate nearly all of them.
    CHECK(separated >= trials * 9 / 10);
}

TEST_CASE("a double eigenvalue 1 has no unique fixed point", "[automata][analysis]") {
    ir::Automaton a;
    a.name = "split";
    a.states.push_back(state("s", ir::Space::barycentric(3)));
    a.arcs.push_back(arc(0, 0, Matrix<Rational>{{1, 0, q(1, 2)}, {0, 1, q(1, 2)}, {0, 0, 0}}, "T"));
    const rt::OperatorAnalysis o = rt::analyze(a).operators.at(0);
    CHECK(o.fixed.exact == Rational(1));
    CHECK(o.fixed.multiplicity == 2);
    CHECK(o.behaviour == rt::Behaviour::undecided);
    CHECK_THAT(o.reason, Catch::Contains("no unique fixed point"));
}

TEST_CASE("operators beyond the exact limit are analysed on their enclosures", "[automata][analysis]") {
    const std::size_t n = rt::exact_spectrum_limit + 4;
    Matrix<Rational> t(n, n);
    for (std::size_t c = 0; c < n; ++c) { // a lazy random walk: 1/2 stay, 1/2 one step down (cyclic)
        t(c, c) = q(1, 2);
        t((c + 1) % n, c) += q(1, 2) - q(1, static_cast<long>(4 * n));
        t(0, c) += q(1, static_cast<long>(4 * n));
    }
    ir::Automaton a;
    a.name = "walk";
    a.states.push_back(state("s", ir::Space::barycentric(static_cast<int>(n))));
    a.arcs.push_back(arc(0, 0, t, "T"));
    const rt::OperatorAnalysis o = rt::analyze(a).operators.at(0);
    CHECK_FALSE(o.characteristic);
    CHECK(o.fixed.verified);
    CHECK_FALSE(o.fixed.exact);
    CHECK(o.separated);
}
