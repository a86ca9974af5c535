// Values the generated code looks up instead of recomputing: everything that depends only on a series
// index (and constants) is computed once, at JIT time, with the same numeric core calls and the same
// rounding the interpreter uses at run time, so a table entry is bit-identical to what the interpreter
// would compute for that index. No LLVM here (this file is compiled with -frounding-math).
//
//  - Index tables: an instruction of a series block whose operands are constants, the series index or
//    other such instructions (the carpet's `pow 3, i`) becomes one table of its interval and point
//    values, one entry per index the series can reach.
//  - Series tables (infinite series): gamma^i as the interpreter accumulates it, gamma^(n+1) and the
//    two geometric sums of ir::series_tail for every n. When the tail coefficients A and B are
//    constants, the whole stopping test is tabulated: ir::term_resolution * width(term bound) and the tail
//    itself.
#pragma once

#include "ir/evaluator.hpp"
#include "ir/tape.hpp"

#include <cstdint>
#include <vector>

namespace frac::jit {

using ir::Interval;

// Most entries of one index table; longer finite series compute those instructions at run time.
inline constexpr std::int64_t max_index_table = 1 << 17;

// What is known of every value of a table (or of a constant), for choosing code statically.
struct Facts {
    bool maybe_empty = true;
    bool lo_positive = false; // lo > 0
    bool hi_negative = false; // hi < 0
    bool lo_nonzero = false;  // lo != 0 (also for NaN-free values only)
    bool hi_nonzero = false;
    bool thin = false; // lo == hi in every value (none empty)
    // Both ends finite in every lane (so none empty): a sum with such an operand, or a quotient by
    // such a divisor of known sign, is never NaN (no inf - inf, 0 / 0 or inf / inf).
    bool finite = false;
};
Facts facts_of(const Interval* values, std::size_t n);

struct IndexTable {
    ir::Slot slot = ir::no_slot;
    std::uint32_t series = 0;
    std::vector<Interval> box; // entry k: index start + k
    std::vector<double> point;
    Facts facts;
};

struct SeriesTables {
    bool infinite = false;
    std::int64_t first = 0, last = 0; // indices the loop can reach
    bool const_tail = false;          // A (and B) are constants
    // const_tail: the stopping test and the tail after each index n (entry n - first), from
    // ir::series_term_bound and ir::series_tail themselves.
    std::vector<double> threshold;  // term_resolution * width(series_term_bound(A, B, gamma_n, n))
    std::vector<Interval> tail;     // series_tail(kind, A, B, gamma, n)
    std::vector<double> tail_width; // width(tail)
    // Otherwise: gamma^n as the interpreter accumulates it (powi(gamma, start), then * gamma), for the
    // term bound; the tail itself comes from ir::series_tail at run time.
    std::vector<Interval> gamma_n;
    // Point evaluation: gamma^(start + 1) in round to nearest, as the interpreter starts it.
    double point_gamma_next = 0.0;
    double point_denominator = 1.0; // (1 - gamma)^2 in round to nearest
};

struct Tables {
    std::vector<SeriesTables> series; // by tape series index
    std::vector<int> slot_table;      // slot -> index into index_tables, or -1
    std::vector<IndexTable> index_tables;
    // What is known of every slot's interval value, given boxes without empty coordinates (the only
    // boxes the generated code sees): maybe_empty is a fixed point over the whole tape, orbit states
    // included; the sign facts hold for constants and index tables.
    std::vector<Facts> slot_facts;
};

// Whether op can give an empty interval when its operands' emptiness is `in` (nullptr-free, arity
// entries) and the divisor (for Div) has the facts `divisor`.
bool may_be_empty(ir::Op op, const bool* in, std::int64_t imm, const Facts& divisor);

// Computes every table of the tape. Sets and restores the rounding mode itself.
Tables build_tables(const ir::Tape& tape, const ir::EvalOptions& options);

} // namespace frac::jit
