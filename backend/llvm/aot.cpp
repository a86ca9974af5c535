// frac compile's code generation: the JIT's module (codegen.hpp) for every shape, exported C wrappers
// around it, and an object file from LLVM's TargetMachine. The C ABI is described in docs/c-abi.md.
#include "backend/llvm/aot.hpp"

#include "backend/llvm/codegen.hpp"
#include "backend/llvm/jit.hpp"
#include "backend/llvm/pipeline.hpp"
#include "backend/llvm/tables.hpp"
#include "ir/external.hpp"
#include "support/atomic_file.hpp"

#include <llvm/IR/Constants.h>
#include <llvm/IR/DerivedTypes.h>
#include <llvm/IR/Function.h>
#include <llvm/IR/GlobalVariable.h>
#include <llvm/IR/IRBuilder.h>
#include <llvm/IR/LLVMContext.h>
#include <llvm/IR/LegacyPassManager.h>
#include <llvm/IR/Module.h>
#include <llvm/MC/MCSubtargetInfo.h>
#include <llvm/MC/TargetRegistry.h>
#include <llvm/Support/FileSystem.h>
#include <llvm/Support/TargetSelect.h>
#include <llvm/Support/raw_ostream.h>
#include <llvm/Target/TargetMachine.h>
#include <llvm/Target/TargetOptions.h>
#include <llvm/TargetParser/Host.h>
#include <llvm/TargetParser/SubtargetFeature.h>
#include <llvm/TargetParser/Triple.h>
#include <llvm/Transforms/Utils/ModuleUtils.h>

#include <algorithm>
#include <functional>
#include <map>
#include <memory>
#include <optional>

namespace frac::jit {
namespace {

struct Target {
    std::unique_ptr<llvm::TargetMachine> machine;
    AotInfo info;
    Rounding rounding = Rounding::constrained;
};

// A target machine for this host's architecture and the CPU asked for. Position-independent code,
// so that one object serves executables (PIE) and shared libraries.
Target make_target(const AotConfig& config) {
    static const bool initialised =
        !llvm::InitializeNativeTarget() && !llvm::InitializeNativeTargetAsmPrinter();
    if (!initialised) throw JitError("LLVM has no code generator for this host");
    Target t;
    t.info.triple = llvm::sys::getProcessTriple();
    std::string error;
    const llvm::Target* target = llvm::TargetRegistry::lookupTarget(t.info.triple, error);
    if (!target) throw JitError("LLVM cannot generate code for " + t.info.triple + ": " + error);
    const llvm::Triple triple(t.info.triple);
    std::string features;
    if (config.cpu == "native") {
        t.info.cpu = llvm::sys::getHostCPUName().str();
        llvm::SubtargetFeatures f;
        for (const auto& [name, enabled] : llvm::sys::getHostCPUFeatures()) f.AddFeature(name, enabled);
        features = f.getString();
    } else if (config.cpu == "generic") {
        t.info.cpu = triple.isX86() ? "x86-64" : "generic";
    } else {
        t.info.cpu = config.cpu;
    }
    t.machine.reset(target->createTargetMachine(t.info.triple, t.info.cpu, features, llvm::TargetOptions(),
                                                llvm::Reloc::PIC_, std::nullopt,
                                                llvm::CodeGenOptLevel::Default));
    if (!t.machine) throw JitError("LLVM cannot create a target machine for " + t.info.triple);
    const llvm::MCSubtargetInfo* sti = t.machine->getMCSubtargetInfo();
    if (!sti->isCPUStringValid(t.info.cpu))
        throw std::invalid_argument("LLVM knows no CPU '" + t.info.cpu + "' for " + t.info.triple +
                                    " (try generic, native, x86-64-v2, x86-64-v3, x86-64-v4)");
    // The {ru-sae} form only where the CPU certainly has AVX-512F (as the JIT's automatic choice).
    const bool avx512 = triple.isX86() && sti->checkFeatures("+avx512f");
    const bool avx = triple.isX86() && sti->checkFeatures("+avx");
    t.rounding = avx512 ? Rounding::avx512 : Rounding::constrained;
    t.info.rounding = avx512 ? "avx512" : "constrained";
    t.info.lanes = default_lanes(avx512, avx);
    return t;
}

// The exported functions of one shape around its generated batch functions (docs/c-abi.md).
void add_wrappers(llvm::Module& m, const AotShape& shape, const AotConfig& config,
                  const GeneratedNames& names) {
    llvm::LLVMContext& ctx = m.getContext();
    auto* dbl = llvm::Type::getDoubleTy(ctx);
    auto* i64 = llvm::Type::getInt64Ty(ctx);
    auto* i32 = llvm::Type::getInt32Ty(ctx);
    auto* ptr = llvm::PointerType::get(ctx, 0);
    auto* vd = llvm::Type::getVoidTy(ctx);
    auto* pair = llvm::StructType::get(ctx, {dbl, dbl}); // struct frac_interval, returned in two registers

    llvm::Function* box_fn = m.getFunction(names.box);
    llvm::Function* point_fn = m.getFunction(names.point);
    box_fn->setLinkage(llvm::GlobalValue::InternalLinkage);
    m.getFunction(names.cells)->setLinkage(llvm::GlobalValue::InternalLinkage); // unused by the C ABI
    point_fn->setLinkage(llvm::GlobalValue::InternalLinkage);
    llvm::FunctionCallee eval_boxes = m.getOrInsertFunction(
        "frac_aot_eval_boxes", llvm::FunctionType::get(vd, {ptr, i64, ptr, i64, ptr}, false));
    llvm::FunctionCallee eval_points = m.getOrInsertFunction(
        "frac_aot_eval_points", llvm::FunctionType::get(vd, {ptr, ptr, i64, ptr}, false));

    llvm::IRBuilder<> b(ctx);
    auto define = [&](const char* what, llvm::Type* ret, std::vector<llvm::Type*> args) {
        auto* f = llvm::Function::Create(llvm::FunctionType::get(ret, args, false),
                                         llvm::GlobalValue::ExternalLinkage,
                                         aot_symbol(config, shape.name, what), m);
        f->setDoesNotThrow();
        b.SetInsertPoint(llvm::BasicBlock::Create(ctx, "entry", f));
        return f;
    };
    llvm::Value* dims = b.getInt64(static_cast<std::uint64_t>(shape.tape.inputs));

    llvm::Function* f = define("eval_boxes", vd, {ptr, i64, ptr});
    b.CreateCall(eval_boxes, {box_fn, dims, f->getArg(0), f->getArg(1), f->getArg(2)});
    b.CreateRetVoid();

    f = define("eval_box", pair, {ptr});
    llvm::Value* result = b.CreateAlloca(pair);
    b.CreateCall(eval_boxes, {box_fn, dims, f->getArg(0), b.getInt64(1), result});
    b.CreateRet(b.CreateLoad(pair, result));

    f = define("eval_points", vd, {ptr, i64, ptr});
    b.CreateCall(eval_points, {point_fn, f->getArg(0), f->getArg(1), f->getArg(2)});
    b.CreateRetVoid();

    f = define("eval_point", dbl, {ptr});
    result = b.CreateAlloca(dbl);
    b.CreateCall(eval_points, {point_fn, f->getArg(0), b.getInt64(1), result});
    b.CreateRet(b.CreateLoad(dbl, result));

    define("dimension", i32, {});
    b.CreateRet(b.getInt32(static_cast<std::uint32_t>(shape.tape.inputs)));

    define("default_box", ptr, {});
    if (shape.box.empty()) {
        b.CreateRet(llvm::ConstantPointerNull::get(ptr));
    } else {
        std::vector<double> flat;
        for (const ir::Interval& v : shape.box) {
            flat.push_back(v.lo);
            flat.push_back(v.hi);
        }
        auto* init = llvm::ConstantDataArray::get(ctx, llvm::ArrayRef<double>(flat));
        auto* g = new llvm::GlobalVariable(m, init->getType(), true, llvm::GlobalValue::PrivateLinkage, init,
                                           "frac_aot." + shape.name + ".default_box");
        g->setAlignment(llvm::Align(16));
        b.CreateRet(g);
    }
}

// The external functions a shape calls (by their index in its tape) in the form compiled models carry.
std::map<std::int64_t, ir::ExternalFunction::Compiled> compiled_externals(const AotShape& s) {
    std::map<std::int64_t, ir::ExternalFunction::Compiled> out;
    for (const auto& block : s.tape.blocks)
        for (const ir::Instr& ins : block) {
            if (ins.op != ir::Op::External || out.contains(ins.imm)) continue;
            const auto k = static_cast<std::size_t>(ins.imm);
            const ir::ExternalFunction* f = k < s.tape.externals.size() ? s.tape.externals[k].get() : nullptr;
            if (!f) throw std::logic_error("aot: external function #" + std::to_string(k) + " is not bound");
            std::optional<ir::ExternalFunction::Compiled> c = f->compiled();
            if (!c)
                throw std::invalid_argument("shape '" + s.name + "' calls " + f->name() +
                                            ", which compiled models cannot carry");
            out.emplace(ins.imm, std::move(*c));
        }
    return out;
}

// The record of external function k (an ir::ExternalData over the embedded data) and the getter the
// generated code calls (codegen.hpp): resolve(record), which rebuilds the function at the first call.
llvm::GlobalVariable* add_external_getter(llvm::Module& m, const std::string& name, std::int64_t k,
                                          const ir::ExternalFunction::Compiled& c) {
    llvm::LLVMContext& ctx = m.getContext();
    auto* ptr = llvm::PointerType::get(ctx, 0);
    auto* i64 = llvm::Type::getInt64Ty(ctx);
    const std::string getter = external_getter(name, k);
    auto* bytes = llvm::ConstantDataArray::get(ctx, llvm::ArrayRef<std::uint8_t>(c.data));
    auto* data = new llvm::GlobalVariable(m, bytes->getType(), true, llvm::GlobalValue::PrivateLinkage, bytes,
                                          getter + ".data");
    auto* record_type = llvm::StructType::get(ctx, {ptr, i64, ptr});
    auto* record = new llvm::GlobalVariable(
        m, record_type, false, llvm::GlobalValue::InternalLinkage,
        llvm::ConstantStruct::get(record_type, {llvm::ConstantPointerNull::get(ptr),
                                                llvm::ConstantInt::get(i64, c.data.size()), data}),
        getter + ".record");
    record->setAlignment(llvm::Align(8)); // its first word is accessed atomically
    auto* f = llvm::Function::Create(llvm::FunctionType::get(ptr, {}, false),
                                     llvm::GlobalValue::InternalLinkage, getter, m);
    f->setDoesNotThrow();
    llvm::IRBuilder<> b(llvm::BasicBlock::Create(ctx, "entry", f));
    llvm::FunctionCallee resolve =
        m.getOrInsertFunction(c.resolve, llvm::FunctionType::get(ptr, {ptr}, false));
    llvm::cast<llvm::Function>(resolve.getCallee())->setDoesNotThrow();
    b.CreateRet(b.CreateCall(resolve, {record}));
    return record;
}

// A destructor of the model (run when a library is unloaded or a program exits) that frees what the
// resolvers built.
void add_releases(llvm::Module& m,
                  const std::vector<std::pair<llvm::GlobalVariable*, std::string>>& releases) {
    if (releases.empty()) return;
    llvm::LLVMContext& ctx = m.getContext();
    auto* ptr = llvm::PointerType::get(ctx, 0);
    auto* vd = llvm::Type::getVoidTy(ctx);
    auto* f = llvm::Function::Create(llvm::FunctionType::get(vd, {}, false),
                                     llvm::GlobalValue::InternalLinkage, "frac_aot.release_externals", m);
    llvm::IRBuilder<> b(llvm::BasicBlock::Create(ctx, "entry", f));
    for (const auto& [record, release] : releases)
        b.CreateCall(m.getOrInsertFunction(release, llvm::FunctionType::get(vd, {ptr}, false)), {record});
    b.CreateRetVoid();
    llvm::appendToGlobalDtors(m, f, 0);
}

// Written atomically (support/atomic_file.hpp): a failed or interrupted write leaves the previous file.
void write_file(const std::string& path, const std::function<void(llvm::raw_fd_ostream&)>& write) {
    try {
        support::AtomicFile file(path, "");
        {
            llvm::raw_fd_ostream os(file.descriptor(), /*shouldClose=*/false);
            write(os);
            os.flush();
            if (os.has_error()) {
                const std::string why = os.error().message();
                os.clear_error(); // an error left set is fatal in the destructor
                file.fail(why);
            }
        }
        file.commit();
    } catch (const JitError&) {
        throw;
    } catch (const std::runtime_error& e) {
        throw JitError(e.what());
    }
}

} // namespace

std::vector<std::string> external_archives(const std::vector<AotShape>& shapes) {
    std::vector<std::string> out;
    for (const AotShape& s : shapes)
        for (const auto& [k, c] : compiled_externals(s))
            if (std::find(out.begin(), out.end(), c.archive) == out.end()) out.push_back(c.archive);
    return out;
}

AotInfo compile_aot(const std::vector<AotShape>& shapes, const AotConfig& config,
                    const std::string& object_path, const std::string& llvm_ir_path) {
    for (const AotShape& s : shapes) {
        check_options(s.tape, config.options);
        compiled_externals(s); // throws for a function compiled models cannot carry
        if (!is_c_identifier(config.prefix + s.name))
            throw std::invalid_argument("'" + config.prefix + s.name + "' is not a C identifier");
        if (static_cast<int>(s.box.size()) != s.tape.inputs)
            throw std::invalid_argument("the default box of '" + s.name + "' does not match its dimension");
    }
    Target target = make_target(config);
    if (target.machine->createDataLayout().getPointerSizeInBits() != 64)
        throw JitError(
            "compiled models need a 64-bit target (size_t and int64_t are the same type in the C ABI)");

    llvm::LLVMContext ctx;
    llvm::Module module("frac_model", ctx);
    module.setDataLayout(target.machine->createDataLayout());
    module.setTargetTriple(target.info.triple);
    module.setPICLevel(llvm::PICLevel::BigPIC);
    std::vector<std::pair<llvm::GlobalVariable*, std::string>> releases;
    for (const AotShape& s : shapes) {
        for (auto& [k, c] : compiled_externals(s))
            releases.emplace_back(add_external_getter(module, "frac_aot." + s.name, k, c), c.release);
        const Tables tables = build_tables(s.tape, config.options);
        const GeneratedNames names = generate(s.tape, config.options, tables, module, "frac_aot." + s.name,
                                              target.rounding, target.info.lanes);
        add_wrappers(module, s, config, names);
    }
    add_releases(module, releases);
    verify_generated(module);
    optimize(module, target.machine.get());

    if (!llvm_ir_path.empty())
        write_file(llvm_ir_path, [&](llvm::raw_fd_ostream& os) { module.print(os, nullptr); });
    if (!object_path.empty()) {
        write_file(object_path, [&](llvm::raw_fd_ostream& os) {
            llvm::legacy::PassManager pm;
            if (target.machine->addPassesToEmitFile(pm, os, nullptr, llvm::CodeGenFileType::ObjectFile))
                throw JitError("LLVM cannot write object files for " + target.info.triple);
            pm.run(module);
        });
    }
    return target.info;
}

} // namespace frac::jit
