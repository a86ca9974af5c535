// Checks of the automaton IR: sizes, the affine condition, reachability, and contractivity proofs.
#include "ir/automaton_check.hpp"
#include "tests/unit/automata_examples.hpp"

#include <catch2/catch.hpp>

#include <algorithm>

using namespace frac;
using namespace frac::test;
using ir::AutomatonProblem;

namespace {

std::vector<AutomatonProblem> errors(const std::vector<AutomatonProblem>& all) {
    std::vector<AutomatonProblem> out;
    for (const auto& p : all)
        if (p.severity == AutomatonProblem::Severity::error) out.push_back(p);
    return out;
}

bool mentions(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

} // namespace

TEST_CASE("the papers' automata pass every check with a contractivity proof", "[automaton_check]") {
    for (const ir::Automaton& a : {sierpinski(), cantor(), koch(), fern(), penrose(), golden(),
                                   bspline(2, {{0, 0}, {1, 2}, {3, 2}, {4, 0}}),
                                   bspline(3, {{0, 0}, {1, 2}, {3, 2}, {4, 0}, {6, 1}})}) {
        INFO(a.name);
        ir::ContractivityResult proof;
        const auto problems = ir::check_automaton(a, {}, &proof);
        for (const auto& p : problems) INFO(p.message);
        CHECK(problems.empty());
        CHECK(proof.proven);
        CHECK(proof.bound < 1.0);
        CHECK(proof.per_step <= 1.0);
        CHECK(mentions(proof.message, "contractive"));
    }
}

TEST_CASE("the contraction bound of similitudes is their ratio", "[automaton_check]") {
    const auto s = ir::prove_contractive(sierpinski());
    REQUIRE(s.proven);
    CHECK(s.length == 1);
    CHECK(s.bound >= 0.5);
    CHECK(s.bound < 0.5 + 1e-12);
    // Penrose: the rotated maps have ratio r = 1/phi and T0a is the identity, so with single arcs
    // rho [[r, 1], [r, r]] = r + sqrt(r) > 1; paths of length 3 prove it.
    const auto p = ir::prove_contractive(penrose());
    REQUIRE(p.proven);
    CHECK(p.length > 1);
    CHECK(p.per_step < 1.0);
}

TEST_CASE("B-spline subdivision matrices contract in the 1-norm of their full coordinates",
          "[automaton_check]") {
    const ir::Automaton cubic = bspline(3, {{0, 0}, {1, 2}, {3, 2}, {4, 0}});
    // Their single-step 2-norms in the direction coordinates exceed 1 ...
    double worst = 0;
    for (std::size_t i = 0; i < cubic.arcs.size(); ++i)
        if (cubic.arcs[i].from == 1) worst = std::max(worst, ir::norm2_upper(ir::linear_part(cubic, i)));
    CHECK(worst > 1.0);
    // ... but on zero-sum weights with the 1-norm each split matrix contracts by its ergodicity coefficient:
    // 1/2 max over column pairs of the 1-norm of their difference, computed here exactly.
    num::Rational coefficient(0);
    for (const ir::Arc& arc : cubic.arcs) {
        if (arc.from != 1 || arc.to != 1) continue;
        const auto& m = *arc.op.exact;
        for (std::size_t j = 0; j < m.cols(); ++j)
            for (std::size_t k = j + 1; k < m.cols(); ++k) {
                num::Rational sum(0);
                for (std::size_t r = 0; r < m.rows(); ++r) {
                    const num::Rational d = m(r, j) - m(r, k);
                    sum += d.sign() < 0 ? -d : d;
                }
                coefficient = std::max(coefficient, sum / num::Rational(2));
            }
    }
    const auto proof = ir::prove_contractive(cubic);
    REQUIRE(proof.proven);
    CHECK(proof.length == 1);
    CHECK(proof.bound == Approx(coefficient.to_double()).epsilon(1e-12));
    CHECK(proof.bound >= coefficient.to_double()); // rounded up, never below the true coefficient
    // The contraction per step is at least the subdominant eigenvalue 1/2 of the subdivision.
    CHECK(proof.per_step >= 0.5);
}

TEST_CASE("the 1-norm bound never proves an expanding barycentric map", "[automaton_check]") {
    // Columns summing to 1 with a subdominant eigenvalue 1.25 on the hyperplane: no norm can prove it.
    ir::Automaton a;
    a.name = "grow";
    a.states.push_back({"b", ir::Space::barycentric(2), {}});
    ir::Arc arc;
    arc.op = ir::Operator::from_exact(num::Matrix<num::Rational>{
        {num::Rational(9, 8), num::Rational(-1, 8)}, {num::Rational(-1, 8), num::Rational(9, 8)}});
    a.arcs.push_back(arc);
    CHECK_FALSE(ir::prove_contractive(a).proven);
}

TEST_CASE("a non-contractive cycle is named in the refusal", "[automaton_check]") {
    ir::Automaton a = golden();
    // b -> b scaling by 3/2: the cycle b -> b never contracts.
    a.arcs.push_back(arc(1, 1, affine({{q(3, 2)}}, {0}), "grow"));
    const auto problems = ir::check_automaton(a);
    const auto errs = errors(problems);
    REQUIRE(errs.size() == 1);
    CHECK(errs[0].kind == AutomatonProblem::Kind::contractivity);
    CHECK(mentions(errs[0].message, "b -grow-> b"));
    CHECK(mentions(errs[0].message, "does not contract"));
    REQUIRE(errs[0].arc);
    CHECK(*errs[0].arc == 3);
    const auto proof = ir::prove_contractive(a);
    CHECK_FALSE(proof.proven);
    CHECK(proof.cycle == std::vector<std::size_t>{3});
    CHECK(proof.cycle_rate == Approx(1.5));
}

TEST_CASE("a cycle of two maps that only contracts as a product", "[automaton_check]") {
    // a -> b scales by 4, b -> a by 1/8: no arc alone contracts, the cycle does (by 1/2).
    ir::Automaton a;
    a.states.push_back(state("a", ir::Space::euclidean(1)));
    a.states.push_back(state("b", ir::Space::euclidean(1)));
    a.arcs.push_back(arc(0, 1, affine({{q(4)}}, {0}), "up"));
    a.arcs.push_back(arc(1, 0, affine({{q(1, 8)}}, {0}), "down"));
    const auto proof = ir::prove_contractive(a);
    REQUIRE(proof.proven);
    CHECK(proof.bound < 1.0);
    // A rotation by 90 degrees (an isometry) on a loop: the cycle's rate is 1.
    ir::Automaton rot;
    rot.states.push_back(state("r", ir::Space::euclidean(2)));
    rot.arcs.push_back(arc(0, 0, affine({{0, -1}, {1, 0}}, {1, 0}), "quarter"));
    const auto refusal = ir::prove_contractive(rot);
    CHECK_FALSE(refusal.proven);
    CHECK(refusal.cycle_rate == Approx(1.0));
    CHECK(mentions(refusal.message, "r -quarter-> r"));
}

TEST_CASE("size mismatches, non-barycentric matrices and non-affine maps are located", "[automaton_check]") {
    ir::Automaton a = bspline(2, {{0, 0}, {1, 2}, {3, 2}, {4, 0}});
    SECTION("a column that does not sum to 1, exactly") {
        Matrix<Rational> bad = *a.arcs[2].op.exact;
        bad(0, 1) = q(1, 2); // column 2 sums to 5/4
        a.arcs[2] = arc(1, 1, bad, "T0b");
        const auto errs = errors(ir::check_automaton(a));
        REQUIRE(errs.size() == 1);
        CHECK(errs[0].kind == AutomatonProblem::Kind::affine);
        CHECK(errs[0].arc == std::optional<std::size_t>(2));
        CHECK(mentions(errs[0].message, "column 2 sums to 5/4"));
    }
    SECTION("by enclosure when inexact") {
        Matrix<Interval> m = num::enclose(*a.arcs[3].op.exact);
        m(0, 0) = Interval(0.3, 0.3);
        a.arcs[3] = arc(1, 1, m, "T1b");
        const auto errs = errors(ir::check_automaton(a));
        REQUIRE(errs.size() == 1);
        CHECK(errs[0].arc == std::optional<std::size_t>(3));
        CHECK(mentions(errs[0].message, "column 1 sums to"));
    }
    SECTION("an operator of the wrong size") {
        a.arcs[0] = arc(0, 1, Matrix<Rational>::identity(3 + 1), "T0a");
        const auto errs = errors(ir::check_automaton(a));
        REQUIRE(errs.size() == 1);
        CHECK(errs[0].kind == AutomatonProblem::Kind::size);
        CHECK(mentions(errs[0].message, "3 rows and 3 columns, not 4 x 4"));
    }
    SECTION("a euclidean map whose last row is not (0, ..., 0, 1)") {
        ir::Automaton s = sierpinski();
        Matrix<Rational> m = *s.arcs[1].op.exact;
        m(2, 0) = 1;
        s.arcs[1] = arc(0, 0, m, "f1");
        const auto errs = errors(ir::check_automaton(s));
        REQUIRE(errs.size() == 1);
        CHECK(mentions(errs[0].message, "f1"));
        CHECK(mentions(errs[0].message, "last row"));
    }
    SECTION("an arc into a missing state") {
        a.arcs[0].to = 7;
        const auto errs = errors(ir::check_automaton(a));
        REQUIRE(errs.size() == 1);
        CHECK(errs[0].kind == AutomatonProblem::Kind::structure);
        CHECK(errs[0].arc == std::optional<std::size_t>(0));
    }
}

TEST_CASE("unreachable states are warnings, dead ends and partial probabilities errors",
          "[automaton_check]") {
    ir::Automaton a = sierpinski();
    a.states.push_back(state("lonely", ir::Space::euclidean(2)));
    a.arcs.push_back(arc(1, 1, affine({{q(1, 2), 0}, {0, q(1, 2)}}, {0, 0}), "g"));
    auto problems = ir::check_automaton(a);
    REQUIRE(problems.size() == 1);
    CHECK(problems[0].severity == AutomatonProblem::Severity::warning);
    CHECK(problems[0].kind == AutomatonProblem::Kind::unreachable);
    CHECK(problems[0].state == std::optional<std::size_t>(1));

    ir::Automaton d = golden();
    d.arcs.pop_back(); // b has no transitions left
    auto errs = errors(ir::check_automaton(d));
    REQUIRE(errs.size() == 1);
    CHECK(errs[0].kind == AutomatonProblem::Kind::dead_end);
    CHECK(mentions(errs[0].message, "state b"));

    ir::Automaton p = sierpinski();
    p.arcs[0].probability = 0.5;
    errs = errors(ir::check_automaton(p));
    REQUIRE(errs.size() == 1);
    CHECK(errs[0].kind == AutomatonProblem::Kind::probability);
}

TEST_CASE("non-finite operator entries are located errors", "[automaton_check]") {
    ir::Automaton a = koch();
    Matrix<Interval> m = a.arcs[2].op.enclosure;
    m(0, 1) = Interval(-num::inf, 1.0);
    a.arcs[2] = arc(0, 0, m, "f2");
    const auto errs = errors(ir::check_automaton(a));
    REQUIRE(errs.size() == 1);
    CHECK(errs[0].arc == std::optional<std::size_t>(2));
    CHECK(mentions(errs[0].message, "not finite"));
}

TEST_CASE("a tensor-product cubic patch in bary(16)", "[automaton_check]") {
    // T_(s, t) = T_s (x) T_t of the cubic subdivision: contractive by products along paths; with one
    // map replaced by the identity the loop on it is refused, within the work budget.
    ir::Automaton patch = tensor_patch(3);
    ir::ContractivityResult proof;
    CHECK(ir::check_automaton(patch, {}, &proof).empty());
    CHECK(proof.proven);
    patch.arcs[3] = arc(0, 0, Matrix<Rational>::identity(16), "still");
    const auto errs = errors(ir::check_automaton(patch));
    REQUIRE(errs.size() == 1);
    CHECK(mentions(errs[0].message, "p -still-> p does not contract"));
}
