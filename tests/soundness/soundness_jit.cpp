// Soundness of the LLVM JIT against MPFI: the random expressions of the oracle, lowered to the graph
// and compiled by the JIT, evaluated on random boxes; every enclosure must admit the MPFI enclosure of
// the exact value at sample points of the box.
//
// Compiling one expression takes milliseconds, so the JIT compiles a block of expressions into one
// function, chosen by a third input: select(s == 0, e0, select(s == 1, e1, ...)). With s a thin integer
// the conditions are decided and `select` returns the chosen branch's enclosure unchanged, so each pair
// checks exactly the code the JIT generated for that expression. Each expression is paired with many
// boxes (10^4 expressions x 100 boxes = 10^6 pairs by default).
#include "backend/llvm/jit.hpp"
#include "ir/tape.hpp"
#include "lower_to_ir.hpp"
#include "oracle.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

using namespace frac;

namespace {

constexpr int num_vars = 2;
constexpr int selector_var = num_vars;

// One JIT function for a block of expressions, and where the block starts (the Exprs the oracle hands
// to the enclosure are the elements of the vector it gave to `prepare`).
class CompiledBlock {
public:
    explicit CompiledBlock(jit::JitConfig config) : config_(config) {}

    void compile(const std::vector<oracle::Expr>& block) {
        ir::Graph g;
        const ir::NodeId selector = g.var(selector_var);
        ir::NodeId root = oracle::lower_to_ir(g, block.back());
        for (std::size_t k = block.size() - 1; k-- > 0;) {
            const ir::NodeId chosen = g.op(ir::Op::Eq, selector, g.constant(static_cast<double>(k)));
            root = g.op(ir::Op::Select, chosen, oracle::lower_to_ir(g, block[k]), root);
        }
        eval_ = jit::make_jit(ir::build_tape(g, root, num_vars + 1), {}, config_);
        first_ = block.data();
        ++compiles_;
    }

    // The inputs of expression e of the current block over `box`.
    std::array<num::Interval, num_vars + 1> inputs(const oracle::Expr& e, const num::Interval* box) const {
        const auto k = static_cast<double>(&e - first_);
        return {box[0], box[1], num::Interval{k, k}};
    }

    num::Interval enclose(const oracle::Expr& e, const num::Interval* box) {
        const auto in = inputs(e, box);
        return eval_->eval_box(in.data());
    }

    // Not an enclosure: the JIT's point value at the box's centre, as a thin interval. The check must
    // reject it (it shows that the harness can fail on JIT-compiled code).
    num::Interval point_at_centre(const oracle::Expr& e, const num::Interval* box) {
        const auto in = inputs(e, box);
        double centre[num_vars + 1];
        for (int i = 0; i <= num_vars; ++i) centre[i] = in[i].lo / 2 + in[i].hi / 2;
        const double v = eval_->eval_point(centre);
        return {v, v};
    }

    int compiles() const { return compiles_; }

private:
    jit::JitConfig config_;
    std::unique_ptr<ir::Evaluator> eval_;
    const oracle::Expr* first_ = nullptr;
    int compiles_ = 0;
};

oracle::Report run(std::uint64_t pairs, std::uint64_t seed, CompiledBlock& compiled,
                   bool point_values = false) {
    oracle::Options options;
    options.boxes_per_expr = 100;
    options.exprs_per_block = 100;
    options.prepare = [&](const std::vector<oracle::Expr>& block) { compiled.compile(block); };
    auto enclosure = [&](const oracle::Expr& e, const num::Interval* box) {
        return point_values ? compiled.point_at_centre(e, box) : compiled.enclose(e, box);
    };
    return oracle::check_soundness(pairs, seed, num_vars, enclosure, options);
}

} // namespace

int main(int argc, char** argv) {
    const std::uint64_t pairs = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 1000000;
    std::string why;
    if (!jit::jit_available(&why)) {
        std::printf("FAIL: the JIT cannot be used on this machine: %s\n0 passed, 1 failed\n", why.c_str());
        return 1;
    }
    int passed = 0, failed = 0;
    auto check = [&](bool ok, const std::string& what, const oracle::Report& r) {
        if (ok) {
            ++passed;
            return;
        }
        ++failed;
        std::printf("FAIL: %s\n%s\n", what.c_str(), r.first_violation.c_str());
    };

    // The default code generation (AVX-512 embedded rounding where the host has it), on every pair.
    {
        const auto start = std::chrono::steady_clock::now();
        CompiledBlock compiled({});
        const oracle::Report r = run(pairs, 20261202, compiled);
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        std::printf("jit (%s): %s(%d compiled functions, %.1f s)\n",
                    jit::host_has_avx512() ? "avx512 rounding" : "constrained intrinsics",
                    r.summary().c_str(), compiled.compiles(), s);
        check(r.violations == 0 && r.pairs == pairs, "the JIT is unsound", r);
        check(r.covered(), "the check shrank: too few points defined or an operator never checked", r);
    }
    // The portable form (constrained intrinsics, MXCSR set per call) on a tenth of the pairs, when the
    // default above was the AVX-512 form; scalar code, so both vector widths are covered.
    if (jit::host_has_avx512()) {
        jit::JitConfig portable;
        portable.rounding = jit::JitConfig::Rounding::constrained;
        portable.lanes = 1;
        CompiledBlock compiled(portable);
        const oracle::Report r = run(pairs / 10, 77, compiled);
        std::printf("jit (constrained intrinsics, scalar): %llu pairs, %llu points, %llu violations\n",
                    static_cast<unsigned long long>(r.pairs),
                    static_cast<unsigned long long>(r.points_checked),
                    static_cast<unsigned long long>(r.violations));
        check(r.violations == 0 && r.pairs == pairs / 10, "the portable JIT form is unsound", r);
        check(r.covered(), "the check shrank: too few points defined or an operator never checked", r);
    }
    // The harness must reject JIT point values posing as enclosures.
    {
        CompiledBlock compiled({});
        const oracle::Report r = run(20000, 7, compiled, /*point_values=*/true);
        std::printf("jit point values as enclosures: %llu violations in %llu points\n",
                    static_cast<unsigned long long>(r.violations),
                    static_cast<unsigned long long>(r.points_checked));
        if (r.violations == 0) {
            ++failed;
            std::printf("FAIL: the check did not catch point values posing as enclosures\n");
        } else {
            ++passed;
        }
    }
    std::printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
