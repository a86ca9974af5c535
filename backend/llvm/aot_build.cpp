// Compiled models as files and in this process: build_aot links the generated object with the run-time
// support (`frac compile`, docs/c-abi.md "Linking"), make_aot loads such a library as an evaluator.
//
// Linking: `ld -r` with libfrac_aot_runtime.a (only the members the code needs), then every symbol but
// the exported functions is made local and COMDAT groups are dissolved (`objcopy`), so that several
// compiled models can live in one program. A shared library is that object linked by the C++ driver (it
// needs the system's libstdc++ and libm, nothing of Frac or LLVM).
#include "backend/llvm/aot.hpp"
#include "backend/llvm/jit.hpp"
#include "backend/llvm/pipeline.hpp"
#include "support/atomic_file.hpp"
#include "support/process_cleaner.hpp"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <dlfcn.h>
#include <fcntl.h>
#include <filesystem>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace frac::jit {
namespace {
namespace fs = std::filesystem;

bool ends_with(const std::string& s, const std::string& suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

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
        throw JitError(what + ": cannot run '" + args[0] + "': " + std::strerror(err));
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) throw JitError(what + ": lost '" + args[0] + "': " + std::strerror(errno));
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        throw JitError(what + " failed (" +
                       (WIFEXITED(status) ? "exit status " + std::to_string(WEXITSTATUS(status))
                                          : std::string("killed by a signal")) +
                       "): " + line);
}

// A run-time archive of compiled models (libfrac_aot_runtime.a, or one an external function names):
// $FRAC_AOT_RUNTIME names the first and its directory holds the others; else they lie next to the
// running binary or where the build put them.
std::string find_archive(const std::string& name) {
    const fs::path build_dir = fs::path(FRAC_AOT_RUNTIME_PATH).parent_path();
    const bool main_archive = name == fs::path(FRAC_AOT_RUNTIME_PATH).filename().string();
    std::vector<fs::path> tried;
    if (const char* env = std::getenv("FRAC_AOT_RUNTIME"); env && *env) {
        const fs::path p = main_archive ? fs::path(env) : fs::path(env).parent_path() / name;
        if (fs::exists(p)) return p.string();
        throw JitError(main_archive
                           ? std::string("FRAC_AOT_RUNTIME names '") + env + "', which does not exist"
                           : "no '" + name + "' next to FRAC_AOT_RUNTIME ('" + env + "')");
    }
    std::error_code ec;
    const fs::path self = fs::read_symlink("/proc/self/exe", ec);
    if (!ec) tried.push_back(self.parent_path() / name);
    tried.push_back(build_dir / name);
    std::string list;
    for (const fs::path& p : tried) {
        if (fs::exists(p, ec)) return p.string();
        list += (list.empty() ? "" : ", ") + p.string();
    }
    const std::string target = fs::path(name).stem().string().substr(3); // libX.a -> X
    throw JitError("cannot find the run-time archive " + name + " of compiled models (" + list +
                   "); build the " + target + " target or set FRAC_AOT_RUNTIME");
}

// A fresh private directory for intermediate files, removed on scope exit -- and when this process is
// killed: a cleaner process (sh) waits for the end of a pipe that only this process and the tools it runs
// hold open, then removes the directory (support::spawn_cleaner). No destructor runs on SIGKILL; the pipe
// closes all the same.
class TempDir {
public:
    TempDir() {
        std::string pattern = (fs::temp_directory_path() / "frac-compile-XXXXXX").string();
        if (!mkdtemp(pattern.data()))
            throw JitError(std::string("cannot create a temporary directory: ") + std::strerror(errno));
        path_ = pattern;
        start_cleaner();
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path_, ec);
        if (cleaner_ > 0) {
            ::close(alive_fd_); // the cleaner sees the end of its input, finds nothing left and exits
            while (waitpid(cleaner_, nullptr, 0) < 0 && errno == EINTR) {
            }
        }
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    std::string file(const char* name) const { return (path_ / name).string(); }

private:
    void start_cleaner() {
        int fds[2];
        if (pipe2(fds, O_CLOEXEC) != 0) return; // no cleaner: the destructor still removes the directory
        // The write end is inherited by the tools (ld, objcopy, c++): the directory outlives them.
        (void)fcntl(fds[1], F_SETFD, 0);
        const pid_t pid = support::spawn_cleaner(fds[0], "cat >/dev/null; exec rm -rf -- \"$1\"",
                                                 "frac-compile-cleanup", {path_.string()});
        ::close(fds[0]);
        if (pid < 0) {
            ::close(fds[1]);
            return;
        }
        cleaner_ = pid;
        alive_fd_ = fds[1];
    }
    fs::path path_;
    pid_t cleaner_ = -1;
    int alive_fd_ = -1;
};

// A loaded compiled model: the C functions of its one shape (docs/c-abi.md), unloaded with the last
// evaluator that uses it.
class Library {
public:
    using Point = double (*)(const double*);
    using Points = void (*)(const double*, std::size_t, double*);
    using Box = ir::Interval (*)(const ir::Interval*);
    using Boxes = void (*)(const ir::Interval*, std::size_t, ir::Interval*);

    Library(const std::string& path, const AotConfig& config, const std::string& shape) {
        // RTLD_LOCAL: every model exports the same names; each is looked up in its own library.
        handle_ = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
        if (!handle_) throw JitError(std::string("cannot load the compiled model: ") + dlerror());
        auto find = [&](const char* function) {
            const std::string name = aot_symbol(config, shape, function);
            void* p = dlsym(handle_, name.c_str());
            if (!p) {
                dlclose(handle_);
                throw JitError("the compiled model lacks " + name);
            }
            return p;
        };
        point = reinterpret_cast<Point>(find("eval_point"));
        points = reinterpret_cast<Points>(find("eval_points"));
        box = reinterpret_cast<Box>(find("eval_box"));
        boxes = reinterpret_cast<Boxes>(find("eval_boxes"));
    }
    ~Library() { dlclose(handle_); }
    Library(const Library&) = delete;
    Library& operator=(const Library&) = delete;

    Point point;
    Points points;
    Box box;
    Boxes boxes;

private:
    void* handle_ = nullptr;
};

class AotEvaluator final : public ir::Evaluator {
public:
    AotEvaluator(std::shared_ptr<const Library> lib, int dimension, std::size_t instructions)
        : lib_(std::move(lib)), dimension_(dimension), instructions_(instructions) {}

    int dimension() const override { return dimension_; }
    std::string engine() const override { return "aot"; }
    std::size_t instruction_count() const override { return instructions_; }

    // The C functions set and restore the rounding mode themselves.
    double eval_point(const double* coords) override {
        ++stats.calls;
        return lib_->point(coords);
    }
    ir::Interval eval_box(const ir::Interval* box) override {
        ++stats.calls;
        return lib_->box(box);
    }
    void eval_points(const double* coords, std::size_t n, double* out) override {
        stats.calls += n;
        lib_->points(coords, n, out);
    }
    void eval_boxes(const ir::Interval* boxes, std::size_t n, ir::Interval* out) override {
        stats.calls += n;
        lib_->boxes(boxes, n, out);
    }
    std::unique_ptr<ir::Evaluator> clone() const override {
        return std::make_unique<AotEvaluator>(lib_, dimension_, instructions_);
    }

private:
    std::shared_ptr<const Library> lib_;
    int dimension_;
    std::size_t instructions_;
};

} // namespace

AotInfo build_aot(const std::vector<AotShape>& shapes, const AotConfig& config, const std::string& output,
                  const std::string& llvm_ir_path) {
    // The external functions' archives first: their members call the run-time support.
    std::vector<std::string> archives;
    for (const std::string& name : external_archives(shapes)) archives.push_back(find_archive(name));
    archives.push_back(find_archive(fs::path(FRAC_AOT_RUNTIME_PATH).filename().string()));
    TempDir tmp;
    const std::string generated = tmp.file("generated.o");
    const AotInfo info = compile_aot(shapes, config, generated, llvm_ir_path);

    const std::string combined = tmp.file("combined.o");
    std::vector<std::string> link = {tool(FRAC_AOT_LD, "ld"), "-r", "-o", combined, generated};
    link.insert(link.end(), archives.begin(), archives.end());
    run_tool(link, "linking the run-time support into the model");
    const std::string object = tmp.file("model.o");
    // Local symbols in COMDAT groups would still be merged with another model's copies (and the
    // references to the discarded copy break): the groups go, each model keeps its own code.
    std::vector<std::string> localize = {tool(FRAC_AOT_OBJCOPY, "objcopy"), "--strip-debug",
                                         "--remove-section=.group"};
    for (const AotShape& s : shapes)
        for (const char* f :
             {"eval_point", "eval_points", "eval_box", "eval_boxes", "dimension", "default_box"})
            localize.push_back("--keep-global-symbol=" + aot_symbol(config, s.name, f));
    localize.push_back(combined);
    localize.push_back(object);
    run_tool(localize, "keeping only the model's functions global");
    const bool shared = ends_with(output, ".so");
    const std::string built = shared ? tmp.file("model.so") : object;
    if (shared)
        run_tool({tool(FRAC_AOT_CXX, "c++"), "-shared", "-o", built,
                  "-Wl,-soname," + fs::path(output).filename().string(), object, "-Wl,-z,noexecstack", "-lm"},
                 "linking the shared library");
    // The tools wrote in the private directory; the output appears whole or not at all.
    try {
        support::copy_file_atomically(built, output, shared ? "shared library" : "object file");
    } catch (const std::runtime_error& e) {
        throw JitError(e.what());
    }
    return info;
}

std::unique_ptr<ir::Evaluator> make_aot(const ir::Tape& tape, const ir::EvalOptions& options,
                                        const std::string& cpu) {
    check_options(tape, options); // before any file or tool is touched
    AotConfig config;
    config.options = options;
    config.cpu = cpu;
    // The box only fills the C ABI's default_box; a closed expression's inputs are query answers.
    AotShape shape{
        "model", tape,
        std::vector<ir::Interval>(static_cast<std::size_t>(tape.inputs), ir::Interval(-num::inf, num::inf))};
    TempDir tmp;
    const std::string so = tmp.file("model.so");
    build_aot({shape}, config, so);
    // The mapping outlives the file: the directory goes when this returns.
    auto lib = std::make_shared<const Library>(so, config, shape.name);
    return std::make_unique<AotEvaluator>(std::move(lib), tape.inputs, tape.instruction_count());
}

} // namespace frac::jit
