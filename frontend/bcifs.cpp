#include "frontend/bcifs.hpp"
#include "frontend/limits.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <map>

namespace frac::front {

namespace {

using num::AffineForm;
using num::Rational;
using Forms = std::vector<AffineForm>; // a matrix's entries, row by row

// The form with every variable replaced by its current value.
AffineForm substitute(const AffineForm& f, const std::vector<AffineForm>& values) {
    AffineForm out;
    out.constant = f.constant;
    for (const auto& [v, a] : f.terms) out.add_scaled(values[v], a);
    return out;
}

// An operator's entries with every variable replaced by its current value.
Forms substitute_all(Forms f, const std::vector<AffineForm>& values) {
    for (AffineForm& e : f) e = substitute(e, values);
    return f;
}

struct Product {
    Forms entries;
    std::size_t rows = 0, cols = 0;
    bool linear = true;
    std::vector<std::size_t> unknown_factors; // indices of factors with non-constant entries
};

// a (r x k) * b (k x c); not linear when both have a non-constant entry.
Product multiply(const Product& a, const Forms& b, std::size_t b_cols) {
    const bool b_constant =
        std::all_of(b.begin(), b.end(), [](const AffineForm& f) { return f.is_constant(); });
    const bool a_constant =
        std::all_of(a.entries.begin(), a.entries.end(), [](const AffineForm& f) { return f.is_constant(); });
    Product p;
    p.rows = a.rows;
    p.cols = b_cols;
    p.linear = a.linear && (a_constant || b_constant);
    if (!p.linear) return p;
    p.entries.assign(p.rows * p.cols, AffineForm{});
    for (std::size_t i = 0; i < p.rows; ++i)
        for (std::size_t j = 0; j < p.cols; ++j) {
            AffineForm& out = p.entries[i * p.cols + j];
            for (std::size_t k = 0; k < a.cols; ++k) {
                const AffineForm &x = a.entries[i * a.cols + k], &y = b[k * b_cols + j];
                if (x.is_constant())
                    out.add_scaled(y, x.constant);
                else
                    out.add_scaled(x, y.constant);
            }
        }
    return p;
}

std::string letters(std::size_t k) {
    std::string s;
    do {
        s.insert(s.begin(), static_cast<char>('a' + k % 26));
        k /= 26;
    } while (k-- > 0);
    return s;
}

std::uint64_t saturating_sum(std::uint64_t a, std::uint64_t b) {
    std::uint64_t s = 0;
    return __builtin_add_overflow(a, b, &s) ? UINT64_MAX : s;
}

std::uint64_t saturating_product(std::initializer_list<std::uint64_t> factors) {
    std::uint64_t p = 1;
    for (std::uint64_t f : factors)
        if (__builtin_mul_overflow(p, f, &p)) return UINT64_MAX;
    return p;
}

// The blocks of the most-uniform least-squares system (most_uniform_values): the free variables
// (solution.free, by their column k) joined when an entry of a barycentric operator depends on both.
struct UniformBlocks {
    std::map<std::size_t, std::size_t> column;     // free variable -> its column k
    std::vector<std::size_t> block, index;         // per column: its block and its index in the block
    std::vector<std::vector<std::size_t>> members; // per block: its columns, increasing
    // Per block: the size of the dense system least_squares solves for it, the number of its rows of
    // several terms when that is smaller than the block and every column has a row of its own, else the
    // block's size.
    std::vector<std::size_t> dense;
};

UniformBlocks uniform_blocks(const BcifsSystem& sys, const BcifsSolution& sol) {
    UniformBlocks out;
    const std::size_t n = sol.free.size();
    for (std::size_t k = 0; k < n; ++k) out.column[sol.free[k]] = k;
    std::vector<std::size_t> parent(n);
    for (std::size_t k = 0; k < n; ++k) parent[k] = k;
    const auto root = [&](std::size_t k) {
        while (parent[k] != k) k = parent[k] = parent[parent[k]];
        return k;
    };
    for (std::size_t j = 0; j < sys.operators.size(); ++j) {
        if (!sys.operators[j].barycentric) continue;
        for (const AffineForm& f : sol.entries[j]) {
            std::optional<std::size_t> first;
            for (const auto& [v, a] : f.terms) {
                const auto c = out.column.find(v);
                if (c == out.column.end()) continue;
                if (!first)
                    first = root(c->second);
                else if (const std::size_t r = root(c->second); r != *first)
                    parent[r] = *first;
            }
        }
    }
    out.block.assign(n, 0);
    out.index.assign(n, 0);
    std::vector<std::optional<std::size_t>> block_of_root(n);
    for (std::size_t k = 0; k < n; ++k) {
        auto& b = block_of_root[root(k)];
        if (!b) {
            b = out.members.size();
            out.members.emplace_back();
        }
        out.block[k] = *b;
        out.index[k] = out.members[*b].size();
        out.members[*b].push_back(k);
    }
    std::vector<std::size_t> several(out.members.size(), 0); // rows of several terms, per block
    std::vector<bool> own(n, false);                         // the column has a row of one term
    for (std::size_t j = 0; j < sys.operators.size(); ++j) {
        if (!sys.operators[j].barycentric) continue;
        for (const AffineForm& f : sol.entries[j]) {
            std::size_t count = 0, last = 0;
            for (const auto& term : f.terms)
                if (const auto c = out.column.find(term.first); c != out.column.end()) {
                    ++count;
                    last = c->second;
                }
            if (count == 1) own[last] = true;
            if (count > 1) ++several[out.block[last]];
        }
    }
    out.dense.resize(out.members.size());
    for (std::size_t b = 0; b < out.members.size(); ++b) {
        const bool all_own =
            std::all_of(out.members[b].begin(), out.members[b].end(), [&](std::size_t k) { return own[k]; });
        out.dense[b] = all_own && several[b] < out.members[b].size() ? several[b] : out.members[b].size();
    }
    return out;
}

// A row of a least-squares system: sum over terms of coefficient * x_index ~ b.
struct LeastSquaresRow {
    std::vector<std::pair<std::size_t, Rational>> terms;
    Rational b;
};

// The x minimising |A x - b| over `size` variables (0 when the normal equations are singular), exactly.
// Dense: the normal equations (A^T A) x = A^T b. By rows (`woodbury`, when every variable has a row of
// its own term): A^T A = D + C^T C with D diagonal (the rows of one term) and C the rows of several, so
// x = y - D^-1 C^T z with y = D^-1 A^T b and (I + C D^-1 C^T) z = C y (the Woodbury identity), a dense
// system as large as C has rows, not as the block (one row for a column summing to 1 with the rest).
std::vector<Rational> least_squares(const std::vector<LeastSquaresRow>& rows, std::size_t size,
                                    bool woodbury) {
    std::vector<Rational> rhs(size);
    for (const LeastSquaresRow& row : rows)
        for (const auto& [i, a] : row.terms) rhs[i] += a * row.b;
    if (!woodbury) {
        num::Matrix<Rational> normal(size, size), r(size, 1);
        for (std::size_t i = 0; i < size; ++i) r(i, 0) = rhs[i];
        for (const LeastSquaresRow& row : rows)
            for (const auto& [i, ai] : row.terms)
                for (const auto& [k, ak] : row.terms) normal(i, k) += ai * ak;
        const auto x = num::solve(normal, r);
        std::vector<Rational> out(size);
        for (std::size_t i = 0; x && i < size; ++i) out[i] = (*x)(i, 0);
        return out;
    }
    std::vector<Rational> diagonal(size);
    std::vector<const LeastSquaresRow*> several;
    for (const LeastSquaresRow& row : rows) {
        if (row.terms.size() == 1)
            diagonal[row.terms[0].first] += row.terms[0].second * row.terms[0].second;
        else
            several.push_back(&row);
    }
    std::vector<Rational> x(size);
    for (std::size_t i = 0; i < size; ++i) x[i] = rhs[i] / diagonal[i];
    const std::size_t d = several.size();
    if (d == 0) return x; // A^T A is diagonal
    num::Matrix<Rational> s(d, d), cy(d, 1);
    std::vector<Rational> scaled(size); // row p of C D^-1, scattered
    for (std::size_t p = 0; p < d; ++p) {
        for (const auto& [i, a] : several[p]->terms) {
            scaled[i] = a / diagonal[i];
            cy(p, 0) += a * x[i];
        }
        for (std::size_t q = 0; q < d; ++q) {
            Rational sum(p == q ? 1 : 0);
            for (const auto& [i, a] : several[q]->terms) sum += a * scaled[i];
            s(p, q) = sum;
        }
        for (const auto& term : several[p]->terms) scaled[term.first] = Rational(0);
    }
    const auto z = num::solve(s, cy);
    if (!z) return std::vector<Rational>(size);
    for (std::size_t p = 0; p < d; ++p)
        for (const auto& [i, a] : several[p]->terms) x[i] -= a * (*z)(p, 0) / diagonal[i];
    return x;
}

} // namespace

std::optional<BcifsSolution> solve_bcifs(const BcifsSystem& sys, Diagnostics& diags,
                                         std::uint64_t max_dense) {
    // Variables: the parameters, then each operator's unknown entries column by column.
    std::vector<Forms> forms(sys.operators.size());
    struct Origin {
        std::size_t op, row, col;
    };
    std::vector<Origin> origin(sys.params.size(), Origin{0, 0, 0});
    for (std::size_t j = 0; j < sys.operators.size(); ++j) {
        const auto& op = sys.operators[j];
        forms[j].resize(op.rows * op.cols);
        for (std::size_t c = 0; c < op.cols; ++c)
            for (std::size_t r = 0; r < op.rows; ++r) {
                const auto& known = op.entries[r * op.cols + c];
                if (known) {
                    forms[j][r * op.cols + c] = *known;
                } else {
                    forms[j][r * op.cols + c] = AffineForm::variable(origin.size());
                    origin.push_back({j, r, c});
                }
            }
    }
    const std::size_t variables = origin.size();
    const std::size_t column_sums = sys.constraints.size(), fixes = column_sums + sys.operators.size();

    std::vector<AffineForm> values(variables);
    for (std::size_t v = 0; v < variables; ++v) values[v] = AffineForm::variable(v);
    std::vector<bool> linear(sys.constraints.size(), false);
    std::size_t linear_count = 0;
    num::LinearSolution solution;
    std::size_t equations = 0;
    for (;;) {
        num::LinearSystem system(variables);
        const auto current = [&](std::size_t j) { return substitute_all(forms[j], values); };
        for (std::size_t j = 0; j < sys.operators.size(); ++j) {
            const auto& op = sys.operators[j];
            if (!op.barycentric) continue;
            const Forms f = current(j);
            for (std::size_t c = 0; c < op.cols; ++c) {
                AffineForm sum;
                sum.constant = Rational(-1);
                for (std::size_t r = 0; r < op.rows; ++r) sum += f[r * op.cols + c];
                system.add(std::move(sum), column_sums + j);
            }
        }
        for (std::size_t k = 0; k < sys.fixes.size(); ++k) {
            const auto& fx = sys.fixes[k];
            const auto& op = sys.operators[fx.op];
            system.add(substitute(forms[fx.op][fx.row * op.cols + fx.col], values) -
                           substitute(fx.value, values),
                       fixes + k);
        }
        std::size_t now_linear = 0;
        for (std::size_t k = 0; k < sys.constraints.size(); ++k) {
            const auto& c = sys.constraints[k];
            Product sides[2];
            for (int s = 0; s < 2; ++s) {
                const auto& factors = s == 0 ? c.left : c.right;
                Product p;
                for (std::size_t i = 0; i < factors.size(); ++i) {
                    const auto& f = factors[i];
                    Forms m;
                    std::size_t rows, cols;
                    if (f.op) {
                        m = current(*f.op);
                        rows = sys.operators[*f.op].rows;
                        cols = sys.operators[*f.op].cols;
                    } else {
                        rows = f.constant.rows();
                        cols = f.constant.cols();
                        for (std::size_t r = 0; r < rows; ++r)
                            for (std::size_t cc = 0; cc < cols; ++cc) {
                                AffineForm e;
                                e.constant = f.constant(r, cc);
                                m.push_back(e);
                            }
                    }
                    if (i == 0) {
                        p.entries = std::move(m);
                        p.rows = rows;
                        p.cols = cols;
                    } else {
                        p = multiply(p, m, cols);
                        if (!p.linear) break;
                    }
                }
                sides[s] = std::move(p);
            }
            if (!sides[0].linear || !sides[1].linear) continue;
            linear[k] = true;
            ++now_linear;
            for (std::size_t e = 0; e < sides[0].entries.size(); ++e)
                system.add(sides[0].entries[e] - sides[1].entries[e], k);
        }
        equations = system.equations();
        solution = system.solve(sys.tolerance);
        if (solution.ill_conditioned) {
            diags.error(
                sys.inexact_at,
                fmt::format("the constraints of bcifs '{}' are too close to a change of rank to solve "
                            "in floating point: elimination finds rank {}, a QR factorisation {} at "
                            "tolerance {:g} (this entry is not exact; exact entries are solved exactly)",
                            sys.name, solution.rank, solution.qr_rank, *sys.tolerance));
            return std::nullopt;
        }
        if (!solution.consistent) {
            // Located at the first source: a constraint, a barycentric operator, or a fix.
            const std::size_t first = solution.conflict.front();
            diags.error(
                first < column_sums ? sys.constraints[first].loc
                : first < fixes     ? sys.operators[first - column_sums].loc
                                    : sys.fixes[first - fixes].loc,
                (solution.conflict.size() == 1
                     ? fmt::format("a constraint of bcifs '{}' cannot hold with these operators", sys.name)
                     : fmt::format("the constraints of bcifs '{}' conflict: no operators satisfy these {} "
                                   "together (without any one of them the rest have a solution)",
                                   sys.name, solution.conflict.size())) +
                    (sys.tolerance
                         ? fmt::format(" (solved in floating point, residuals above {:g})", *sys.tolerance)
                         : std::string()));
            for (std::size_t s : solution.conflict) {
                if (s < column_sums) {
                    diags.note(sys.constraints[s].loc, fmt::format("constraint {}", sys.constraints[s].text));
                } else if (s < fixes) {
                    const auto& op = sys.operators[s - column_sums];
                    diags.note(op.loc, fmt::format("the columns of {}.{} sum to 1 (a barycentric operator)",
                                                   op.cell, op.name));
                } else {
                    const auto& fx = sys.fixes[s - fixes];
                    const auto& op = sys.operators[fx.op];
                    diags.note(fx.loc, fmt::format("fix {}.{}[{}][{}]", op.cell, op.name, fx.row, fx.col));
                }
            }
            return std::nullopt;
        }
        values = solution.values;
        if (now_linear == sys.constraints.size()) break;
        if (now_linear == linear_count) {
            // Nothing more can be determined: the first constraint still bilinear is the error.
            std::size_t k = 0;
            while (linear[k]) ++k;
            const auto& c = sys.constraints[k];
            std::vector<std::string> unknown;
            for (const auto* side : {&c.left, &c.right})
                for (const auto& f : *side)
                    if (f.op) {
                        const Forms cur = substitute_all(forms[*f.op], values);
                        const std::string name =
                            fmt::format("{}.{}", sys.operators[*f.op].cell, sys.operators[*f.op].name);
                        if (std::find(unknown.begin(), unknown.end(), name) == unknown.end() &&
                            std::any_of(cur.begin(), cur.end(),
                                        [](const AffineForm& e) { return !e.is_constant(); }))
                            unknown.push_back(name);
                    }
            diags.error(
                c.loc,
                fmt::format("this constraint multiplies operators whose entries are not determined ({}): "
                            "a product of unknowns is not linear, and the other constraints do not "
                            "determine all but one factor of each product; fix the entries of one of them",
                            fmt::join(unknown, ", ")));
            return std::nullopt;
        }
        linear_count = now_linear;
    }

    BcifsSolution out;
    out.unknowns = variables - sys.params.size();
    out.equations = equations;
    out.rank = solution.rank;
    out.tolerance = sys.tolerance;
    out.qr_checked = solution.qr_checked;
    for (const Forms& f : forms) out.entries.push_back(substitute_all(f, values));
    // Names: the parameters' own, then one letter per (operator, column) of the free entries.
    out.variable_names.assign(variables, "");
    for (std::size_t p = 0; p < sys.params.size(); ++p) out.variable_names[p] = sys.params[p];
    std::map<std::pair<std::size_t, std::size_t>, std::string> group;
    std::size_t next = 0;
    for (std::size_t v : solution.free) {
        if (v < sys.params.size()) continue;
        out.free.push_back(v);
        const auto key = std::pair{origin[v].op, origin[v].col};
        if (!group.count(key)) {
            std::string l;
            do l = letters(next++);
            while (std::find(sys.params.begin(), sys.params.end(), l) != sys.params.end());
            group[key] = l;
        }
        out.variable_names[v] = fmt::format("{}{}", group[key], origin[v].row);
    }
    // Degrees of freedom: a free entry belongs to the lowest cell whose operators use it (the first such
    // operator's cell on a tie), found in one pass over the entries.
    out.dof.assign(sys.cells.size(), 0);
    std::vector<std::optional<std::size_t>> owner(variables);
    for (std::size_t j = 0; j < sys.operators.size(); ++j) {
        const std::size_t cell = sys.operators[j].cell_index;
        for (const AffineForm& e : out.entries[j])
            for (const auto& [v, a] : e.terms) {
                auto& o = owner[v];
                if (!o || sys.cell_order[cell] < sys.cell_order[*o]) o = cell;
            }
    }
    for (std::size_t v : out.free)
        if (owner[v]) ++out.dof[*owner[v]];
    // The dense systems most_uniform_values will solve, refused before it builds them when over the limit.
    const UniformBlocks blocks = uniform_blocks(sys, out);
    std::uint64_t cubes = 0;
    for (std::size_t m : blocks.dense) cubes = saturating_sum(cubes, saturating_product({m, m, m}));
    if (cubes > max_dense) {
        diags.error(sys.loc,
                    fmt::format("bcifs '{}' is too large to give its {} free entries values: the most "
                                "uniform values solve exact dense systems of up to {} unknowns, their "
                                "sizes cubed summing to {}, more than the limit of {}{}; fix some of the "
                                "free entries (frac solve shows them), or split its cells into fewer parts",
                                sys.name, out.free.size(),
                                *std::max_element(blocks.dense.begin(), blocks.dense.end()), cubes, max_dense,
                                raised_by("FRAC_MAX_BCIFS_DENSE")));
        return std::nullopt;
    }
    return out;
}

std::vector<Rational> most_uniform_values(const BcifsSystem& sys, const BcifsSolution& sol,
                                          const std::vector<Rational>& params) {
    const std::size_t n = sol.free.size();
    if (n == 0) return {};
    // Least squares: each entry of a barycentric operator is a row of A (its free variables' coefficients)
    // and of b (1/rows less the rest); the rows are kept by block, in the block's own indices.
    const UniformBlocks blocks = uniform_blocks(sys, sol);
    std::vector<std::vector<LeastSquaresRow>> rows(blocks.members.size());
    for (std::size_t j = 0; j < sys.operators.size(); ++j) {
        const auto& op = sys.operators[j];
        if (!op.barycentric) continue;
        const Rational target(1, static_cast<long>(op.rows));
        for (const AffineForm& f : sol.entries[j]) {
            LeastSquaresRow row;
            std::size_t block = 0;
            row.b = target - f.constant;
            for (const auto& [v, a] : f.terms) {
                if (auto c = blocks.column.find(v); c != blocks.column.end()) {
                    block = blocks.block[c->second];
                    row.terms.emplace_back(blocks.index[c->second], a);
                } else {
                    row.b -= a * params[v];
                }
            }
            if (!row.terms.empty()) rows[block].push_back(std::move(row));
        }
    }
    std::vector<Rational> out(n);
    for (std::size_t b = 0; b < blocks.members.size(); ++b) {
        const std::vector<Rational> x =
            least_squares(rows[b], blocks.members[b].size(), blocks.dense[b] < blocks.members[b].size());
        rows[b] = {};
        for (std::size_t i = 0; i < blocks.members[b].size(); ++i) {
            const mpq_class scaled = x[i].value() * 64 + mpq_class(1, 2);
            mpz_class whole;
            mpz_fdiv_q(whole.get_mpz_t(), scaled.get_num_mpz_t(), scaled.get_den_mpz_t());
            out[blocks.members[b][i]] = Rational(mpq_class(whole, 64));
        }
    }
    return out;
}

std::string BcifsSolution::print_entry(const AffineForm& f) const {
    // Solved in floating point: the shortest decimals that read back as the doubles found.
    const auto number = [&](const Rational& x) {
        return tolerance ? fmt::format("{}", x.to_double()) : x.to_string();
    };
    std::string s;
    if (!f.constant.is_zero() || f.terms.empty()) s = number(f.constant);
    for (const auto& [v, a] : f.terms) {
        const std::string& name = variable_names[v];
        const Rational m = a.sign() < 0 ? -a : a;
        std::string term;
        if (tolerance)
            term = m == Rational(1) ? name : fmt::format("{}*{}", number(m), name);
        else if (m.is_integer())
            term = m == Rational(1) ? name : fmt::format("{}*{}", m.to_string(), name);
        else if (m.numerator() == 1)
            term = fmt::format("{}/{}", name, m.denominator().get_str());
        else
            term = fmt::format("{}*{}/{}", m.numerator().get_str(), name, m.denominator().get_str());
        if (s.empty())
            s = a.sign() < 0 ? "-" + term : term;
        else
            s += (a.sign() < 0 ? " - " : " + ") + term;
    }
    return s;
}

std::string print_bcifs_solution(const BcifsSystem& sys, const BcifsSolution& sol) {
    std::string out = fmt::format("bcifs {}: {} unknown entries, {} equations of rank {}, {} free\n",
                                  sys.name, sol.unknowns, sol.equations, sol.rank, sol.free.size());
    if (sol.tolerance)
        out +=
            fmt::format("  solved in floating point with tolerance {:g} ({}): the entry at line {}:{} is not "
                        "exact\n",
                        *sol.tolerance,
                        sol.qr_checked ? "rank checked by QR"
                                       : fmt::format("rank not checked: the QR check takes systems of up to "
                                                     "{:g} coefficients",
                                                     num::qr_check_limit),
                        sys.inexact_at.line, sys.inexact_at.column);
    for (std::size_t j = 0; j < sys.operators.size(); ++j) {
        const auto& op = sys.operators[j];
        std::vector<std::string> rows;
        for (std::size_t r = 0; r < op.rows; ++r) {
            std::vector<std::string> row;
            for (std::size_t c = 0; c < op.cols; ++c)
                row.push_back(sol.print_entry(sol.entries[j][r * op.cols + c]));
            rows.push_back(fmt::format("[{}]", fmt::join(row, ", ")));
        }
        out += fmt::format("  {}.{} = [{}]\n", op.cell, op.name, fmt::join(rows, ", "));
    }
    std::vector<std::string> dof;
    for (std::size_t c = 0; c < sys.cells.size(); ++c)
        dof.push_back(fmt::format("{} {}", sys.cells[c], sol.dof[c]));
    out += fmt::format("  degrees of freedom: {}\n", fmt::join(dof, ", "));
    return out;
}

} // namespace frac::front
