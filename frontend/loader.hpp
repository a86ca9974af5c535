// The first stage of the pipeline (driver/pipeline.cpp): reading a model file and the files it imports,
// each lexed and parsed, into one program (imported files first), and the --set overrides of its
// constants. The later stages run over the Compilation this fills.
#pragma once

#include "frontend/ast.hpp"
#include "frontend/consteval.hpp"
#include "frontend/lower.hpp"
#include "frontend/module.hpp"
#include "frontend/typecheck.hpp"

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace frac::front {

struct Compilation {
    SourceManager sources;
    Diagnostics diags;
    std::vector<std::string> unknown_overrides; // overridden constants the model does not define
    Program program;                            // the items of every file, imported files first
    TypedProgram typed;                         // the types of the program (typecheck)
    ConstantValues constants;                   // the values of its constants (consteval)
    Module module;
    bool ok() const { return !diags.has_errors(); }
};

// Seconds spent lexing and parsing, over all files read (for --time-passes).
struct LoadTimes {
    double lex = 0, parse = 0;
};

// Reads a file of at most max_file_bytes (a directory, a read error or a larger file: false, with why).
bool read_file(const std::string& path, std::size_t max_file_bytes, std::string& text, std::string& why);

// Reads, lexes and parses `path` and its imports into c.program. A file that cannot be read is an
// error in c.diags; returns whether the main file was read.
// Of `limits`, the size of files, the depth of imports and what the parser limits.
bool load_file(Compilation& c, const std::string& path, const Limits& limits, LoadTimes* times = nullptr);
// Same, from text (name is used in diagnostics; imports resolve relative to the working directory).
void load_source(Compilation& c, const std::string& name, const std::string& text, const Limits& limits,
                 LoadTimes* times = nullptr);

// Constants replaced before names are resolved (frac --set NAME=VALUE): name, expression text.
using ConstOverrides = std::vector<std::pair<std::string, std::string>>;
// Replaces the body of every constant named by an override; names the model lacks go to
// c.unknown_overrides.
void apply_overrides(Compilation& c, const ConstOverrides& overrides);

// Whether `text` is a name of the language (a letter or '_', then letters, digits, '_').
bool is_identifier(const std::string& text);

// The standard library files embedded in the binary, by name ("fractals").
const std::map<std::string, std::string>& embedded_stdlib();

} // namespace frac::front
