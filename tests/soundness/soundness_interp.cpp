// Soundness of the IR interpreter against MPFI: random expressions over every builtin are lowered to
// the expression graph (with its constant folding), scheduled to a tape and evaluated on random boxes;
// every enclosure must contain the MPFI enclosure of the exact value at sample points of the box.
#include "backend/interp/interpreter.hpp"
#include "ir/semantics.hpp"
#include "ir/tape.hpp"
#include "lower_to_ir.hpp"
#include "oracle.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>

using namespace frac;

namespace {

constexpr int num_vars = 2;

num::Interval interpret(const oracle::Expr& e, const num::Interval* box) {
    ir::Graph g;
    const ir::NodeId root = oracle::lower_to_ir(g, e);
    auto eval = interp::make_interpreter(ir::build_tape(g, root, num_vars));
    return eval->eval_box(box);
}

// The interpreter with rounding left at nearest: what an engine that forgot to set the mode would do.
num::Interval interpret_without_rounding(const oracle::Expr& e, const num::Interval* box) {
    ir::Graph g;
    const ir::NodeId root = oracle::lower_to_ir(g, e);
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
    if (!sound.covered()) {
        std::printf("FAIL: the check shrank: too few points defined or an operator never checked\n");
        ++failed;
    }
    if (sound.violations != 0 || sound.pairs < pairs) {
        std::printf("FAIL: the interpreter is unsound:\n%s\n", sound.first_violation.c_str());
        ++failed;
    }
    if (unsound.violations == 0) {
        std::printf("FAIL: the check did not catch an evaluator without outward rounding\n");
        ++failed;
    }
    std::printf("%d passed, %d failed\n", 3 - failed, failed);
    return failed ? 1 : 0;
}
