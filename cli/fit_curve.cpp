// frac fit --method hough|pfif|rfif: fractal interpolation functions and curves fitted to samples.
#include "cli/fit_curve.hpp"

#include "cli/session.hpp"
#include "frontend/builtins.hpp"
#include "frontend/diagnostics.hpp"
#include "frontend/lexer.hpp"
#include "frontend/loader.hpp"
#include "runtime/fit/generate.hpp"
#include "runtime/fit/hough.hpp"
#include "runtime/fit/least_squares.hpp"
#include "support/atomic_file.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <iostream>

namespace frac::cli {

namespace {

// A user error in the data file, located like a compile error (exit 65).
struct DataFileError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

rt::fit::Samples read_samples(const std::string& path, rt::fit::DataKind kind) {
    // As a model is read (a directory, a device or a file past the size limit: refused, with why).
    std::string text, why;
    if (!front::read_file(path, frontend_limits().max_file_bytes, text, why))
        throw UsageError(fmt::format("cannot read '{}': {}", path, why));
    try {
        return rt::fit::parse_csv(text, kind);
    } catch (const rt::fit::SamplesError& e) {
        if (e.line == 0) throw DataFileError(fmt::format("{}: error: {}\n", path, e.what()));
        front::SourceManager sources;
        const auto id = sources.add(path, text);
        front::Diagnostics diags;
        diags.error({id, std::uint32_t(e.line), std::uint32_t(std::max<std::size_t>(e.column, 1))}, e.what());
        throw DataFileError(diags.render(sources));
    }
}

// The model's name: the output file's stem as an identifier.
std::string model_name(const FitCurveOptions& o) {
    std::string name = o.name.empty() ? std::filesystem::path(o.output).stem().string() : o.name;
    for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') c = '_';
    if (name.empty() || std::isdigit(static_cast<unsigned char>(name[0]))) name = "fit_" + name;
    return name;
}

int generate(const FitCurveOptions& o) {
    if (o.output.empty()) throw UsageError("--generate writes a CSV file: give it with -o FILE.csv");
    check_output_writable(o.output);
    rt::fit::FractalFunction f;
    try {
        f = rt::fit::generator(o.generate);
    } catch (const std::invalid_argument&) {
        no_such_name("generator", o.generate, rt::fit::generator_names(), "generators");
    }
    // Feature points (seed 001 sec. 4.1) unless a count of uniform samples is given.
    const rt::fit::Samples s =
        o.points > 0 ? rt::fit::sample(f, std::size_t(o.points)) : rt::fit::feature_points(f, 6);
    support::write_file_atomically(o.output, rt::fit::to_csv(s), "CSV");
    std::cout << fmt::format("wrote {} ({} samples of {})\n", o.output, s.size(), o.generate);
    return 0;
}

// A parameter as printed: rounding noise around 0 shows as 0, not -0.0000.
double shown(double v) {
    return std::abs(v) < 5e-5 ? 0.0 : v;
}

void report_hough(const rt::fit::HoughResult& r) {
    std::cout << fmt::format("hough: {} maps, {} valid; steps a {:.4g} b {:.4g} c {:.4g} d {:.4g} e {:.4g}\n",
                             r.maps, r.valid, r.steps.a, r.steps.b, r.steps.c, r.steps.d, r.steps.e);
    std::cout << "rank     hits       a       b       c       d       e\n";
    for (std::size_t i = 0; i < r.clusters.size(); ++i) {
        const auto& m = r.clusters[i].map;
        std::cout << fmt::format("{:>4} {:>8} {:>7.3f} {:>7.3f} {:>7.3f} {:>7.3f} {:>7.3f}\n", i + 1,
                                 r.clusters[i].hits, m.a, m.b[0], m.c[0][0], m.d, m.e[0]);
    }
}

// The fitted model's name must be free in a model: not a keyword, a builtin function or constant
// (checked before the fit, which takes seconds).
void check_model_name(const std::string& name, bool from_output) {
    front::Diagnostics ignored;
    const std::vector<front::Token> tokens = front::lex(name, 0, ignored);
    const std::vector<std::string> builtins = front::builtin_names();
    const bool keyword = tokens.size() != 2 || tokens[0].kind != front::Tok::ident;
    if (!keyword && !front::is_builtin_constant(name) &&
        std::find(builtins.begin(), builtins.end(), name) == builtins.end())
        return;
    throw UsageError(fmt::format("the model cannot be named '{}'{}: it is {} of the language; {}", name,
                                 from_output ? " (after the output file)" : "",
                                 keyword ? "a keyword" : "a builtin name",
                                 from_output ? "give another with --name" : "choose another --name"));
}

} // namespace

void add_fit_curve_options(CLI::App* fit, FitCurveOptions& o) {
    fit->add_option("--maps", o.maps, "maps of the model (default: 2 for hough, 7 otherwise)")
        ->check(CLI::Range(2, 4096));
    fit->add_option("--grid", o.grid, "pfif: cells of the grid of range and domain end points")
        ->check(CLI::Range(2, 1024))
        ->capture_default_str();
    fit->add_option("--data", o.kind, "auto, function (t,x) or curve (x,y or t,x,y)")
        ->check(CLI::IsMember({"auto", "function", "curve"}))
        ->capture_default_str();
    fit->add_flag("--separable", o.separable, "curves: eight-parameter maps (eq. 8) instead of ten (eq. 9)");
    fit->add_option("--budget", o.budget,
                    "seconds the fit may take (0: no limit); past it nothing is written")
        ->check(CLI::NonNegativeNumber);
    fit->add_option("--generate", o.generate,
                    "write synthetic data instead: table1 (seed 001 Table 1) or "
                    "sierpinski (the hidden-variable curve of Fig. 3)");
    fit->add_option("--points", o.points, "--generate: uniform samples (default: the feature points)")
        ->check(CLI::Range(5, 10000000));
}

int run_fit_curve(const FitCurveOptions& o) {
    if (!o.generate.empty()) return generate(o);
    if (o.file.empty()) throw UsageError("give the data file: frac fit FILE.csv -o MODEL.frac");
    if (!is_curve_fit_method(o.method))
        throw UsageError(fmt::format("no fitting method '{}' for curves: hough, pfif or rfif", o.method));
    if (o.quantize != 0 && o.quantize != 8)
        throw UsageError(
            fmt::format("--quantize {}: curve fits store parameters in 8 bits or in full", o.quantize));
    if (!o.output.empty()) {
        check_output_writable(o.output, {o.file});
        check_model_name(model_name(o), o.name.empty());
    }
    const auto kind = o.kind == "function" ? rt::fit::DataKind::function
                      : o.kind == "curve"  ? rt::fit::DataKind::curve
                                           : rt::fit::DataKind::automatic;
    rt::fit::Samples data;
    try {
        data = read_samples(o.file, kind);
    } catch (const DataFileError& e) {
        std::cerr << e.what();
        return front::exit_compile_error;
    }
    const auto progress = [](const std::string& line) { std::cerr << line << "\n"; };
    const int maps = o.maps > 0 ? o.maps : o.method == "hough" ? 2 : 7;
    std::cout << fmt::format("fit: {} samples of a {}, method {}, {} maps\n", data.size(),
                             data.curve() ? "curve (t -> x, y)" : "function (t -> x)", o.method, maps);
    rt::fit::FractalFunction f;
    rt::fit::LeastSquaresOptions ls;
    ls.maps = maps;
    ls.grid = o.grid;
    ls.recurrent = o.method == "rfif";
    ls.coupled = !o.separable;
    ls.seconds = o.budget;
    ls.progress = progress;
    try {
        if (o.method == "hough") {
            if (data.curve())
                throw UsageError("the Hough recovery takes a function (t,x): use pfif or rfif for a curve");
            rt::fit::HoughOptions h;
            h.seconds = o.budget;
            h.progress = progress;
            h.results = std::max(10, maps);
            const rt::fit::HoughResult r = rt::fit::hough_recover(data, h);
            report_hough(r);
            f = rt::fit::fif_from_clusters(r, data, std::size_t(maps));
            const auto crude = rt::fit::measure(f, data);
            std::cout << fmt::format(
                "the FIF of the top {} clusters: max error {:.4g}, mean squared error {:.4g}\n", maps,
                crude.max_error, crude.mse);
            rt::fit::refit_joins(f, data, ls, rt::fit::join_tolerance(r, data));
        } else {
            f = rt::fit::fit_least_squares(data, ls);
        }
    } catch (const rt::fit::BudgetExceeded& e) {
        throw RunError(fmt::format("{}: the fit did not finish; nothing written", e.what()));
    } catch (const std::runtime_error& e) {
        if (dynamic_cast<const UsageError*>(&e)) throw;
        throw RunError(fmt::format("the fit did not converge: {}; nothing written", e.what()));
    }
    if (o.quantize == 8) {
        rt::fit::quantize8(f, data);
        const std::string why = rt::fit::make_consistent(f, 1e-9 * (f.t1 - f.t0));
        if (!why.empty())
            throw RunError("the 8-bit model is not a fractal function: " + why + "; nothing written");
    }
    const auto error = rt::fit::measure(f, data);
    const std::size_t values = data.size() * (data.curve() ? 3 : 2), parameters = f.parameter_count();
    const std::size_t data_bytes = values * 8, model_bytes = parameters * (o.quantize == 8 ? 1 : 8);
    std::cout << fmt::format("max error {:.4g}, mean squared error {:.4g}, PSNR {:.2f} dB\n", error.max_error,
                             error.mse, error.psnr);
    std::cout << fmt::format(
        "model: {} parameters, {} bytes ({}); data: {} values, {} bytes; compression ratio {:.2f}\n",
        parameters, model_bytes, o.quantize == 8 ? "8 bits each" : "float64", values, data_bytes,
        double(data_bytes) / double(model_bytes));
    for (std::size_t i = 0; i < f.pieces.size(); ++i) {
        const auto& p = f.pieces[i];
        std::cout << fmt::format("  T{}: [{:.4f}, {:.4f}] -> [{:.4f}, {:.4f}]  a {:.4f}  d {:.4f}", i + 1,
                                 shown(p.alpha), shown(p.beta), shown(p.lo), shown(p.hi), shown(p.map.a),
                                 shown(p.map.d));
        if (data.curve())
            std::cout << fmt::format(
                "  b ({:.4f}, {:.4f})  C [[{:.4f}, {:.4f}], [{:.4f}, {:.4f}]]  e ({:.4f}, {:.4f})\n",
                shown(p.map.b[0]), shown(p.map.b[1]), shown(p.map.c[0][0]), shown(p.map.c[0][1]),
                shown(p.map.c[1][0]), shown(p.map.c[1][1]), shown(p.map.e[0]), shown(p.map.e[1]));
        else
            std::cout << fmt::format("  b {:.4f}  c {:.4f}  e {:.4f}\n", shown(p.map.b[0]),
                                     shown(p.map.c[0][0]), shown(p.map.e[0]));
    }
    if (o.output.empty()) return 0;
    const bool partitioned = !f.every_domain_whole() && !f.domains_are_unions_of_ranges(1e-9 * (f.t1 - f.t0));
    const std::string name = model_name(o);
    const std::string text = rt::fit::to_frac(
        f, name,
        fmt::format(
            "// frac fit --method {} of {} ({} samples): max error {:.4g}, mean squared error {:.4g}\n",
            o.method, std::filesystem::path(o.file).filename().string(), data.size(), error.max_error,
            error.mse),
        o.method == "hough" ? 0 : static_cast<std::size_t>(o.grid));
    // The model must compile, its contraction proven, before it replaces anything.
    const auto compiled = driver::compile_source(o.output, text);
    if (!compiled->ok())
        throw RunError(
            fmt::format("the fitted model does not compile (nothing written){}:\n{}",
                        partitioned ? "; a PFIF whose domains do not close up is no automaton: fit an RFIF "
                                      "(--method rfif), or a PFIF on another --grid"
                                    : "",
                        compiled->diags.render(compiled->sources)));
    support::write_file_atomically(o.output, text, "model");
    std::cout << fmt::format("wrote {} ({} {})\n", o.output,
                             f.every_domain_whole() ? "ifs"
                             : partitioned          ? "fif"
                                                    : "cifs",
                             name);
    return 0;
}

} // namespace frac::cli
