// Soundness of the IR interpreter against MPFI: random expressions over every builtin are lowered to
// the expression graph (with its constant folding), scheduled to a tape and evaluated on random boxes;
// every enclosure must contain the MPFI enclosure of the exact value at sample points of the box.
#include "backend/interp/interpreter.hpp"
#include "ir/semantics.hpp"
#include "ir/tape.hpp"
#include "oracle.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>

using namespace frac;

namespace {

ir::NodeId lower(ir::Graph& g, const oracle::Expr& e) {
    using oracle::Op;
    auto arg = [&](std::size_t i) { return lower(g, e.args[i]); };
    switch (e.op) {
    case Op::Const: return g.constant(e.value);
    case Op::Var: return g.var(e.var);
    case Op::Add: return g.op(ir::Op::Add, arg(0), arg(1));
    case Op::Sub: return g.op(ir::Op::Sub, arg(0), arg(1));
    case Op::Mul: return g.op(ir::Op::Mul, arg(0), arg(1));
    case Op::Div: return g.op(ir::Op::Div, arg(0), arg(1));
    case Op::Neg: return g.op(ir::Op::Neg, arg(0));
    case Op::Sqr: return g.op(ir::Op::Sqr, arg(0));
    case Op::PowInt: return g.op(ir::Op::PowI, arg(0), ir::no_node, ir::no_node, e.n);
    case Op::Pow: return g.op(ir::Op::Pow, arg(0), arg(1));
    case Op::Sqrt: return g.op(ir::Op::Sqrt, arg(0));
    case Op::Abs: return g.op(ir::Op::Abs, arg(0));
    case Op::Min: return g.op(ir::Op::Min, arg(0), arg(1));
    case Op::Max: return g.op(ir::Op::Max, arg(0), arg(1));
    case Op::Floor: return g.op(ir::Op::Floor, arg(0));
    case Op::Ceil: return g.op(ir::Op::Ceil, arg(0));
    case Op::Mod1: return g.op(ir::Op::Mod1, arg(0));
    case Op::Dz: return g.op(ir::Op::Dz, arg(0));
    case Op::Sin: return g.op(ir::Op::Sin, arg(0));
    case Op::Cos: return g.op(ir::Op::Cos, arg(0));
    case Op::Tan: return g.op(ir::Op::Tan, arg(0));
    case Op::Exp: return g.op(ir::Op::Exp, arg(0));
    case Op::Log: return g.op(ir::Op::Log, arg(0));
    case Op::Atan2: return g.op(ir::Op::Atan2, arg(0), arg(1));
    }
    std::abort();
}

constexpr int num_vars = 2;

num::Interval interpret(const oracle::Expr& e, const num::Interval* box) {
    ir::Graph g;
    const ir::NodeId root = lower(g, e);
    auto eval = interp::make_interpreter(ir::build_tape(g, root, num_vars));
    return eval->eval_box(box);
}

// The interpreter with rounding left at nearest: what an engine that forgot to set the mode would do.
num::Interval interpret_without_rounding(const oracle::Expr& e, const num::Interval* box) {
    ir::Graph g;
    const ir::NodeId root = lower(g, e);
    const ir::Tape t = ir::build_tape(g, root, num_vars);
    std::vector<num::Interval> slots(t.num_slots);
    for (const auto& c : t.constants) slots[c.slot] = c.value;
    for (std::size_t k = 0; k < t.input_slots.size(); ++k)
        if (t.input_slots[k] != ir::no_slot) slots[t.input_slots[k]] = box[k];
    for (const ir::Instr& ins : t.blocks[0]) {
        num::Interval a[3];
        for (int i = 0; i < ir::arity(ins.op); ++i) a[i] = slots[ins.in[static_cast<std::size_t>(i)]];
        slots[ins.out] = ir::apply_interval(ins.op, a, ins.imm);
    }
    return slots[t.result];
}

} // namespace

int main(int argc, char** argv) {
    const std::uint64_t pairs = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 1000000;
    const auto start = std::chrono::steady_clock::now();
    const oracle::Report sound = oracle::check_soundness(pairs, 20261201, num_vars, interpret);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("interpreter: %s(%.1f s)\n", sound.summary().c_str(), seconds);
    const oracle::Report unsound = oracle::check_soundness(20000, 7, num_vars, interpret_without_rounding);
    std::printf("interpreter without upward rounding: %llu violations in %llu points\n",
                static_cast<unsigned long long>(unsound.violations),
                static_cast<unsigned long long>(unsound.points_checked));
    int failed = 0;
    if (sound.violations != 0 || sound.pairs < pairs) {
        std::printf("FAIL: the interpreter is unsound:\n%s\n", sound.first_violation.c_str());
        ++failed;
    }
    if (unsound.violations == 0) {
        std::printf("FAIL: the check did not catch an evaluator without outward rounding\n");
        ++failed;
    }
    std::printf("%d passed, %d failed\n", 2 - failed, failed);
    return failed ? 1 : 0;
}
