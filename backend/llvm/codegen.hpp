// Tape -> LLVM IR. Private to backend/llvm.
//
// Two functions per tape, both loops over a batch:
//   void <name>_box(const double* boxes, i64 n, double* out, u64* stats)     (box_codegen.cpp)
//     boxes: n groups of `inputs` intervals (lo, hi); out: n intervals; stats: ir::EvalStats.
//     The caller holds upward rounding and passes only boxes without empty coordinates.
//   void <name>_point(const double* coords, i64 n, double* out, u64* stats)   (round to nearest)
//
// Interval code mirrors numeric/interval.cpp operation for operation (the same IEEE
// operations in the same order, the same comparisons deciding ties of signed zeros), rounded upward
// by constrained intrinsics or AVX-512 embedded rounding, so that no pass may fold, reorder or merge
// a floating-point operation under the assumption of round-to-nearest. Lower bounds are computed as
// -RU(-x op y). Complex operations call the numeric core (helpers.hpp).
#pragma once

#include "backend/llvm/tables.hpp"
#include "ir/evaluator.hpp"
#include "ir/tape.hpp"

#include <cstdint>
#include <memory>
#include <string>

namespace llvm {
class LLVMContext;
class Module;
} // namespace llvm

namespace frac::jit {

// How the interval code rounds upward: LLVM's constrained intrinsics (portable; the caller sets MXCSR),
// or AVX-512 instructions with embedded rounding ({ru-sae}) where the host has them.
enum class Rounding { constrained, avx512 };

// Two entry points share the box code: <name>_box (above), and
//   void <name>_cells(const CellArgs* cells, i64 n, u8* verdicts, u64* stats)
//     the n cells' boxes from their integer coordinates and the grid's tables, each evaluated as
//     <name>_box evaluates a box, and its verdict (ir::CellVerdict, ir::classify) stored. The caller
//     holds upward rounding and passes in-range coordinates and tables of non-empty intervals.
struct CellArgs {
    const double* axis[3];       // per axis: the cells' intervals (lo, hi), ir::CellGrid::axis
    const std::uint32_t* coords; // cell k, axis a: coords[k * stride + a]
    std::int64_t stride;         // >= the tape's inputs
    std::int64_t closed_inside;  // 1: hi <= 0 is inside (ir::classify)
};

struct GeneratedNames {
    std::string box, point, cells;
};

// The tape's external function k (Op::External) is called through a pointer: the JIT embeds the
// address of the ir::ExternalFunction it runs with; a compiled model cannot, so its module defines,
// before generate, a function `ptr external_getter(name, k)()` returning it (aot.cpp), which the code
// calls instead.
std::string external_getter(const std::string& name, std::int64_t k);

// Emits both functions into `module` (whose data layout and triple the caller has set).
GeneratedNames generate(const ir::Tape& tape, const ir::EvalOptions& options, const Tables& tables,
                        llvm::Module& module, const std::string& name, Rounding rounding, int lanes);

} // namespace frac::jit
