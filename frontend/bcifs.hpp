// The BCIFS constraint solver (seed 002 sec. 3): every constraint `P1 * ... * Pk == Q1 * ... * Qm` between
// products of operators is a set of equations on the operators' unknown entries; with the columns of
// barycentric operators summing to 1 and the `fix` statements they form one linear system, solved
// exactly over the rationals (numeric/linear_system.hpp) — or, when an entry is not exact (sqrt(2)/2),
// in floating point with a stated tolerance and a rank-revealing check.
//
// A product is linear when at most one factor has entries that are not yet numbers. Constraints that
// are not linear wait until the solution of the others determines all but one of their factors (so a
// vertex level, then an edge level, then a face level are solved in turn); a constraint still not
// linear when nothing more can be determined is an error naming it. Symbolic parameters (`param`) are
// variables numbered before every unknown entry, so they stay free; the remaining free entries get names
// as in the papers: one letter per (operator, column), the row as index (T0 = [[1, a0, b0], ...]).
#pragma once

#include "frontend/diagnostics.hpp"
#include "numeric/linear_system.hpp"
#include "numeric/matrix.hpp"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace frac::front {

struct BcifsSystem {
    struct Operator {
        std::string cell, name;
        std::size_t cell_index = 0; // the state of `cell`
        std::size_t rows = 0, cols = 0;
        bool barycentric = false; // between barycentric spaces: its columns sum to 1
        // Row by row; nullopt: unknown. A known entry is an affine form over the parameters.
        std::vector<std::optional<num::AffineForm>> entries;
        Location loc;
    };
    struct Factor {
        std::optional<std::size_t> op; // an operator, or the constant matrix
        num::Matrix<num::Rational> constant;
    };
    struct Constraint {
        std::vector<Factor> left, right;
        Location loc;
        std::string text; // as written, for messages
    };
    struct Fix {
        std::size_t op = 0, row = 0, col = 0;
        num::AffineForm value; // over the parameters
        Location loc;
    };
    std::string name;
    std::vector<std::string> params; // variables 0 .. params.size() - 1
    std::vector<std::string> cells;  // by state index
    std::vector<int> cell_order;     // the cells' levels: lower cells own shared free entries
    std::vector<Operator> operators;
    std::vector<Constraint> constraints;
    std::vector<Fix> fixes;
    // Set when an entry is not exact (sqrt(2)/2): the system is solved in floating point with this
    // tolerance (numeric/linear_system.hpp); `inexact_at` is the first such entry.
    std::optional<double> tolerance;
    Location inexact_at;
    Location loc; // the bcifs, for its limits
};

struct BcifsSolution {
    // Every operator's entries, row by row, as affine forms over the free variables (parameters first).
    std::vector<std::vector<num::AffineForm>> entries;
    std::vector<std::string> variable_names; // of every variable that is free (parameters included)
    std::vector<std::size_t> free;           // the free variables that are no parameters
    std::vector<int> dof;                    // per cell: the free entries it owns
    std::size_t unknowns = 0, equations = 0, rank = 0;
    std::optional<double> tolerance; // solved in floating point: entries print as decimals
    bool qr_checked = false;         // and its rank confirmed by QR (linear_system.hpp)

    std::string print_entry(const num::AffineForm& f) const;
};

// Solves the system; errors (a conflict with its minimal set of constraints, a product that stays
// bilinear) go to `diags` and give nullopt. So does a solution whose free entries most_uniform_values
// would give values by dense exact systems whose sizes cubed sum to more than `max_dense`
// (Limits::max_bcifs_dense), reported before they are built.
std::optional<BcifsSolution> solve_bcifs(const BcifsSystem& system, Diagnostics& diags,
                                         std::uint64_t max_dense = UINT64_MAX);

// Values of the free entries (solution.free, in order) that make the operators the most uniform: the
// least-squares choice of every entry of a barycentric operator closest to 1/rows (so columns spread
// their weight, which tends to contract), rounded to multiples of 1/64 (exact and short to print). The
// normal equations are solved exactly per block of free entries that some entry ties together (a column
// of an operator, typically), each as a dense system no larger than the block's entries of several terms.
// `params` holds the parameters' values (the first system.params.size() variables).
std::vector<num::Rational> most_uniform_values(const BcifsSystem& system, const BcifsSolution& solution,
                                               const std::vector<num::Rational>& params);

// The solution as `frac solve` prints it: each operator with exact entries and named free parameters,
// the degrees of freedom per cell, the size of the linear system.
std::string print_bcifs_solution(const BcifsSystem& system, const BcifsSolution& solution);

} // namespace frac::front
