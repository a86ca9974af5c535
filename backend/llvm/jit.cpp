#include "backend/llvm/jit.hpp"

#include "backend/interp/interpreter.hpp"
#include "backend/llvm/code_cache.hpp"
#include "backend/llvm/codegen.hpp"
#include "backend/llvm/helpers.hpp"
#include "backend/llvm/pipeline.hpp"
#include "backend/llvm/tables.hpp"
#include "ir/specialize.hpp"

#include <llvm/Bitcode/BitcodeWriter.h>
#include <llvm/ExecutionEngine/Orc/CompileUtils.h>
#include <llvm/ExecutionEngine/Orc/Core.h>
#include <llvm/ExecutionEngine/Orc/JITTargetMachineBuilder.h>
#include <llvm/ExecutionEngine/Orc/LLJIT.h>
#include <llvm/ExecutionEngine/Orc/ThreadSafeModule.h>
#include <llvm/IR/LLVMContext.h>
#include <llvm/IR/Module.h>
#include <llvm/Support/MemoryBuffer.h>
#include <llvm/Support/TargetSelect.h>
#include <llvm/Support/raw_ostream.h>
#include <llvm/Target/TargetMachine.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <mutex>
#include <optional>

namespace frac::jit {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// The generated batch functions (codegen.hpp).
using BatchBoxes = void (*)(const double* boxes, std::int64_t n, double* out, std::uint64_t* stats);
using BatchPoints = void (*)(const double* coords, std::int64_t n, double* out, std::uint64_t* stats);
using BatchCells = void (*)(const CellArgs* cells, std::int64_t n, std::uint8_t* verdicts,
                            std::uint64_t* stats);
static_assert(sizeof(ir::CellVerdict) == 1);

static_assert(sizeof(ir::EvalStats) == 3 * sizeof(std::uint64_t));
static_assert(offsetof(ir::EvalStats, calls) == 0 && offsetof(ir::EvalStats, series_terms) == 8 &&
              offsetof(ir::EvalStats, series_capped) == 16);
static_assert(sizeof(Interval) == 2 * sizeof(double) && offsetof(Interval, hi) == sizeof(double));

std::string to_string(llvm::Error e) {
    std::string s;
    llvm::raw_string_ostream os(s);
    os << e;
    return os.str();
}

// One LLJIT for the process; every compiled tape is a module with its own resource tracker.
class Engine {
public:
    static Engine* get(std::string* why) {
        static std::string error;
        static Engine* engine = create(error); // never destroyed: evaluators may outlive static destructors
        if (!engine && why) *why = error;
        return engine;
    }

    std::unique_ptr<llvm::orc::LLJIT> jit;
    std::unique_ptr<llvm::TargetMachine> tm;      // target information for the optimiser
    std::unique_ptr<llvm::TargetMachine> tm_fast; // the same target, machine code unoptimised
    std::mutex mu;                                // one compile (and one removal) at a time
    std::atomic<std::uint64_t> counter{0};
    bool avx512 = false; // the host has AVX-512F
    bool avx = false;    // ... AVX
    std::string target;  // what decides an object besides its IR (the cache key's part)
    std::string target_fast;

    llvm::TargetMachine& machine(const JitConfig& c) const { return c.fast_codegen ? *tm_fast : *tm; }
    const std::string& target_of(const JitConfig& c) const { return c.fast_codegen ? target_fast : target; }

    int lanes_for(const JitConfig& c, Rounding r) const {
        int lanes = c.lanes;
        if (lanes == 0) lanes = default_lanes(avx512, avx);
        if (lanes != 1 && lanes != 2 && lanes != 4 && lanes != 8 && lanes != 16)
            throw std::invalid_argument("jit: lanes must be 0, 1, 2, 4, 8 or 16");
        if (r == Rounding::avx512 && lanes != 1 && lanes != 8)
            throw std::invalid_argument("jit: AVX-512 rounding works with 1 or 8 lanes");
        return lanes;
    }

    Rounding rounding_for(const JitConfig& c) const {
        switch (c.rounding) {
        case JitConfig::Rounding::constrained: return Rounding::constrained;
        case JitConfig::Rounding::avx512:
            if (!avx512) throw JitError("this host has no AVX-512: cannot generate {ru-sae} code");
            return Rounding::avx512;
        case JitConfig::Rounding::automatic: break;
        }
        return avx512 ? Rounding::avx512 : Rounding::constrained;
    }

private:
    static Engine* create(std::string& error) {
        if (llvm::InitializeNativeTarget() || llvm::InitializeNativeTargetAsmPrinter()) {
            error = "LLVM has no code generator for this host";
            return nullptr;
        }
        auto jtmb = llvm::orc::JITTargetMachineBuilder::detectHost();
        if (!jtmb) {
            error = "cannot describe the host to LLVM: " + to_string(jtmb.takeError());
            return nullptr;
        }
        jtmb->setCodeGenOptLevel(llvm::CodeGenOptLevel::Default);
        auto tm = jtmb->createTargetMachine();
        if (!tm) {
            error = "cannot create an LLVM target machine: " + to_string(tm.takeError());
            return nullptr;
        }
        jtmb->setCodeGenOptLevel(llvm::CodeGenOptLevel::None);
        auto tm_fast = jtmb->createTargetMachine();
        if (!tm_fast) {
            error = "cannot create an LLVM target machine: " + to_string(tm_fast.takeError());
            return nullptr;
        }
        jtmb->setCodeGenOptLevel(llvm::CodeGenOptLevel::Default);
        // Modules are compiled to objects by `tm` or `tm_fast` (compile() below, serialised by `mu`)
        // and linked from there, so that an object can come from the cache.
        auto jit = llvm::orc::LLJITBuilder().setJITTargetMachineBuilder(*jtmb).create();
        if (!jit) {
            error = "cannot start the LLVM ORC JIT: " + to_string(jit.takeError());
            return nullptr;
        }
        llvm::orc::SymbolMap symbols;
        for (const Helper& h : helpers())
            symbols[(*jit)->mangleAndIntern(h.name)] = {llvm::orc::ExecutorAddr::fromPtr(h.address),
                                                        llvm::JITSymbolFlags::Exported |
                                                            llvm::JITSymbolFlags::Callable};
        if (auto err = (*jit)->getMainJITDylib().define(llvm::orc::absoluteSymbols(std::move(symbols)))) {
            error = "cannot register the JIT's helper functions: " + to_string(std::move(err));
            return nullptr;
        }
        auto* e = new Engine;
        for (const std::string& f : jtmb->getFeatures().getFeatures()) {
            if (f == "+avx512f") e->avx512 = true;
            if (f == "+avx") e->avx = true;
        }
        e->jit = std::move(*jit);
        e->tm = std::move(*tm);
        e->tm_fast = std::move(*tm_fast);
        const std::string host = e->tm->getTargetTriple().str() + " " + e->tm->getTargetCPU().str() + " " +
                                 e->tm->getTargetFeatureString().str();
        e->target = host + " codegen-level-default";
        e->target_fast = host + " codegen-level-none";
        return e;
    }
};

std::size_t instruction_count(const llvm::Module& m) {
    std::size_t n = 0;
    for (const llvm::Function& f : m)
        for (const llvm::BasicBlock& b : f) n += b.size();
    return n;
}

std::size_t table_bytes(const Tables& t) {
    std::size_t n = 0;
    for (const IndexTable& x : t.index_tables) n += x.box.size() * 16 + x.point.size() * 8;
    for (const SeriesTables& s : t.series)
        n += s.threshold.size() * 8 + s.tail.size() * 16 + s.tail_width.size() * 8 + s.gamma_n.size() * 16;
    return n;
}

struct Generated {
    std::unique_ptr<llvm::LLVMContext> ctx;
    std::unique_ptr<llvm::Module> module;
    GeneratedNames names;
};

Generated generate_module(const ir::Tape& tape, const ir::EvalOptions& options, const Tables& tables,
                          const std::string& name, Engine* engine, Rounding rounding, int lanes) {
    Generated g;
    g.ctx = std::make_unique<llvm::LLVMContext>();
    g.module = std::make_unique<llvm::Module>(name, *g.ctx);
    if (engine) {
        g.module->setDataLayout(engine->jit->getDataLayout());
        g.module->setTargetTriple(engine->jit->getTargetTriple().str());
    }
    g.names = generate(tape, options, tables, *g.module, name, rounding, lanes);
    verify_generated(*g.module);
    return g;
}

// Machine code of one tape, shared by an evaluator and its clones.
struct Compiled {
    ir::Tape tape;
    ir::EvalOptions options;
    JitConfig config;
    bool has_choices = false; // block 0 has min/max/select instructions to prune
    BatchBoxes boxes = nullptr;
    BatchPoints points = nullptr;
    BatchCells cells = nullptr;
    // Each tape's code is linked into its own library, so that every module can use the same symbol
    // names: its object is then the same in every process, and can be cached.
    llvm::orc::JITDylib* dylib = nullptr;
    CompileInfo info;

    ~Compiled() {
        if (!dylib) return;
        Engine* e = Engine::get(nullptr);
        std::lock_guard<std::mutex> lock(e->mu);
        llvm::consumeError(e->jit->getExecutionSession().removeJITDylib(*dylib));
    }
};

bool calls_externals(const ir::Tape& tape) {
    return std::any_of(tape.externals.begin(), tape.externals.end(),
                       [](const auto& f) { return f != nullptr; });
}

class JitEvaluator final : public ir::Evaluator {
public:
    explicit JitEvaluator(std::shared_ptr<const Compiled> code,
                          std::weak_ptr<ir::SpecializationCache> cache = {})
        : code_(std::move(code)), cache_(std::move(cache)) {}

    int dimension() const override { return code_->tape.inputs; }
    std::string engine() const override { return "jit"; }
    std::unique_ptr<ir::Evaluator> clone() const override {
        return std::make_unique<JitEvaluator>(code_, cache_);
    }
    std::size_t instruction_count() const override { return code_->tape.instruction_count(); }

    // Choices are recorded with the interpreter (the generated code keeps no register file); the
    // interpreter's enclosures are the JIT's bit for bit, so both engines prune alike.
    bool may_specialize() const override {
        return code_->options.prune && code_->has_choices && !cache_.expired();
    }
    bool may_specialize_now(double expected_evaluations) override {
        return static_cast<bool>(may_record(expected_evaluations));
    }
    std::shared_ptr<ir::Evaluator> specialize(const Interval* box, double expected_evaluations) override {
        const auto cache = may_record(expected_evaluations);
        if (!cache) return nullptr;
        const auto t0 = Clock::now();
        if (!recorder_) recorder_ = std::make_unique<interp::ChoiceRecorder>(code_->tape, code_->options);
        const std::vector<ir::Choice> choices = recorder_->record(box);
        specialize_stats.record_ms += ms_since(t0);
        ++specialize_stats.requests;
        return cache->get(code_->tape, choices, expected_evaluations, specialize_stats);
    }

    // The cache when a recording for this many evaluations could pay (SpecializationCache::may_pay),
    // else null.
    std::shared_ptr<ir::SpecializationCache> may_record(double expected_evaluations) {
        if (!code_->options.prune || !code_->has_choices ||
            expected_evaluations < jit_min_expected_evaluations)
            return nullptr;
        auto cache = cache_.lock();
        if (!cache) return nullptr;
        if (cost_ < 0) cost_ = ir::tape_cost(code_->tape);
        // A recording is an evaluation by the tape interpreter.
        if (!cache->may_pay(cost_, expected_evaluations, interp::tape_eval_ns_per_cost * cost_))
            return nullptr;
        return cache;
    }

    void own_cache(std::shared_ptr<ir::SpecializationCache> cache) {
        cache_ = cache;
        owned_cache_ = std::move(cache);
    }

    double eval_point(const double* coords) override {
        double r;
        code_->points(coords, 1, &r, counters());
        return r;
    }

    void eval_points(const double* coords, std::size_t n, double* out) override {
        if (n) code_->points(coords, static_cast<std::int64_t>(n), out, counters());
    }

    Interval eval_box(const Interval* box) override {
        Interval r;
        eval_boxes(box, 1, &r);
        return r;
    }

    void eval_boxes(const Interval* boxes, std::size_t n, Interval* out) override {
        num::UpwardRounding up; // once per batch
        const auto d = static_cast<std::size_t>(code_->tape.inputs);
        // The generated code assumes non-empty coordinates (that lets it drop most emptiness tests);
        // a box with an empty coordinate goes to the interpreter, which is the definition anyway.
        std::size_t i = 0;
        while (i < n) {
            std::size_t j = i;
            while (j < n && !has_empty(boxes + j * d, d)) ++j;
            if (j > i)
                code_->boxes(reinterpret_cast<const double*>(boxes + i * d), static_cast<std::int64_t>(j - i),
                             reinterpret_cast<double*>(out + i), counters());
            if (j < n) {
                out[j] = fallback(boxes + j * d);
                ++j;
            }
            i = j;
        }
    }

    // The boxes from the grid's tables and the verdicts in the generated code: no boxes in memory, no
    // test of each box for empty coordinates (a grid knows whether its tables are non-empty).
    void eval_cells(const ir::CellGrid& grid, const std::uint32_t* coords, std::size_t stride, std::size_t n,
                    ir::CellVerdict* out, bool closed_inside) override {
        if (!grid.nonempty()) {
            Evaluator::eval_cells(grid, coords, stride, n, out, closed_inside);
            return;
        }
        grid.check(dimension(), coords, stride, n);
        if (n == 0) return;
        CellArgs args{};
        for (int a = 0; a < grid.dimension(); ++a)
            args.axis[a] = reinterpret_cast<const double*>(grid.axis(a));
        args.coords = coords;
        args.stride = static_cast<std::int64_t>(stride);
        args.closed_inside = closed_inside ? 1 : 0;
        num::UpwardRounding up;
        code_->cells(&args, static_cast<std::int64_t>(n), reinterpret_cast<std::uint8_t*>(out), counters());
    }

    const CompileInfo& info() const { return code_->info; }

private:
    static bool has_empty(const Interval* box, std::size_t d) {
        for (std::size_t k = 0; k < d; ++k)
            if (box[k].is_empty()) return true;
        return false;
    }
    std::uint64_t* counters() { return reinterpret_cast<std::uint64_t*>(&stats); }

    Interval fallback(const Interval* box) {
        if (!interp_) interp_ = interp::make_interpreter(code_->tape, code_->options);
        interp_->stats = {};
        const Interval r = interp_->eval_box(box);
        stats += interp_->stats;
        return r;
    }

    std::shared_ptr<const Compiled> code_;
    std::unique_ptr<ir::Evaluator> interp_;
    std::weak_ptr<ir::SpecializationCache> cache_;
    std::shared_ptr<ir::SpecializationCache> owned_cache_; // the root of a family owns the cache
    std::unique_ptr<interp::ChoiceRecorder> recorder_;
    double cost_ = -1; // ir::tape_cost of the tape, once asked
};

} // namespace

bool jit_available(std::string* why) {
    return Engine::get(why) != nullptr;
}

bool host_has_avx512() {
    Engine* e = Engine::get(nullptr);
    return e && e->avx512;
}

namespace {

std::shared_ptr<const Compiled> compile(const ir::Tape& tape, const ir::EvalOptions& options,
                                        const JitConfig& config) {
    const auto t0 = Clock::now();
    check_options(tape, options);
    std::string why;
    Engine* engine = Engine::get(&why);
    if (!engine) throw JitError("the LLVM JIT is not available: " + why);

    const Rounding rounding = engine->rounding_for(config);
    const int lanes = engine->lanes_for(config, rounding);
    auto code = std::make_shared<Compiled>();
    code->tape = tape;
    code->options = options;
    code->config = config;
    code->has_choices = ir::has_choices(tape);
    CompileInfo& info = code->info;
    info.rounding = rounding == Rounding::avx512 ? "avx512" : "constrained";
    info.lanes = lanes;
    info.fast_codegen = config.fast_codegen;

    auto t = Clock::now();
    const Tables tables = build_tables(tape, options);
    info.tables_ms = ms_since(t);
    info.table_bytes = table_bytes(tables);

    std::lock_guard<std::mutex> lock(engine->mu);
    t = Clock::now();
    Generated g = generate_module(tape, options, tables, "frac", engine, rounding, lanes);
    info.codegen_ms = ms_since(t);

    std::unique_ptr<llvm::MemoryBuffer> object;
    std::optional<CodeCache> cache;
    std::string key;
    if (!config.cache_dir.empty() && !calls_externals(tape)) {
        t = Clock::now();
        cache.emplace(config.cache_dir, config.cache_max_bytes);
        // The module's bitcode (deterministic, like its text, and written about 10x faster than the
        // text is printed: 0.5 s of a 12,000-instruction tape's cache hit was printing).
        llvm::SmallVector<char, 0> bitcode;
        llvm::raw_svector_ostream os(bitcode);
        llvm::WriteBitcodeToFile(*g.module, os);
        key = CodeCache::key(std::string_view(bitcode.data(), bitcode.size()), engine->target_of(config));
        object = cache->load(key);
        info.cache = object ? "hit" : "miss";
        info.cache_ms = ms_since(t);
    }
    if (!object && config.cache_only) throw NotCached("jit: the code is not in the cache");
    if (!object) {
        t = Clock::now();
        optimize(*g.module, engine->tm.get());
        info.optimize_ms = ms_since(t);
        info.ir_instructions = instruction_count(*g.module);
        t = Clock::now();
        auto compiled = llvm::orc::SimpleCompiler(engine->machine(config))(*g.module);
        if (!compiled) throw JitError("LLVM could not compile a shape: " + to_string(compiled.takeError()));
        object = std::move(*compiled);
        info.machine_ms = ms_since(t);
        if (cache) {
            t = Clock::now();
            cache->store(key, std::string_view(object->getBufferStart(), object->getBufferSize()));
            info.cache_ms += ms_since(t);
        }
    }

    t = Clock::now();
    auto dylib = engine->jit->createJITDylib("frac" + std::to_string(engine->counter++));
    if (!dylib) throw JitError("the LLVM JIT cannot make a library: " + to_string(dylib.takeError()));
    code->dylib = &*dylib;
    dylib->addToLinkOrder(engine->jit->getMainJITDylib()); // the helpers
    if (auto err = engine->jit->addObjectFile(*dylib, std::move(object)))
        throw JitError("the LLVM JIT rejected an object: " + to_string(std::move(err)));
    auto box = engine->jit->lookup(*dylib, g.names.box);
    if (!box) throw JitError("the LLVM JIT could not link a shape: " + to_string(box.takeError()));
    auto point = engine->jit->lookup(*dylib, g.names.point);
    if (!point) throw JitError("the LLVM JIT could not compile a shape: " + to_string(point.takeError()));
    auto cells = engine->jit->lookup(*dylib, g.names.cells);
    if (!cells) throw JitError("the LLVM JIT could not link a shape: " + to_string(cells.takeError()));
    code->boxes = box->toPtr<BatchBoxes>();
    code->cells = cells->toPtr<BatchCells>();
    code->points = point->toPtr<BatchPoints>();
    info.machine_ms += ms_since(t);
    info.total_ms = ms_since(t0);
    return code;
}

} // namespace

std::unique_ptr<ir::Evaluator> make_jit(const ir::Tape& tape, const ir::EvalOptions& options,
                                        const JitConfig& config) {
    auto root = std::make_unique<JitEvaluator>(compile(tape, options, config));
    // Specialisations are compiled like the shape; they refer to the cache weakly (it owns them).
    auto self = std::make_shared<std::weak_ptr<ir::SpecializationCache>>();
    auto cache = std::make_shared<ir::SpecializationCache>(
        [options, config, self](const ir::Tape& t) -> std::unique_ptr<ir::Evaluator> {
            return std::make_unique<JitEvaluator>(compile(t, options, config), *self);
        },
        jit_prune_costs,
        // Until a pruned tape has earned its compile time, the interpreter runs it when that is faster
        // than the JIT running the whole tape; its enclosures are the JIT's bit for bit.
        [options](const ir::Tape& t) { return interp::make_interpreter(t, options); },
        [](const ir::Tape& t) { return interp::cover_eval_ns(t); });
    *self = cache;
    root->own_cache(std::move(cache));
    return root;
}

const CompileInfo* compile_info(const ir::Evaluator& e) {
    const auto* j = dynamic_cast<const JitEvaluator*>(&e);
    return j ? &j->info() : nullptr;
}

std::string emit_llvm(const ir::Tape& tape, const ir::EvalOptions& options, bool optimized,
                      const JitConfig& config) {
    check_options(tape, options);
    std::string why;
    Engine* engine = Engine::get(&why);
    if (!engine) throw JitError("the LLVM JIT is not available: " + why);
    const Tables tables = build_tables(tape, options);
    std::lock_guard<std::mutex> lock(engine->mu);
    const Rounding rounding = engine->rounding_for(config);
    Generated g =
        generate_module(tape, options, tables, "frac", engine, rounding, engine->lanes_for(config, rounding));
    if (optimized) optimize(*g.module, engine->tm.get());
    std::string s;
    llvm::raw_string_ostream os(s);
    g.module->print(os, nullptr);
    return os.str();
}

} // namespace frac::jit
