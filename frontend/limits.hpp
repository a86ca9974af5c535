// The frontend's limits. Each is reported with its value and the environment variable that raises it
// (read by the CLI, cli/session.cpp); the defaults keep every recursive pass within the stack and a bad
// model within a second.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace frac::front {

struct Limits {
    // Expression nesting: parentheses, calls, let, if, prefix operators, `not`, `^` (FRAC_MAX_NESTING).
    int max_nesting = 200;
    // Binary operators and field accesses of one definition (FRAC_MAX_OPERATORS): a chain a + b + ... is a
    // left-deep tree that every later pass recurses along.
    int max_operators = 200000;
    int max_finite_terms = 10000; // terms of a finite series (FRAC_MAX_SERIES_TERMS)
    int max_inline_depth = 64;    // nested function calls (FRAC_MAX_CALL_DEPTH)
    int max_series_nesting = 16;  // FRAC_MAX_SERIES_NESTING
    // Expression nodes of a definition with its calls inlined (inline_size.hpp; FRAC_MAX_INLINE_NODES).
    std::uint64_t max_inline_nodes = 2'000'000;
    int max_import_depth = 64;                          // files open at once along a chain of imports
    std::size_t max_file_bytes = std::size_t{16} << 20; // of a model file (FRAC_MAX_FILE_MB, in MiB)
    // Unknown entries of a bcifs's operators (FRAC_MAX_BCIFS_UNKNOWNS), counted by the type checker before
    // anything is built: solving and choosing values take about 25 us and 1.5 KB per unknown entry
    // (quad(e) split 7 x 7 over bary(7): 117,992, 2 s and 190 MB; split 8 x 8 over bary(8): 262,656).
    std::uint64_t max_bcifs_unknowns = 131'072;
    // The exact dense systems that give a bcifs's free entries their most uniform values, as the sum of
    // their sizes cubed (FRAC_MAX_BCIFS_DENSE), counted before they are built (bcifs.hpp): 2 * 10^7 steps
    // of exact arithmetic take a few seconds.
    std::uint64_t max_bcifs_dense = 20'000'000;
    // The contraction proofs of a bcifs's value choices together (the most uniform values, then up to
    // 7 nearby, or 64 draws from a seed), in products of their interval matrices times the matrices'
    // size cubed (FRAC_MAX_BCIFS_PROOF_WORK): a choice is tried while a whole proof's budget is left
    // (5 * 10^7, about a second). An edge over bary(40) that no choice makes contractive took 9 s to
    // refuse, 72 s with a seed; small systems take a tiny part of it per proof.
    std::uint64_t max_bcifs_proof_work = 100'000'000;
};

// "(NAME raises it)", the end of a limit's message.
inline std::string raised_by(const char* env) {
    return std::string(" (") + env + " raises it)";
}

} // namespace frac::front
