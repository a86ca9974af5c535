// The frontend pipeline, in order: read (with imports) -> lex -> parse -> resolve names -> elaborate
// (types, lowering, series bounds) -> verify the graph.
#pragma once

#include "frontend/ast.hpp"
#include "frontend/elaborate.hpp"
#include "frontend/module.hpp"

#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace frac::front {

struct Compilation {
    SourceManager sources;
    Diagnostics diags;
    std::vector<std::string> unknown_overrides; // overridden constants the model does not define
    Program program;                            // the items of every file, imported files first
    Module module;
    bool ok() const { return !diags.has_errors(); }
};

enum class StopAfter { parse, resolve, elaborate };

// Constants replaced before names are resolved (frac --set NAME=VALUE): name, expression text.
using ConstOverrides = std::vector<std::pair<std::string, std::string>>;

// Compiles a model file. Never throws for a bad model: problems are in `diags`.
std::unique_ptr<Compilation> compile_file(const std::string& path, const Limits& limits = {},
                                          StopAfter stop = StopAfter::elaborate,
                                          const ConstOverrides& overrides = {});

// Whether `text` is a name of the language (a letter or '_', then letters, digits, '_').
bool is_identifier(const std::string& text);
// Same, from text (name is used in diagnostics; imports resolve relative to the working directory).
std::unique_ptr<Compilation> compile_source(const std::string& name, const std::string& text,
                                            const Limits& limits = {}, StopAfter stop = StopAfter::elaborate);

// The standard library files embedded in the binary, by name ("fractals").
const std::map<std::string, std::string>& embedded_stdlib();

} // namespace frac::front
