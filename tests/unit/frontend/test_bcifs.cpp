// The bcifs constraint solver end to end: every constraint a model writes or a topology declaration
// generates holds exactly on the operators the compiler lowers (with the values it gave the free entries),
// so sub-patches share their boundaries exactly; seed 002's edge comes out in the paper's form.
#include "compile.hpp"

#include "frontend/ast.hpp"
#include "ir/automaton.hpp"

#include <catch2/catch.hpp>
#include <optional>

using namespace frac;
using num::Matrix;
using num::Rational;

namespace {

const ir::Arc& operator_named(const ir::Automaton& a, const std::string& cell, const std::string& name) {
    for (const auto* list : {&a.arcs, &a.embeddings})
        for (const ir::Arc& arc : *list)
            if (a.states[arc.from].name == cell && arc.label == name) return arc;
    FAIL("no operator " << cell << "." << name);
    throw std::logic_error("unreachable");
}

// The product of a side whose factors are all operators; nullopt when one is a constant matrix.
std::optional<Matrix<Rational>> product(const ir::Automaton& a, const std::vector<front::FactorDecl>& side) {
    std::optional<Matrix<Rational>> p;
    for (const front::FactorDecl& f : side) {
        if (f.constant) return std::nullopt;
        const ir::Arc& arc = operator_named(a, f.cell, f.name);
        REQUIRE(arc.op.exact);
        p = p ? *p * *arc.op.exact : *arc.op.exact;
    }
    return p;
}

// Checks every constraint of every bcifs of the compilation; returns how many were checked.
int check_constraints(const front::Compilation& c) {
    int checked = 0;
    for (const front::Item& it : c.program.items) {
        if (!it.automaton || !it.automaton->bcifs) continue;
        const front::AutomatonInfo* info = c.module.find_automaton(it.name);
        REQUIRE(info);
        for (const front::ConstraintDecl& k : it.automaton->bcifs->constraints) {
            const auto left = product(info->automaton, k.left), right = product(info->automaton, k.right);
            if (!left || !right) continue;
            INFO(it.name << ": " << front::print_product(k.left) << " == " << front::print_product(k.right));
            CHECK(*left == *right);
            ++checked;
        }
    }
    return checked;
}

} // namespace

TEST_CASE("every constraint of the library's bcifs holds exactly on the lowered operators", "[bcifs]") {
    auto c = test::compile_ok("import \"bcifs\";");
    // fractal_edge 3, quad_patch 3 + 12, bezier_patch 3 + 12, c1_edge 5 of 6 (one has a constant factor),
    // cubic_spline 3, quadratic_spline 3, spline_junction 6, bicubic_patch 3 + 12, triangle_patch 3 + 9,
    // bezier_triangle 3 + 9.
    CHECK(check_constraints(*c) == 38 + 51);
}

TEST_CASE("a patch split 3 x 3 over an edge split 3 shares every side exactly", "[bcifs]") {
    auto c = test::compile_ok(R"(
bcifs patch3 {
  cell v in bary(1);
  cell e in bary(4);
  cell f in bary(16);
  topology e = edge(v) split 3;
  topology f = quad(e) split 3 x 3;
  project = controls((0,0,0), (1,0,1), (2,0,1), (3,0,0), (0,1,1), (1,1,2), (2,1,2), (3,1,1),
                     (0,2,1), (1,2,2), (2,2,2), (3,2,1), (0,3,0), (1,3,1), (2,3,1), (3,3,0));
}
)");
    // edge: 2 incidence + 2 adjacency; patch: 4 x 3 incidence + 2 x 3 x 2 adjacency.
    CHECK(check_constraints(*c) == 4 + 12 + 12);
    const ir::Automaton& a = c->module.find_automaton("patch3")->automaton;
    CHECK(a.arcs.size() == 1 + 3 + 9);
    CHECK(a.embeddings.size() == 2 + 4);
}

TEST_CASE("seed 002's edge: the free entries are the paper's, the rest follow exactly", "[bcifs]") {
    auto c = test::compile_ok(R"(
bcifs edge {
  cell v in bary(1);
  cell e in bary(3);
  topology e = edge(v) split 2;
  fix e.T0[0][1] = 1/2; fix e.T0[1][1] = 1/4; fix e.T0[0][2] = 1/8;
  fix e.T0[1][2] = 3/8; fix e.T1[0][1] = 1/16; fix e.T1[1][1] = 5/16;
  project = controls((0, 0), (1, 1), (2, 0));
}
)");
    const ir::Automaton& a = c->module.find_automaton("edge")->automaton;
    const Rational h(1, 2), q(1, 4), e(1, 8), t(3, 8), s(1, 16), f(5, 16);
    CHECK(*operator_named(a, "e", "T0").op.exact ==
          Matrix<Rational>{{1, h, e}, {0, q, t}, {0, Rational(1) - h - q, Rational(1) - e - t}});
    CHECK(*operator_named(a, "e", "T1").op.exact ==
          Matrix<Rational>{{e, s, 0}, {t, f, 0}, {Rational(1) - e - t, Rational(1) - s - f, 1}});
    CHECK(c->module.find_automaton("edge")->dof == std::vector<int>{0, 0}); // all six fixed
}

TEST_CASE("bcifs errors are located and specific", "[bcifs]") {
    const std::string cells =
        "cell v in bary(1); cell e in bary(3); project = controls((0, 0), (1, 1), (2, 0)); ";
    CHECK_THAT(test::errors_of("bcifs b { " + cells + "topology e = edge(v) split 2; fix e.T0[0][0] = 2; }"),
               Catch::Contains("conflict") && Catch::Contains("note: fix e.T0[0][0]"));
    CHECK_THAT(test::errors_of("bcifs b { " + cells + "topology e = quad(v) split 2 x 2; }"),
               Catch::Contains("quad(e): the patch is a cell of bary(k * k)"));
    CHECK_THAT(test::errors_of("bcifs b { " + cells + "subdivide e { T0 = [[1, ?], [0, ?]]; } }"),
               Catch::Contains("so it is a 3×3 matrix; this one is 2×2"));
    CHECK_THAT(test::errors_of("bcifs b { " + cells + "topology e = edge(v) split 2; fix e.T0[0][3] = 0; }"),
               Catch::Contains("entry [0][3] is outside it"));
    CHECK_THAT(
        test::errors_of("bcifs b { " + cells +
                        "param p = 1/2; subdivide e { T0 = [[1, p * p, 0], [0, 0, 0], [0, 1, 1]]; } }"),
        Catch::Contains("affine in the parameters"));
    // An entry that is not exact: solved in floating point, and this column cannot sum to 1.
    CHECK_THAT(test::errors_of("bcifs b { " + cells +
                               "subdivide e { T0 = [[1, sqrt(2), 0], [0, 0, 0], [0, 1, 1]]; } }"),
               Catch::Contains("solved in floating point, residuals above 1e-09") &&
                   Catch::Contains("note: the columns of e.T0 sum to 1"));
    CHECK_THAT(test::errors_of("const m = 2 * ?;"), Catch::Contains("'?'"));
}

TEST_CASE("a volume cell: a cube split 2 x 2 x 2 over quad faces, solved and proven contractive", "[bcifs]") {
    auto c = test::compile_ok(R"(
bcifs block {
  cell v in bary(1);
  cell e in bary(3);
  cell f in bary(9);
  cell c in bary(27);
  topology e = edge(v) split 2;
  topology f = quad(e) split 2 x 2;
  topology c = cube(f) split 2 x 2 x 2;
  project = controls((0,0,0), (1,0,0), (2,0,0), (0,1,0), (1,1,0), (2,1,0), (0,2,0), (1,2,0), (2,2,0),
                     (0,0,1), (1,0,1), (2,0,1), (0,1,1), (1,1,1.5), (2,1,1), (0,2,1), (1,2,1), (2,2,1),
                     (0,0,2), (1,0,2), (2,0,2), (0,1,2), (1,1,2), (2,1,2), (0,2,2), (1,2,2), (2,2,2));
}
)");
    // edge 3, face 12, cube: 6 faces x 4 sub-patches + 3 axes x 4 neighbour pairs.
    CHECK(check_constraints(*c) == 3 + 12 + 24 + 12);
    const front::AutomatonInfo& info = *c->module.find_automaton("block");
    CHECK(info.dof == std::vector<int>{0, 6, 72, 702});
    CHECK(info.automaton.arcs.size() == 1 + 2 + 4 + 8);
    CHECK(info.automaton.embeddings.size() == 2 + 4 + 6);
}

TEST_CASE("seed 004's junction: cells taken from two splines, T^i solved from T^l and T^r", "[bcifs]") {
    auto c = test::compile_ok("import \"bcifs\";");
    const ir::Automaton& a = c->module.find_automaton("spline_junction")->automaton;
    // The paper's T^i with (a, b, c, d, e) = (0.131, 0.2, 0.38, 0.289, 0), (k, l, m, n, p) = (0.11, 0.12,
    // 0.1, 0.12, 0.55): its first 3 columns are T^l's last 3, its last 2 are T^r's first 2.
    const Matrix<Rational> ti = *operator_named(a, "i", "Ti").op.exact;
    const Matrix<Rational> tl = *operator_named(a, "i", "Tl").op.exact;
    const Matrix<Rational> tr = *operator_named(a, "i", "Tr").op.exact;
    const std::vector<std::vector<Rational>> paper = {
        {Rational(1, 8), 0, Rational(131, 1000), Rational(11, 100), 0},
        {Rational(3, 4), Rational(1, 2), Rational(1, 5), Rational(3, 25), 0},
        {Rational(1, 8), Rational(1, 2), Rational(19, 50), Rational(1, 10), 0},
        {0, 0, Rational(289, 1000), Rational(3, 25), Rational(3, 4)},
        {0, 0, 0, Rational(11, 20), Rational(1, 4)}};
    for (std::size_t r = 0; r < 5; ++r) {
        for (std::size_t k = 0; k < 5; ++k) CHECK(ti(r, k) == paper[r][k]);
        for (std::size_t k = 0; k < 3; ++k) CHECK(ti(r, k) == tl(r, k + 1));
        for (std::size_t k = 0; k < 2; ++k) CHECK(ti(r, k + 3) == tr(r, k));
    }
    // The taken cells keep their source's operators: l's halves are the cubic B-spline's.
    CHECK(*operator_named(a, "l", "T0").op.exact ==
          *operator_named(c->module.find_automaton("cubic_spline")->automaton, "e", "T0").op.exact);
    // The intermediate control points are derived: l's last three, r's first two.
    const Matrix<Rational> pi = *operator_named(a, "h", "Pi").op.exact;
    CHECK(pi(0, 0) == 1);
    CHECK(pi(1, 0) == 3);
    CHECK(pi(0, 4) == 8);
    CHECK(pi(1, 4) == 3);
}

TEST_CASE("a triangle patch split 3 shares every side exactly", "[bcifs]") {
    auto c = test::compile_ok(R"(
bcifs tri3 {
  cell v in bary(1);
  cell e in bary(3);
  cell t in bary(6);
  topology e = edge(v) split 3;
  topology t = triangle(e) split 3;
  project = controls((0, 0, 0), (1, 0, 1), (2, 0, 0), (0, 1, 1), (1, 1, 1), (0, 2, 0));
}
)");
    // edge: 2 incidence + 2 adjacency; triangle: 3 sides x 3 pieces + 3 downward x 3 sides.
    CHECK(check_constraints(*c) == 4 + 9 + 9);
    const ir::Automaton& a = c->module.find_automaton("tri3")->automaton;
    CHECK(a.arcs.size() == 1 + 3 + 9);
}

TEST_CASE("free entries drawn from a seed: reproducible, each seed its own", "[bcifs]") {
    const std::string text = R"(
bcifs edge {
  cell v in bary(1);
  cell e in bary(3);
  topology e = edge(v) split 2;
  project = controls((0, 0), (1, 1), (2, 0));
}
)";
    const auto t0 = [&](std::optional<std::uint64_t> seed) {
        driver::CompileOptions options;
        options.free_entry_seed = seed;
        auto c = test::compile_ok(text, options);
        return *operator_named(c->module.find_automaton("edge")->automaton, "e", "T0").op.exact;
    };
    CHECK(t0(7) == t0(7));
    CHECK_FALSE(t0(7) == t0(8));
    CHECK_FALSE(t0(7) == t0(std::nullopt));
    // Most uniform without a seed: 21/64 for every free entry.
    CHECK(t0(std::nullopt)(0, 1) == Rational(21, 64));
}

TEST_CASE("a quad patch over two edge cells, split 3 x 2, shares every side exactly", "[bcifs]") {
    auto c = test::compile_ok(R"(
bcifs patch32 {
  cell v in bary(1);
  cell e in bary(3);
  cell g in bary(4);
  cell f in bary(12);
  topology e = edge(v) split 3;
  topology g = edge(v) split 2;
  topology f = quad(e, g) split 3 x 2;
  project = controls((0,0,0), (1,0,1), (2,0,0), (0,1,1), (1,1,2), (2,1,1),
                     (0,2,1), (1,2,2), (2,2,1), (0,3,0), (1,3,1), (2,3,0));
}
)");
    // e: 2 + 2, g: 2 + 1; patch: 2 x 3 + 2 x 2 incidence, 2 x 2 + 3 x 1 adjacency.
    CHECK(check_constraints(*c) == 4 + 3 + 10 + 7);
    const ir::Automaton& a = c->module.find_automaton("patch32")->automaton;
    CHECK(a.arcs.size() == 1 + 3 + 2 + 6);
    CHECK_THAT(test::errors_of("bcifs b { cell v in bary(1); cell e in bary(3); cell f in bary(9); "
                               "topology e = edge(v) split 2; topology f = quad(e) split 2 x 3; }"),
               Catch::Contains("quad(e, g) takes a second edge cell"));
}
