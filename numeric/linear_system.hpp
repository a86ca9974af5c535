// Sparse linear systems over the rationals, solved exactly, for the BCIFS constraint solver.
//
// Equations are affine forms c + sum a_k x_k = 0 over numbered variables, each tagged with the source it
// came from (a constraint of the model). The solution is the reduced row echelon form with the pivots
// taken from the highest-numbered variables first, so the free variables are the earliest ones: a caller
// that numbers the entries it wants to keep as parameters first gets them as the free ones (the papers'
// T0 = [[1, a0, b0], [0, a1, b1], [0, 1 - a0 - a1, 1 - b0 - b1]] comes from numbering each operator's
// entries column by column). An inconsistent system reports a minimal set of sources that conflict:
// removing any one of them makes the rest consistent.
//
// When the coefficients are not exact (a model's entry is sqrt(2)/2), the caller gives a tolerance: the
// same elimination then runs in floating point with partial pivoting (the largest coefficient of the
// column), a coefficient or residual of at most the tolerance counts as zero, and the rank it finds is
// checked against a rank-revealing factorisation (Eigen's sparse Householder QR with numerical column
// pivoting) at the same tolerance; a system whose rank the two do not agree on is reported as
// ill-conditioned.
#pragma once

#include "numeric/rational.hpp"

#include <cstddef>
#include <map>
#include <optional>
#include <vector>

namespace frac::num {

// c + sum over terms of coefficient * x_variable. Zero coefficients are never stored.
struct AffineForm {
    Rational constant;
    std::map<std::size_t, Rational> terms;

    static AffineForm variable(std::size_t v);
    bool is_constant() const { return terms.empty(); }
    AffineForm& operator+=(const AffineForm& o);
    AffineForm& operator-=(const AffineForm& o);
    AffineForm& operator*=(const Rational& s);
    friend AffineForm operator+(AffineForm a, const AffineForm& b) { return a += b; }
    friend AffineForm operator-(AffineForm a, const AffineForm& b) { return a -= b; }
    friend AffineForm operator*(AffineForm a, const Rational& s) { return a *= s; }
    friend bool operator==(const AffineForm&, const AffineForm&) = default;
    // Adds s * o.
    void add_scaled(const AffineForm& o, const Rational& s);
};

struct LinearSolution {
    bool consistent = true;
    // Solved with a tolerance: the elimination and the QR factorisation found different ranks (the
    // system is too close to a rank change at this tolerance); nothing else is set.
    bool ill_conditioned = false;
    bool qr_checked = false; // the QR check ran (systems up to qr_check_limit coefficients)
    std::size_t qr_rank = 0;
    // When inconsistent: a minimal set of conflicting sources, in increasing order.
    std::vector<std::size_t> conflict;
    // When consistent: every variable as an affine form over the free variables (a free variable is
    // the form x_v itself), and the free variables in increasing order.
    std::vector<AffineForm> values;
    std::vector<std::size_t> free;
    std::size_t rank = 0;
};

// The largest system (equations x variables) whose floating-point rank the QR factorisation checks: the
// sparse QR of a volume cell's system (9,409 x 6,174) takes minutes, a 3 x 3 patch's (1,728 x 2,352)
// seconds (bench/bench_bcifs).
inline constexpr double qr_check_limit = 5e6;

class LinearSystem {
public:
    explicit LinearSystem(std::size_t variables) : variables_(variables) {}
    std::size_t variables() const { return variables_; }
    std::size_t equations() const { return equations_.size(); }
    // Requires form == 0; `source` names where it came from (for conflicts).
    void add(AffineForm form, std::size_t source);
    // Exact without a tolerance; else in floating point, |x| <= tolerance counting as 0 (the values are
    // then the doubles found, as exact rationals).
    LinearSolution solve(std::optional<double> tolerance = std::nullopt) const;

    struct Equation {
        AffineForm form;
        std::size_t source;
    };

private:
    std::size_t variables_;
    std::vector<Equation> equations_;
};

} // namespace frac::num
