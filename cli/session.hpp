// What every command does first: compile a model, report its diagnostics, and make evaluators.
#pragma once

#include "driver/engines.hpp"
#include "driver/pipeline.hpp"
#include "driver/queries.hpp"
#include "ir/tape.hpp"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace frac::cli {

using driver::EngineOptions;
using driver::make_evaluator;
using driver::RunError;

// A mistake on the command line (unknown shape, bad number, wrong output name): exit code 64.
struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// The --set NAME=VALUE options of the command; every later compile_or_report applies them. Throws
// UsageError when one is not NAME=VALUE or its value is not a constant expression.
void set_constant_overrides(const std::vector<std::string>& sets);
// --seed N: every later compile_or_report gives the free entries of a bcifs values drawn from N.
void set_free_entry_seed(std::optional<std::uint64_t> seed);

// The frontend's limits (frontend/limits.hpp), each raised or lowered by its environment variable
// (FRAC_MAX_NESTING, FRAC_MAX_OPERATORS, FRAC_MAX_CALL_DEPTH, FRAC_MAX_SERIES_NESTING,
// FRAC_MAX_SERIES_TERMS, FRAC_MAX_INLINE_NODES, FRAC_MAX_IMPORT_DEPTH, FRAC_MAX_FILE_MB,
// FRAC_MAX_BCIFS_UNKNOWNS, FRAC_MAX_BCIFS_DENSE, FRAC_MAX_BCIFS_PROOF_WORK); a UsageError
// when one is not a number in its range.
front::Limits frontend_limits();
// The most instructions of compiled code: 20,000, or FRAC_MAX_COMPILE_INSTRUCTIONS (at most 10^9).
std::size_t compile_instruction_limit();
// The JIT's on-disk cache of machine code (backend/llvm/code_cache.hpp): $FRAC_CACHE_DIR ("off" or
// empty: none), else $XDG_CACHE_HOME/frac, else $HOME/.cache/frac, else none.
std::string jit_cache_dir();

// Compiles `path`; on errors prints the diagnostics to stderr and returns null.
// `times`, when not null, gets the time of each stage run.
std::unique_ptr<front::Compilation> compile_or_report(const std::string& path,
                                                      driver::Stage stop = driver::Stage::lower,
                                                      driver::PassTimes* times = nullptr);

// A constant expression given on the command line (`1/3`, `sqrt(2)/2`, `pi/4`), evaluated by the
// language itself in an empty module: its proven enclosure and its point value. `what` names it in
// the UsageError thrown when it is not a constant.
struct ConstantValue {
    ir::Interval enclosure;
    double point = 0;
};
ConstantValue evaluate_constant(const std::string& text, const std::string& what);

bool ends_with(const std::string& s, const std::string& suffix);

// A positive number from the environment variable `name`, or nullopt when it is not set; a UsageError
// naming the variable and `unit` when it is set to anything else.
std::optional<double> positive_env(const char* name, const char* unit);

// Throws UsageError when `path` cannot be written (checked before any work; leaves no file behind), or
// when it names the same file as one of `inputs` (the model, the data), which writing would destroy.
void check_output_writable(const std::string& path, const std::vector<std::string>& inputs = {});

// Throws the UsageError for an unknown name, with the nearest known one and the list.
[[noreturn]] void no_such_name(const std::string& what, const std::string& name,
                               const std::vector<std::string>& known, const std::string& kind_plural);
const front::ShapeInfo& find_shape(const front::Compilation& c, const std::string& name);
// The shape named, or the model's only/first shape when `name` is empty.
const front::ShapeInfo& pick_shape(const front::Compilation& c, const std::string& name);

// Parses "x0:x1,y0:y1[,z0:z1]" into an outward box; "x,y" into a point (and its outward enclosure).
std::vector<ir::Interval> parse_box(const std::string& text, int dimension);
std::vector<double> parse_point(const std::string& text, int dimension, std::vector<ir::Interval>* enclosure);

std::string format_interval(ir::Interval v);

// Large objects a command is done with (a compiled model, a cover), freed by the end of the process
// instead of node by node: freeing a 7000-clause model's syntax tree, graph and cover takes tens of
// milliseconds, as long as drawing its picture (compilers do the same: clang's -disable-free). The
// guard hands its object over when it goes out of scope; main then leaves with std::_Exit once the
// output is flushed (objects_kept_for_exit). Builds with AddressSanitizer free them at once, so that
// every destructor still runs under its checks.
void keep_for_exit(std::shared_ptr<void> object);
bool objects_kept_for_exit();

template <class T>
class FreedAtExit {
public:
    explicit FreedAtExit(T& object) : object_(object) {}
    FreedAtExit(const FreedAtExit&) = delete;
    FreedAtExit& operator=(const FreedAtExit&) = delete;
    ~FreedAtExit() {
#if !defined(__SANITIZE_ADDRESS__)
        try {
            keep_for_exit(std::make_shared<T>(std::move(object_)));
        } catch (const std::bad_alloc&) {
            // no memory to keep it: it is freed as usual
        }
#endif
    }

private:
    T& object_;
};

} // namespace frac::cli
