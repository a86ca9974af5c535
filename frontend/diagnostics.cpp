#include "frontend/diagnostics.hpp"

#include <algorithm>
#include <fmt/format.h>

namespace frac::front {

SourceManager::SourceManager() {
    files_.push_back({"<unknown>", ""});
}

std::uint32_t SourceManager::add(std::string name, std::string text) {
    files_.push_back({std::move(name), std::move(text)});
    return static_cast<std::uint32_t>(files_.size() - 1);
}

std::string SourceManager::line_text(Location loc) const {
    if (loc.file == 0 || loc.file >= files_.size() || loc.line == 0) return {};
    const std::string& t = files_[loc.file].text;
    std::size_t pos = 0;
    for (std::uint32_t l = 1; l < loc.line && pos != std::string::npos; ++l) {
        pos = t.find('\n', pos);
        if (pos != std::string::npos) ++pos;
    }
    if (pos == std::string::npos || pos > t.size()) return {};
    const std::size_t end = t.find('\n', pos);
    return t.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
}

namespace {

// A message quotes names and numbers of the model between single quotes; a quote of a 10^6-character
// token is cut to its beginning and its length, so that one error prints a bounded text.
std::string bounded(std::string message) {
    constexpr std::size_t max_quote = 80, kept = 60;
    if (message.size() <= max_quote) return message;
    std::string out;
    std::size_t pos = 0;
    while (pos < message.size()) {
        const std::size_t open = message.find('\'', pos);
        const std::size_t close = open == std::string::npos ? open : message.find('\'', open + 1);
        if (close == std::string::npos) break;
        out.append(message, pos, open + 1 - pos);
        const std::size_t length = close - open - 1;
        if (length > max_quote) {
            out.append(message, open + 1, kept);
            out += fmt::format("... ({} characters)", length);
        } else {
            out.append(message, open + 1, length);
        }
        out += '\'';
        pos = close + 1;
    }
    out.append(message, pos, std::string::npos);
    return out;
}

} // namespace

void Diagnostics::error(Location loc, std::string message) {
    message = bounded(std::move(message));
    skipping_notes_ = !said_.insert({loc.file, loc.line, loc.column, message}).second;
    if (skipping_notes_) return;
    ++errors_;
    if (errors_ <= max_errors) list_.push_back({Severity::error, loc, std::move(message)});
}

void Diagnostics::warning(Location loc, std::string message) {
    skipping_notes_ = false;
    list_.push_back({Severity::warning, loc, bounded(std::move(message))});
}

void Diagnostics::note(Location loc, std::string message) {
    if (skipping_notes_) return;
    list_.push_back({Severity::note, loc, bounded(std::move(message))});
}

std::string Diagnostics::render(const SourceManager& sm) const {
    // Sorted by location, each note kept after the diagnostic it explains (it may point elsewhere).
    std::vector<std::vector<Diagnostic>> groups;
    for (const Diagnostic& d : list_) {
        if (d.severity != Severity::note || groups.empty()) groups.emplace_back();
        groups.back().push_back(d);
    }
    std::stable_sort(groups.begin(), groups.end(), [](const auto& a, const auto& b) {
        return std::tie(a[0].loc.file, a[0].loc.line, a[0].loc.column) <
               std::tie(b[0].loc.file, b[0].loc.line, b[0].loc.column);
    });
    std::vector<Diagnostic> sorted;
    for (const auto& g : groups) sorted.insert(sorted.end(), g.begin(), g.end());
    std::string out;
    for (const Diagnostic& d : sorted) {
        const char* kind = d.severity == Severity::error     ? "error"
                           : d.severity == Severity::warning ? "warning"
                                                             : "note";
        if (d.loc.file != 0)
            out += fmt::format("{}:{}:{}: {}: {}\n", sm.name(d.loc.file), d.loc.line, d.loc.column, kind,
                               d.message);
        else
            out += fmt::format("{}: {}\n", kind, d.message);
        std::string line = sm.line_text(d.loc);
        if (!line.empty()) {
            // A long line is quoted by an excerpt around the column, so one error prints a bounded text.
            constexpr std::size_t max_quote = 160, before = 60;
            std::size_t column = d.loc.column > 0 ? d.loc.column - 1 : 0;
            std::string prefix;
            if (line.size() > max_quote) {
                const std::size_t start = column > before ? column - before : 0;
                line = line.substr(start, max_quote) + (start + max_quote < line.size() ? " ..." : "");
                if (start > 0) {
                    prefix = "... ";
                    column = column - start;
                }
            }
            out += "  " + prefix + line + "\n";
            std::string caret = "  " + std::string(prefix.size(), ' ');
            for (std::size_t c = 0; c < column && c < line.size(); ++c) caret += line[c] == '\t' ? '\t' : ' ';
            out += caret + "^\n";
        }
    }
    if (errors_ > max_errors) out += fmt::format("{} more errors not shown\n", errors_ - max_errors);
    return out;
}

} // namespace frac::front
