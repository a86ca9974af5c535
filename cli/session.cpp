#include "cli/session.hpp"

#include "frontend/suggest.hpp"
#include "support/atomic_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fmt/format.h>
#include <iostream>
#include <mutex>
#include <string_view>

namespace frac::cli {

namespace {
front::ConstOverrides constant_overrides;
std::optional<std::uint64_t> free_entry_seed;
} // namespace

void set_free_entry_seed(std::optional<std::uint64_t> seed) {
    free_entry_seed = seed;
}

void set_constant_overrides(const std::vector<std::string>& sets) {
    constant_overrides.clear();
    for (const std::string& set : sets) {
        const std::size_t eq = set.find('=');
        const std::string name = eq == std::string::npos ? "" : set.substr(0, eq);
        if (name.empty() || !front::is_identifier(name))
            throw UsageError(
                fmt::format("--set needs NAME=VALUE (a constant of the model and its value), not '{}'", set));
        const std::string value = set.substr(eq + 1);
        (void)evaluate_constant(value,
                                fmt::format("--set {}: the value", name)); // a constant, or a usage error
        constant_overrides.push_back({name, value});
    }
}

namespace {

// A limit set by the environment variable `name`, a whole number of `unit` from 1 to `most`.
template <class T>
void limit_from_env(const char* name, const char* unit, double most, T& limit) {
    const auto v = positive_env(name, unit);
    if (!v) return;
    if (*v > most)
        throw UsageError(
            fmt::format("{} must be at most {} {}, not '{}'", name, most, unit, std::getenv(name)));
    limit = static_cast<T>(std::ceil(*v));
}

} // namespace

std::size_t compile_instruction_limit() {
    std::size_t limit = driver::EngineOptions{}.max_compile_instructions;
    limit_from_env("FRAC_MAX_COMPILE_INSTRUCTIONS", "instructions", 1e9, limit);
    return limit;
}

std::string jit_cache_dir() {
    if (const char* dir = std::getenv("FRAC_CACHE_DIR")) return std::string_view(dir) == "off" ? "" : dir;
    if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg == '/')
        return std::string(xdg) + "/frac";
    if (const char* home = std::getenv("HOME"); home && *home == '/')
        return std::string(home) + "/.cache/frac";
    return "";
}

front::Limits frontend_limits() {
    front::Limits l;
    // The nesting limits stop where the work thread's stack (cli/main.cpp) would no longer hold every
    // recursive pass.
    limit_from_env("FRAC_MAX_NESTING", "levels", 100000, l.max_nesting);
    limit_from_env("FRAC_MAX_OPERATORS", "operators", 500000, l.max_operators);
    limit_from_env("FRAC_MAX_CALL_DEPTH", "calls", 10000, l.max_inline_depth);
    limit_from_env("FRAC_MAX_SERIES_NESTING", "series", 1000, l.max_series_nesting);
    limit_from_env("FRAC_MAX_SERIES_TERMS", "terms", 1e9, l.max_finite_terms);
    limit_from_env("FRAC_MAX_INLINE_NODES", "expression nodes", 1e18, l.max_inline_nodes);
    limit_from_env("FRAC_MAX_IMPORT_DEPTH", "files", 10000, l.max_import_depth);
    limit_from_env("FRAC_MAX_BCIFS_UNKNOWNS", "unknown entries", 1e12, l.max_bcifs_unknowns);
    limit_from_env("FRAC_MAX_BCIFS_DENSE", "steps", 1e18, l.max_bcifs_dense);
    limit_from_env("FRAC_MAX_BCIFS_PROOF_WORK", "steps", 1e18, l.max_bcifs_proof_work);
    std::size_t mib = l.max_file_bytes >> 20;
    limit_from_env("FRAC_MAX_FILE_MB", "MiB", 1 << 20, mib);
    l.max_file_bytes = mib << 20;
    return l;
}

std::unique_ptr<front::Compilation> compile_or_report(const std::string& path, driver::Stage stop,
                                                      driver::PassTimes* times) {
    driver::CompileOptions options;
    options.stop = stop;
    options.limits = frontend_limits();
    options.overrides = constant_overrides;
    options.free_entry_seed = free_entry_seed;
    options.times = times;
    auto c = driver::compile_file(path, options);
    if (!c->unknown_overrides.empty()) {
        // A --set of a constant the model lacks is a command-line mistake, reported before any diagnostic.
        const std::string& name = c->unknown_overrides.front();
        std::vector<std::string> consts;
        for (const front::Item& it : c->program.items)
            if (it.kind == front::ItemKind::const_) consts.push_back(it.name);
        const auto near = front::closest_name(name, consts);
        throw UsageError(fmt::format("--set {}: the model has no constant '{}'{} (constants: {})", name, name,
                                     near ? fmt::format("; did you mean '{}'?", *near) : "",
                                     front::list_names(consts)));
    }
    if (!c->ok()) {
        std::cerr << c->diags.render(c->sources);
        const std::size_t n = c->diags.error_count();
        std::cerr << fmt::format("{} error{} in {}\n", n, n == 1 ? "" : "s", path);
        return nullptr;
    }
    if (!c->diags.all().empty()) std::cerr << c->diags.render(c->sources); // warnings
    return c;
}

void no_such_name(const std::string& what, const std::string& name, const std::vector<std::string>& known,
                  const std::string& kind_plural) {
    const auto near = front::closest_name(name, known);
    throw UsageError(fmt::format("no {} '{}' in the model{} ({}: {})", what, name,
                                 near ? fmt::format("; did you mean '{}'?", *near) : "", kind_plural,
                                 front::list_names(known)));
}

const front::ShapeInfo& find_shape(const front::Compilation& c, const std::string& name) {
    if (const front::ShapeInfo* s = c.module.find_shape(name)) return *s;
    std::vector<std::string> known;
    for (const auto& s : c.module.shapes) known.push_back(s.name);
    no_such_name("shape", name, known, "shapes");
}

const front::ShapeInfo& pick_shape(const front::Compilation& c, const std::string& name) {
    if (!name.empty()) return find_shape(c, name);
    if (c.module.shapes.empty()) throw UsageError("the model defines no shape");
    // The last shape of the main file: imported libraries come first.
    return c.module.shapes.back();
}

namespace {

// The parts of `text` between the separators outside parentheses and brackets (a coordinate may be
// max(1, 2) or an interval [0, 1]).
std::vector<std::string> split(const std::string& text, char sep) {
    std::vector<std::string> parts(1);
    int depth = 0;
    for (const char c : text) {
        depth += c == '(' || c == '[' ? 1 : c == ')' || c == ']' ? -1 : 0;
        if (c == sep && depth == 0)
            parts.emplace_back();
        else
            parts.back() += c;
    }
    if (parts.back().empty()) parts.pop_back(); // as getline: no empty part after a final separator
    return parts;
}

std::string point_form(int dimension) {
    return dimension == 2 ? "x,y" : dimension == 3 ? "x,y,z" : fmt::format("{} numbers", dimension);
}
std::string box_form(int dimension) {
    return dimension == 2   ? "x0:x1,y0:y1"
           : dimension == 3 ? "x0:x1,y0:y1,z0:z1"
                            : fmt::format("{} intervals lo:hi", dimension);
}

} // namespace

ConstantValue evaluate_constant(const std::string& text, const std::string& what) {
    // The text is the body of a constant of an otherwise empty model: the language's own parser,
    // name resolution and constant checks apply, and nothing of the user's model is in scope.
    if (text.find_first_of(";\n") != std::string::npos || text.find("//") != std::string::npos)
        throw UsageError(fmt::format("{} '{}' is one expression: no ';', comment or line break", what, text));
    const std::string source = "const value = " + text + ";\nprint value;\n";
    auto c = driver::compile_source("<command line>", source);
    if (!c->ok() || c->program.items.size() != 2 || c->module.prints.size() != 1 ||
        c->module.prints[0].kind != front::ValueKind::scalar) {
        std::string why = "not a number";
        for (const front::Diagnostic& d : c->diags.all())
            if (d.severity == front::Severity::error) {
                why = d.message;
                break;
            }
        throw UsageError(fmt::format("{} '{}' is not a constant expression ({}); write a number or an "
                                     "expression of numbers such as 1/3, 2^-3, sqrt(2)/2, pi/4",
                                     what, text, why));
    }
    const front::Module& m = c->module;
    EngineOptions interpreted;
    interpreted.engine = "interp"; // one evaluation: compiling would cost more than it saves
    auto eval = make_evaluator(m, m.prints[0].nodes[0], 0, interpreted);
    ConstantValue v;
    v.enclosure = eval->eval_box(nullptr);
    v.point = eval->eval_point(nullptr);
    if (v.enclosure.is_empty() || !std::isfinite(v.enclosure.lo) || !std::isfinite(v.enclosure.hi))
        throw UsageError(fmt::format("{} '{}' is not a finite number", what, text));
    return v;
}

std::optional<double> positive_env(const char* name, const char* unit) {
    const char* env = std::getenv(name);
    if (!env) return std::nullopt;
    char* end = nullptr;
    const double v = std::strtod(env, &end);
    if (end != env && *end == '\0' && v > 0 && std::isfinite(v)) return v;
    throw UsageError(fmt::format("{} must be a positive number of {}, not '{}'", name, unit, env));
}

bool ends_with(const std::string& s, const std::string& suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

void check_output_writable(const std::string& path, const std::vector<std::string>& inputs) {
    if (std::string problem = support::output_problem(path); !problem.empty())
        throw UsageError(fmt::format("cannot write '{}': {}", path, problem));
    for (const std::string& input : inputs)
        if (support::same_file(path, input))
            throw UsageError(
                fmt::format("cannot write '{}': it would overwrite the input '{}'", path, input));
}

std::vector<ir::Interval> parse_box(const std::string& text, int dimension) {
    const auto axes = split(text, ',');
    if (static_cast<int>(axes.size()) != dimension)
        throw UsageError(fmt::format("the box '{}' has {} axes; the shape takes {} ({})", text, axes.size(),
                                     dimension, box_form(dimension)));
    std::vector<ir::Interval> box;
    for (const std::string& axis : axes) {
        const auto bounds = split(axis, ':');
        if (bounds.size() != 2) throw UsageError(fmt::format("'{}' is not an interval lo:hi", axis));
        const ir::Interval lo = evaluate_constant(bounds[0], "the bound").enclosure;
        const ir::Interval hi = evaluate_constant(bounds[1], "the bound").enclosure;
        if (!(lo.lo <= hi.hi)) throw UsageError(fmt::format("empty interval '{}': lo > hi", axis));
        box.push_back({lo.lo, hi.hi});
    }
    return box;
}

std::vector<double> parse_point(const std::string& text, int dimension,
                                std::vector<ir::Interval>* enclosure) {
    const auto coords = split(text, ',');
    if (static_cast<int>(coords.size()) != dimension)
        throw UsageError(fmt::format("the point '{}' has {} coordinate{}; the shape takes {} ({})", text,
                                     coords.size(), coords.size() == 1 ? "" : "s", dimension,
                                     point_form(dimension)));
    std::vector<double> p;
    for (const std::string& c : coords) {
        const ConstantValue v = evaluate_constant(c, "the coordinate");
        if (enclosure) enclosure->push_back(v.enclosure);
        p.push_back(v.point);
    }
    return p;
}

std::string format_interval(ir::Interval v) {
    if (v.is_empty()) return "empty";
    return fmt::format("[{}, {}]", v.lo, v.hi);
}

namespace {

struct KeptObjects {
    std::mutex mutex;
    std::vector<std::shared_ptr<void>> objects;
};

KeptObjects& kept_objects() {
    static auto* kept = new KeptObjects; // never destroyed: the process ends with its objects
    return *kept;
}

} // namespace

void keep_for_exit(std::shared_ptr<void> object) {
    KeptObjects& kept = kept_objects();
    const std::lock_guard lock(kept.mutex);
    kept.objects.push_back(std::move(object));
}

bool objects_kept_for_exit() {
    KeptObjects& kept = kept_objects();
    const std::lock_guard lock(kept.mutex);
    return !kept.objects.empty();
}

} // namespace frac::cli
