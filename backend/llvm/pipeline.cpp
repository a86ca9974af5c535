#include "backend/llvm/pipeline.hpp"

#include <llvm/IR/Module.h>
#include <llvm/IR/Verifier.h>
#include <llvm/Passes/PassBuilder.h>
#include <llvm/Support/raw_ostream.h>
#include <llvm/Target/TargetMachine.h>

#include <stdexcept>
#include <string>

namespace frac::jit {

void check_options(const ir::Tape& tape, const ir::EvalOptions& options) {
    if (options.max_terms < 1 || options.max_terms > ir::max_terms_limit)
        throw std::invalid_argument("max_terms out of range");
    if (std::string why = ir::verify_tape(tape); !why.empty())
        throw std::invalid_argument("malformed tape: " + why);
}

void verify_generated(const llvm::Module& module) {
    std::string problems;
    llvm::raw_string_ostream os(problems);
    if (llvm::verifyModule(module, &os))
        throw std::logic_error("jit: generated invalid LLVM IR: " + os.str());
}

void optimize(llvm::Module& m, llvm::TargetMachine* tm) {
    llvm::LoopAnalysisManager lam;
    llvm::FunctionAnalysisManager fam;
    llvm::CGSCCAnalysisManager cgam;
    llvm::ModuleAnalysisManager mam;
    llvm::PassBuilder pb(tm);
    pb.registerModuleAnalyses(mam);
    pb.registerCGSCCAnalyses(cgam);
    pb.registerFunctionAnalyses(fam);
    pb.registerLoopAnalyses(lam);
    pb.crossRegisterProxies(lam, fam, cgam, mam);
    // The generated IR is already SSA with the tape's loop-invariant code hoisted; what it needs is
    // the counters promoted to registers, common subexpressions shared, constant conditions folded
    // and the invariant parts of the lanes' work (zero tests of a coordinate ...) hoisted out of
    // series loops. This pipeline runs at a twentieth of the cost of -O2 and gives the same speed
    // on the standard library (bench/bench_jit.cpp).
    llvm::ModulePassManager mpm;
    if (auto err =
            pb.parsePassPipeline(mpm, "function(sroa,early-cse,simplifycfg,loop-mssa(licm),early-cse,dce)")) {
        std::string s;
        llvm::raw_string_ostream os(s);
        os << err;
        throw std::logic_error("jit: bad pass pipeline: " + os.str());
    }
    mpm.run(m, mam);
}

int default_lanes(bool avx512, bool avx) {
    return avx512 ? 8 : avx ? 4 : 2;
}

} // namespace frac::jit
