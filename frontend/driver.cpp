#include "frontend/driver.hpp"

#include "frontend/resolve.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <set>
#include <sstream>

namespace frac::front {

namespace {

constexpr std::size_t max_file_bytes = 16u << 20;

bool read_file(const std::string& path, std::string& text, std::string& why) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) {
        why = "is a directory";
        return false;
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        why = std::strerror(errno);
        return false;
    }
    std::ostringstream ss;
    ss << in.rdbuf();
    text = ss.str();
    if (text.size() > max_file_bytes) {
        why = fmt::format("larger than the limit of {} MiB", max_file_bytes >> 20);
        return false;
    }
    return true;
}

class Loader {
public:
    Loader(Compilation& c) : c_(c) {}

    void load(const std::string& name, const std::string& text, const std::filesystem::path& dir) {
        const std::uint32_t file = c_.sources.add(name, text);
        Program p = parse(lex(text, file, c_.diags), c_.diags);
        for (Item& it : p.items) {
            if (it.kind == ItemKind::import) import(it, dir);
            c_.program.items.push_back(std::move(it));
        }
    }

private:
    void import(const Item& it, const std::filesystem::path& dir) {
        const std::string& spec = it.name;
        const bool library = spec.find('/') == std::string::npos && spec.find(".frac") == std::string::npos;
        if (library) {
            auto lib = embedded_stdlib().find(spec);
            if (lib == embedded_stdlib().end()) {
                c_.diags.error(it.loc, fmt::format("no standard library module '{}'", spec));
                return;
            }
            if (seen_.insert("std:" + spec).second)
                load(fmt::format("<stdlib>/{}.frac", spec), lib->second, dir);
            return;
        }
        const std::filesystem::path path = (dir / spec).lexically_normal();
        std::error_code ec;
        const auto canonical = std::filesystem::weakly_canonical(path, ec);
        if (!seen_.insert(ec ? path.string() : canonical.string()).second)
            return; // imported already (or a cycle)
        std::string text, why;
        if (!read_file(path.string(), text, why)) {
            c_.diags.error(it.loc, fmt::format("cannot read '{}': {}", path.string(), why));
            return;
        }
        load(path.string(), text, path.parent_path());
    }

    Compilation& c_;
    std::set<std::string> seen_;
};

void finish(Compilation& c, const Limits& limits, StopAfter stop) {
    if (stop == StopAfter::parse || c.diags.has_errors()) return;
    resolve_names(c.program, c.diags);
    if (stop == StopAfter::resolve || c.diags.has_errors()) return;
    elaborate(c.program, c.sources, limits, c.module, c.diags);
    if (std::string defect = ir::verify_graph(c.module.graph); !defect.empty())
        throw InternalError("malformed expression graph: " + defect);
}

} // namespace

std::unique_ptr<Compilation> compile_source(const std::string& name, const std::string& text,
                                            const Limits& limits, StopAfter stop) {
    auto c = std::make_unique<Compilation>();
    Loader(*c).load(name, text, std::filesystem::current_path());
    finish(*c, limits, stop);
    return c;
}

std::unique_ptr<Compilation> compile_file(const std::string& path, const Limits& limits, StopAfter stop) {
    auto c = std::make_unique<Compilation>();
    std::string text, why;
    if (!read_file(path, text, why)) {
        c->diags.error({}, fmt::format("cannot read '{}': {}", path, why));
        return c;
    }
    Loader(*c).load(path, text, std::filesystem::path(path).parent_path());
    finish(*c, limits, stop);
    return c;
}

} // namespace frac::front
