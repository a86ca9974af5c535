// frac compile: shapes -> an object file or a shared library with the C ABI of docs/c-abi.md.
//
// The generated code (backend/llvm/aot.cpp) is linked with the run-time archive libfrac_aot_runtime.a
// (`ld -r`, only the members it needs), then every symbol but the exported functions is made local
// and COMDAT groups are dissolved (`objcopy`), so that several compiled models can live in one program. A
// shared library is that object linked by the C++ driver (it needs the system's libstdc++ and libm, nothing
// of Frac or LLVM).
#include "backend/llvm/aot.hpp"
#include "backend/llvm/jit.hpp"
#include "cli/commands.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace frac::cli {
namespace fs = std::filesystem;

namespace {

// A configured tool if it is there, else the same name looked up in PATH.
std::string tool(const char* configured, const char* fallback) {
    std::error_code ec;
    if (configured[0] != '\0' && fs::exists(configured, ec)) return configured;
    return fallback;
}

void run_tool(const std::vector<std::string>& args, const std::string& what) {
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    std::string line;
    for (const std::string& a : args) line += (line.empty() ? "" : " ") + a;
    pid_t pid = 0;
    if (const int err = posix_spawnp(&pid, argv[0], nullptr, nullptr, argv.data(), environ); err != 0)
        throw RunError(fmt::format("{}: cannot run '{}': {}", what, args[0], std::strerror(err)));
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR)
            throw RunError(fmt::format("{}: lost '{}': {}", what, args[0], std::strerror(errno)));
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        throw RunError(fmt::format("{} failed ({}): {}", what,
                                   WIFEXITED(status) ? fmt::format("exit status {}", WEXITSTATUS(status))
                                                     : std::string("killed by a signal"),
                                   line));
}

// The run-time archive: $FRAC_AOT_RUNTIME, next to the frac binary, or where the build put it.
std::string find_runtime_archive() {
    const char* name = "libfrac_aot_runtime.a";
    std::vector<fs::path> tried;
    if (const char* env = std::getenv("FRAC_AOT_RUNTIME"); env && *env) {
        if (fs::exists(env)) return env;
        throw RunError(fmt::format("FRAC_AOT_RUNTIME names '{}', which does not exist", env));
    }
    std::error_code ec;
    const fs::path self = fs::read_symlink("/proc/self/exe", ec);
    if (!ec) tried.push_back(self.parent_path() / name);
    tried.push_back(FRAC_AOT_RUNTIME_PATH);
    std::string list;
    for (const fs::path& p : tried) {
        if (fs::exists(p, ec)) return p.string();
        list += (list.empty() ? "" : ", ") + p.string();
    }
    throw RunError(fmt::format("cannot find the run-time archive of compiled models ({}); build the "
                               "frac_aot_runtime target or set FRAC_AOT_RUNTIME",
                               list));
}

// A fresh private directory for the intermediate files, removed on scope exit.
class TempDir {
public:
    TempDir() {
        std::string pattern = (fs::temp_directory_path() / "frac-compile-XXXXXX").string();
        if (!mkdtemp(pattern.data()))
            throw RunError(fmt::format("cannot create a temporary directory: {}", std::strerror(errno)));
        path_ = pattern;
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    std::string file(const char* name) const { return (path_ / name).string(); }

private:
    fs::path path_;
};

// Fails early, with the system's reason, when `path` cannot be written.
void check_writable(const std::string& path) {
    std::ofstream probe(path, std::ios::binary | std::ios::app);
    if (!probe) throw RunError(fmt::format("cannot write '{}': {}", path, std::strerror(errno)));
}

// Removes the files the command created unless it succeeded: no empty or half-written model is left.
class OutputsOnFailure {
public:
    void add(const std::string& path) { paths_.push_back(path); }
    void commit() { paths_.clear(); }
    ~OutputsOnFailure() {
        std::error_code ec;
        for (const std::string& p : paths_) fs::remove(p, ec);
    }

private:
    std::vector<std::string> paths_;
};

std::string header_guard(const std::string& header_path) {
    std::string g = "FRAC_MODEL_";
    for (char c : fs::path(header_path).filename().string())
        g += std::isalnum(static_cast<unsigned char>(c))
                 ? static_cast<char>(std::toupper(static_cast<unsigned char>(c)))
                 : '_';
    return g;
}

std::vector<jit::AotShape> chosen_shapes(const front::Compilation& c, const std::vector<std::string>& names) {
    std::vector<const front::ShapeInfo*> infos;
    if (names.empty()) {
        for (const front::ShapeInfo& s : c.module.shapes) infos.push_back(&s);
        if (infos.empty()) throw UsageError("the model defines no shape");
    } else {
        for (const std::string& n : names) {
            const front::ShapeInfo* s = &find_shape(c, n);
            if (std::find(infos.begin(), infos.end(), s) == infos.end()) infos.push_back(s);
        }
    }
    std::vector<jit::AotShape> shapes;
    for (const front::ShapeInfo* s : infos) {
        ir::Tape tape = ir::build_tape(c.module.graph, s->root, s->dimension);
        if (std::string defect = ir::verify_tape(tape); !defect.empty())
            throw front::InternalError("malformed tape: " + defect);
        shapes.push_back({s->name, std::move(tape), s->box});
    }
    return shapes;
}

} // namespace

std::string check_compile_output(const std::string& path) {
    if (ends_with(path, ".o") || ends_with(path, ".so") || ends_with(path, ".ll")) return "";
    return fmt::format(
        "cannot tell what to write to '{}': use .o (object), .so (shared library) or .ll (LLVM IR)", path);
}

int run_compile(const std::string& file, const CompileOptions& o) {
    if (std::string problem = check_compile_output(o.output); !problem.empty()) throw UsageError(problem);
    for (const std::string& path : {o.output, o.header})
        if (!path.empty()) check_output_writable(path);
    jit::AotConfig config;
    config.options.max_terms = o.max_terms;
    config.cpu = o.cpu;
    config.prefix = o.prefix;
    if (!jit::is_c_identifier(config.prefix + "x"))
        throw UsageError(fmt::format("--prefix '{}' cannot begin a C identifier", config.prefix));

    auto c = compile_or_report(file);
    if (!c) return front::exit_compile_error;
    const std::vector<jit::AotShape> shapes = chosen_shapes(*c, o.shapes);
    for (const jit::AotShape& s : shapes)
        if (!jit::is_c_identifier(config.prefix + s.name))
            throw RunError(fmt::format("shape '{}' does not give C names ({}{}_eval_box)", s.name,
                                       config.prefix, s.name));

    const bool ir_only = ends_with(o.output, ".ll");
    const std::string ir_path = ir_only       ? o.output
                                : o.emit_llvm ? fs::path(o.output).replace_extension(".ll").string()
                                              : std::string();
    OutputsOnFailure outputs;
    for (const std::string& path : {o.output, ir_path, o.header}) {
        if (path.empty()) continue;
        std::error_code ec;
        const bool existed = fs::exists(path, ec);
        check_writable(path);
        if (!existed) outputs.add(path);
    }

    const std::string archive = ir_only ? std::string() : find_runtime_archive();
    TempDir tmp;
    const std::string generated = ir_only ? std::string() : tmp.file("generated.o");
    jit::AotInfo info;
    try {
        info = jit::compile_aot(shapes, config, generated, ir_path);
    } catch (const std::invalid_argument& e) {
        throw RunError(e.what());
    } catch (const jit::JitError& e) {
        throw RunError(e.what());
    }

    if (!ir_only) {
        const std::string combined = tmp.file("combined.o");
        run_tool({tool(FRAC_AOT_LD, "ld"), "-r", "-o", combined, generated, archive},
                 "linking the run-time support into the model");
        const std::string object = ends_with(o.output, ".o") ? o.output : tmp.file("model.o");
        // Local symbols in COMDAT groups would still be merged with another model's copies (and the
        // references to the discarded copy break): the groups go, each model keeps its own code.
        std::vector<std::string> localize = {tool(FRAC_AOT_OBJCOPY, "objcopy"), "--strip-debug",
                                             "--remove-section=.group"};
        for (const jit::AotShape& s : shapes)
            for (const char* f :
                 {"eval_point", "eval_points", "eval_box", "eval_boxes", "dimension", "default_box"})
                localize.push_back("--keep-global-symbol=" + jit::aot_symbol(config, s.name, f));
        localize.push_back(combined);
        localize.push_back(object);
        run_tool(localize, "keeping only the model's functions global");
        if (ends_with(o.output, ".so"))
            run_tool({tool(FRAC_AOT_CXX, "c++"), "-shared", "-o", o.output,
                      "-Wl,-soname," + fs::path(o.output).filename().string(), object, "-Wl,-z,noexecstack",
                      "-lm"},
                     "linking the shared library");
    }
    if (!o.header.empty()) {
        std::ofstream h(o.header, std::ios::binary | std::ios::trunc);
        h << jit::aot_header(shapes, config, info, fs::path(file).filename().string(),
                             header_guard(o.header));
        if (!h.flush()) throw RunError(fmt::format("cannot write '{}': {}", o.header, std::strerror(errno)));
    }

    outputs.commit();
    std::string names;
    for (const jit::AotShape& s : shapes) names += (names.empty() ? "" : ", ") + s.name;
    std::cerr << fmt::format(
        "wrote {}{}{}: {} shape{} ({}); {} code for {}, {} rounding, {} lanes, at most {} "
        "series terms\n",
        o.output, ir_path.empty() || ir_only ? "" : ", " + ir_path, o.header.empty() ? "" : ", " + o.header,
        shapes.size(), shapes.size() == 1 ? "" : "s", names, info.cpu, info.triple, info.rounding, info.lanes,
        o.max_terms);
    return 0;
}

} // namespace frac::cli
