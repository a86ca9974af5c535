// Source files and user-facing diagnostics: "file:line:col: error: message", the source line and a
// caret, sorted by location. Internal errors (bugs) are a different thing: `InternalError`.
#pragma once

#include <cstdint>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace frac::front {

struct Location {
    std::uint32_t file = 0; // index into SourceManager; 0 is "no file"
    std::uint32_t line = 0; // 1-based; 0 = unknown
    std::uint32_t column = 0;
};

class SourceManager {
public:
    SourceManager();
    // Registers a file's text; returns its id.
    std::uint32_t add(std::string name, std::string text);
    const std::string& name(std::uint32_t file) const { return files_[file].name; }
    const std::string& text(std::uint32_t file) const { return files_[file].text; }
    std::string line_text(Location loc) const;
    std::size_t count() const { return files_.size(); }

private:
    struct File {
        std::string name, text;
    };
    std::vector<File> files_;
};

enum class Severity { error, warning, note };

struct Diagnostic {
    Severity severity;
    Location loc;
    std::string message;
};

class Diagnostics {
public:
    // Stops collecting after this many errors (each file is still parsed to the end).
    static constexpr std::size_t max_errors = 50;

    void error(Location loc, std::string message);
    void note(Location loc, std::string message);
    void warning(Location loc, std::string message);
    bool has_errors() const { return errors_ > 0; }
    std::size_t error_count() const { return errors_; }
    const std::vector<Diagnostic>& all() const { return list_; }
    // Sorted by file and position, each with its source line and a caret.
    std::string render(const SourceManager& sm) const;

private:
    std::vector<Diagnostic> list_;
    std::size_t errors_ = 0;
    // An error said twice at one place (an expression a declaration copies into several places, as
    // a fif's points into its shears) is reported once, without its notes.
    std::set<std::tuple<std::uint32_t, std::uint32_t, std::uint32_t, std::string>> said_;
    bool skipping_notes_ = false;
};

// A located user error that aborts the current item (collected into Diagnostics by the caller).
struct CompileError : std::runtime_error {
    Location loc;
    std::vector<std::pair<Location, std::string>> notes; // e.g. the calls that inlined the failing body
    CompileError(Location l, const std::string& message) : std::runtime_error(message), loc(l) {}
};

// A defect in Frac itself: reported as an internal error with exit code 70, never as a user error.
struct InternalError : std::logic_error {
    using std::logic_error::logic_error;
};

// Exit codes (BSD sysexits): a bad command line, a model that does not compile, a run-time failure, a bug.
inline constexpr int exit_usage_error = 64;
inline constexpr int exit_compile_error = 65;
inline constexpr int exit_runtime_error = 1;
inline constexpr int exit_internal_error = 70;

} // namespace frac::front
