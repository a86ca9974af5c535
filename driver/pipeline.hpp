// The pipeline from source to evaluator, every stage in order (pipeline.cpp holds the list):
//
//   lex -> parse -> resolve -> typecheck -> consteval -> lower (and verify)   (frontend, once per model)
//   -> automaton                                                   (the automaton IR of each ifs, cifs)
//   -> tape -> specialize -> codegen                               (backend, per shape)
//
// Each stage can print what it produced (frac check --emit=<stage>) and is timed
// (frac check --time-passes).
#pragma once

#include "frontend/loader.hpp"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace frac::driver {

enum class Stage {
    lex,
    parse,
    constraints,
    resolve,
    typecheck,
    const_eval,
    lower,
    automaton,
    tape,
    specialize,
    codegen
};

struct StageInfo {
    Stage stage;
    const char* name;  // as written after --emit=
    const char* shows; // what --emit prints
};

// Every stage, in the order they run.
const std::vector<StageInfo>& stages();
std::optional<Stage> find_stage(const std::string& name);
// "lex, parse, ..." for messages.
std::string stage_names();

// Seconds per stage, in the order they ran.
struct PassTimes {
    std::vector<std::pair<std::string, double>> passes;
    void add(const std::string& name, double seconds);
    // A table: stage, milliseconds, share of the total.
    std::string report() const;
};

struct CompileOptions {
    front::Limits limits;
    Stage stop = Stage::lower; // the last frontend stage to run (lex and parse run together)
    front::ConstOverrides overrides;
    std::optional<std::uint64_t> free_entry_seed; // --seed: drawn values for free bcifs entries
    PassTimes* times = nullptr;                   // filled when not null
};

// Runs the frontend stages up to options.stop. Never throws for a bad model: problems are in `diags`.
std::unique_ptr<front::Compilation> compile_file(const std::string& path, const CompileOptions& options = {});
// Same, from text (name is used in diagnostics; imports resolve relative to the working directory).
std::unique_ptr<front::Compilation> compile_source(const std::string& name, const std::string& text,
                                                   const CompileOptions& options = {});

// What `stage` produced, as text, for the shapes named (all of the model's when empty). The frontend
// stages print the model; the backend stages run for each shape (tape, specialize: over the shape's
// default box; codegen: the JIT's optimised LLVM module). Throws std::runtime_error when codegen
// cannot run (no LLVM backend here).
std::string emit(const front::Compilation& c, Stage stage, const std::vector<std::string>& shapes,
                 PassTimes* times = nullptr);

} // namespace frac::driver
