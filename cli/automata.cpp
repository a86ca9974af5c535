// frac tree, frac chaos, and render / dimension of automata (ifs, cifs).
#include "cli/commands.hpp"

#include "driver/queries.hpp"
#include "runtime/automata/chaos.hpp"
#include "runtime/automata/dimension.hpp"
#include "runtime/automata/tree.hpp"
#include "runtime/dimension.hpp"

#include <fmt/format.h>
#include <iostream>
#include <stdexcept>

namespace frac::cli {

namespace {

// Runs a runtime job, turning its refusals (std::invalid_argument) into run-time errors.
template <class F>
auto runtime_job(F&& job) {
    try {
        return job();
    } catch (const std::invalid_argument& e) {
        throw RunError(e.what());
    }
}

void check_picture_output(const std::string& path, bool svg_allowed) {
    if (path.empty()) throw UsageError("give the picture file: -o FILE.png");
    if (!ends_with(path, ".png") && !(svg_allowed && ends_with(path, ".svg")))
        throw UsageError(fmt::format("cannot tell the picture format of '{}': use .png{}", path,
                                     svg_allowed ? " or .svg" : ""));
    check_output_writable(path);
}

} // namespace

const front::AutomatonInfo& find_automaton(const front::Compilation& c, const std::string& name) {
    if (const front::AutomatonInfo* a = c.module.find_automaton(name)) return *a;
    std::vector<std::string> known;
    for (const auto& a : c.module.automata) known.push_back(a.name);
    no_such_name("ifs or cifs", name, known, "automata");
}

int run_tree(const std::string& file, const TreeOptions& o) {
    if (o.depth < 0 || o.depth > 24) throw UsageError("--depth must be between 0 and 24");
    if (!o.output.empty()) check_picture_output(o.output, true);
    auto c = compile_or_report(file);
    if (!c) return front::exit_compile_error;
    const ir::Automaton& a = find_automaton(*c, o.name).automaton;
    if (o.output.empty()) { // the text dump (--emit=tree): each node's state and composite operator
        runtime_job([&] {
            rt::write_tree_text(a, o.depth, std::cout, o.matrices);
            return 0;
        });
        return 0;
    }
    runtime_job([&] {
        if (ends_with(o.output, ".svg"))
            rt::write_tree_svg(a, o.depth, o.output);
        else
            rt::write_tree_png(a, o.depth, o.output, o.size);
        return 0;
    });
    std::cout << fmt::format("wrote {} (evaluation tree of {} to depth {})\n", o.output, a.name, o.depth);
    return 0;
}

int run_chaos(const std::string& file, const ChaosCommandOptions& o) {
    check_picture_output(o.output, false);
    if (o.points < 1 || o.points > 4'000'000'000ULL) throw UsageError("-n must be between 1 and 4e9 points");
    if (o.size < 16 || o.size > 8192) throw UsageError("--size must be between 16 and 8192 pixels");
    auto c = compile_or_report(file);
    if (!c) return front::exit_compile_error;
    const ir::Automaton& a = find_automaton(*c, o.name).automaton;
    rt::ChaosOptions co;
    co.points = o.points;
    co.seed = o.seed;
    co.threads = o.threads;
    co.width = o.size;
    const rt::Density d = runtime_job([&] { return rt::chaos_game(a, co); });
    rt::write_density_png(d, o.output);
    std::cout << fmt::format("wrote {} ({} points of {}, seed {}, over [{}, {}] × [{}, {}])\n", o.output,
                             d.recorded, a.name, o.seed, d.x0, d.x1, d.y0, d.y1);
    return 0;
}

int automaton_dimension(const front::AutomatonInfo& info, int from, int to) {
    const rt::SimilarityDimension d = runtime_job([&] { return rt::similarity_dimension(info.automaton); });
    if (d.defined) {
        std::cout << fmt::format("similarity dimension of {}: {:.12f} in [{:.15f}, {:.15f}] ({})\n",
                                 info.name, d.value, d.bracket.lo, d.bracket.hi, d.method);
        return 0;
    }
    // Maps that are not similitudes: box counting of the chaos-game cover.
    std::cout << fmt::format("{} has no similarity dimension: {}\n", info.name, d.reason);
    if (to > 12) throw UsageError("the chaos-game cover of an automaton goes to --to 12 at most");
    rt::ChaosOptions co;
    co.points = std::uint64_t{1} << std::min(2 * to + 4, 30);
    const rt::Cover cover = runtime_job([&] { return rt::chaos_cover(info.automaton, to, co, false); });
    const rt::DimensionEstimate e = runtime_job([&] { return rt::box_counting(cover, from, to); });
    for (const auto& [level, count] : e.counts)
        std::cout << fmt::format("level {:2}: {} boxes\n", level, count);
    std::cout << fmt::format(
        "box-counting dimension of {} (chaos game, {} points): {:.4f} (r^2 = {:.5f}, levels "
        "{}..{})\n",
        info.name, co.points, e.dimension, e.r_squared, from, to);
    return 0;
}

} // namespace frac::cli
