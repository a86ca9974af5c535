#include "frontend/loader.hpp"
#include "frontend/fif.hpp"

#include "frontend/resolve.hpp"
#include "frontend/suggest.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <set>
#include <sstream>

namespace frac::front {

bool read_file(const std::string& path, std::size_t max_file_bytes, std::string& text, std::string& why) {
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
    // Read in chunks (room for the whole limit at once would be written, and faulted in, for every
    // file: 16 MB per import). At most one byte over the limit is read, so a device without end
    // (/dev/zero) stops at the limit; a failed read (/proc/self/mem) is an error, not an empty file.
    constexpr std::size_t chunk = std::size_t{64} << 10;
    text.clear();
    while (text.size() <= max_file_bytes) {
        const std::size_t have = text.size();
        text.resize(have + std::min(chunk, max_file_bytes + 1 - have));
        in.read(text.data() + have, static_cast<std::streamsize>(text.size() - have));
        text.resize(have + static_cast<std::size_t>(in.gcount()));
        if (in.bad()) {
            why = "read error";
            return false;
        }
        if (!in) break; // the end of the file
    }
    if (text.size() > max_file_bytes) {
        why = fmt::format("larger than the limit of {} MiB{}", max_file_bytes >> 20,
                          raised_by("FRAC_MAX_FILE_MB"));
        return false;
    }
    return true;
}

namespace {

// Renames the definitions of a module imported `as alias` to alias.name, and the uses of them in the
// module's own bodies (a parameter or a local of the same name is not a use).
class Qualifier {
public:
    Qualifier(const std::string& alias, Program& module) : alias_(alias) {
        for (const Item& it : module.items)
            if (is_definition(it.kind)) globals_.insert(it.name);
    }

    void rename(Item& it) {
        if (globals_.count(it.name) && is_definition(it.kind)) it.name = qualified(it.name);
        locals_.clear();
        std::set<std::string> params;
        for (const Param& p : it.params) params.insert(p.name);
        if (it.kind == ItemKind::shape && !it.has_params) params = {"x", "y", "z"};
        locals_.push_back(params);
        if (it.over) expr(*it.over);
        if (it.body) expr(*it.body);
        for (Expect& e : it.expects) {
            expr(*e.expr);
            if (e.within) expr(*e.within);
        }
        if (it.automaton) {
            // The automaton is shared with the item only: it can be renamed in place.
            for (StateDecl& st : it.automaton->states) {
                if (!it.automaton->graph_directed) st.name = it.name;
                if (st.primitive) expr(*st.primitive);
            }
            for (ArcDecl& arc : it.automaton->arcs) {
                if (!it.automaton->graph_directed) arc.from = arc.to = it.name;
                expr(*arc.op);
                if (arc.probability) expr(*arc.probability);
            }
            if (it.automaton->projection) expr(*it.automaton->projection);
        }
    }

private:
    static bool is_definition(ItemKind k) {
        return k == ItemKind::fn || k == ItemKind::const_ || k == ItemKind::shape || k == ItemKind::automaton;
    }
    std::string qualified(const std::string& name) const { return alias_ + "." + name; }
    bool global(const std::string& name) const {
        for (const auto& scope : locals_)
            if (scope.count(name)) return false;
        return globals_.count(name) > 0;
    }
    void expr(Expr& e) {
        switch (e.kind) {
        case ExprKind::name:
        case ExprKind::call:
            if (global(e.text)) e.text = qualified(e.text);
            for (Arg& a : e.args) expr(*a.value);
            return;
        case ExprKind::let:
            locals_.emplace_back();
            for (Binding& b : e.bindings) {
                expr(*b.value);
                locals_.back().insert(b.name);
            }
            expr(*e.kids[0]);
            locals_.pop_back();
            return;
        case ExprKind::lambda:
            locals_.emplace_back();
            for (const Binding& b : e.bindings) locals_.back().insert(b.name);
            expr(*e.kids[0]);
            locals_.pop_back();
            return;
        case ExprKind::series:
            for (std::size_t k : {0u, 1u, 3u, 4u})
                if (k < e.kids.size() && e.kids[k]) expr(*e.kids[k]);
            if (!e.series->orbit_map.empty() && global(e.series->orbit_map))
                e.series->orbit_map = qualified(e.series->orbit_map);
            locals_.push_back({e.series->var, e.series->orbit_var});
            expr(*e.kids[2]);
            locals_.pop_back();
            return;
        default:
            for (ExprPtr& k : e.kids)
                if (k) expr(*k);
            return;
        }
    }

    std::string alias_;
    std::set<std::string> globals_;
    std::vector<std::set<std::string>> locals_;
};

class Loader {
public:
    Loader(Compilation& c, Program& into, const Limits& limits, LoadTimes* times,
           std::vector<std::string>* loading = nullptr)
        : c_(c), into_(into), limits_(limits), times_(times), loading_(loading ? loading : &own_loading_) {}

    // `key` names the file for cycles (its canonical path; empty for text without a file).
    void load(const std::string& name, const std::string& text, const std::filesystem::path& dir,
              const std::string& key = "") {
        loading_->push_back(key);
        struct Pop {
            std::vector<std::string>* s;
            ~Pop() { s->pop_back(); }
        } pop{loading_};
        if (!key.empty()) seen_.insert(key + " as ");
        const std::uint32_t file = c_.sources.add(name, text);
        using clock = std::chrono::steady_clock;
        const auto t0 = clock::now();
        std::vector<Token> tokens = lex(text, file, c_.diags);
        const auto t1 = clock::now();
        Program p = parse(tokens, c_.diags, limits_);
        if (times_) {
            times_->lex += std::chrono::duration<double>(t1 - t0).count();
            times_->parse += std::chrono::duration<double>(clock::now() - t1).count();
        }
        for (Item& it : p.items) {
            if (it.kind == ItemKind::import) import(it, dir);
            if (it.kind == ItemKind::automaton && it.automaton && it.automaton->fif)
                expand_fif(it, dir, limits_.max_file_bytes, c_.diags);
            into_.items.push_back(std::move(it));
        }
    }

private:
    void import(const Item& it, const std::filesystem::path& dir) {
        const std::string& spec = it.name;
        if (loading_->size() >= static_cast<std::size_t>(limits_.max_import_depth)) {
            // Each nested import holds its file's text and a frame of the loader.
            c_.diags.error(it.loc, fmt::format("imports nested deeper than the limit of {} files{}: import "
                                               "the modules side by side from one file",
                                               limits_.max_import_depth, raised_by("FRAC_MAX_IMPORT_DEPTH")));
            return;
        }
        const bool library = spec.find('/') == std::string::npos && spec.find(".frac") == std::string::npos;
        std::string name, text, key;
        std::filesystem::path module_dir = dir;
        if (library) {
            auto lib = embedded_stdlib().find(spec);
            if (lib == embedded_stdlib().end()) {
                std::vector<std::string> modules;
                for (const auto& [m, t] : embedded_stdlib()) modules.push_back(m);
                const auto near = closest_name(spec, modules);
                c_.diags.error(it.loc, fmt::format("no standard library module '{}'{} (modules: {})", spec,
                                                   near ? fmt::format("; did you mean \"{}\"?", *near) : "",
                                                   list_names(modules)));
                return;
            }
            name = fmt::format("<stdlib>/{}.frac", spec);
            text = lib->second;
            key = "std:" + spec;
        } else {
            const std::filesystem::path path = (dir / spec).lexically_normal();
            std::error_code ec;
            const auto canonical = std::filesystem::weakly_canonical(path, ec);
            key = ec ? path.string() : canonical.string();
            if (const auto at = std::find(loading_->begin(), loading_->end(), key); at != loading_->end()) {
                // A file importing, through others, a file that is still being read.
                std::string chain;
                for (auto k = at; k != loading_->end(); ++k)
                    chain += std::filesystem::path(*k).filename().string() + " imports ";
                c_.diags.error(it.loc, fmt::format("import cycle: {}{}", chain,
                                                   std::filesystem::path(key).filename().string()));
                return;
            }
            if (seen_.count(key + " as " + it.alias)) return; // imported already
            std::string why;
            std::error_code kind;
            if (std::filesystem::exists(path, kind) && !std::filesystem::is_regular_file(path, kind) &&
                !std::filesystem::is_directory(path, kind)) {
                // A device or a pipe may never end or block (/dev/stdin): a module is a file.
                c_.diags.error(it.loc, fmt::format("cannot import '{}': not a regular file", path.string()));
                return;
            }
            if (!read_file(path.string(), limits_.max_file_bytes, text, why)) {
                c_.diags.error(it.loc, fmt::format("cannot read '{}': {}", path.string(), why));
                return;
            }
            name = path.string();
            module_dir = path.parent_path();
        }
        if (!seen_.insert(key + " as " + it.alias).second) return; // imported already
        if (it.alias.empty()) {
            load(name, text, module_dir, key);
            return;
        }
        // A qualified module is loaded on its own (its imports too), then its names get the prefix: it
        // shares nothing with the importing files but what they reach through the prefix.
        Program module;
        Loader(c_, module, limits_, times_, loading_).load(name, text, module_dir, key);
        Qualifier q(it.alias, module);
        for (Item& m : module.items) {
            q.rename(m);
            into_.items.push_back(std::move(m));
        }
    }

    Compilation& c_;
    Program& into_;
    const Limits& limits_;
    LoadTimes* times_;
    std::vector<std::string> own_loading_; // the files being read, outermost first
    std::vector<std::string>* loading_;
    std::set<std::string> seen_;
};

} // namespace

// Each override's expression is parsed as a file of its own, so that its diagnostics point into the
// command line's text.
void apply_overrides(Compilation& c, const ConstOverrides& overrides) {
    for (const auto& [name, value] : overrides) {
        bool found = false;
        for (Item& it : c.program.items) {
            if (it.kind != ItemKind::const_ || it.name != name) continue;
            const std::string text = fmt::format("const {} = {};", name, value);
            const std::uint32_t file = c.sources.add(fmt::format("<--set {}>", name), text);
            Program p = parse(lex(text, file, c.diags), c.diags);
            if (p.items.size() == 1 && p.items[0].kind == ItemKind::const_)
                it.body = std::move(p.items[0].body);
            found = true;
        }
        if (!found) c.unknown_overrides.push_back(name);
    }
}

void load_source(Compilation& c, const std::string& name, const std::string& text, const Limits& limits,
                 LoadTimes* times) {
    Loader(c, c.program, limits, times).load(name, text, std::filesystem::current_path());
}

bool is_identifier(const std::string& text) {
    if (text.empty() || !(std::isalpha(static_cast<unsigned char>(text[0])) || text[0] == '_')) return false;
    for (char ch : text)
        if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_')) return false;
    return true;
}

bool load_file(Compilation& c, const std::string& path, const Limits& limits, LoadTimes* times) {
    std::string text, why;
    if (!read_file(path, limits.max_file_bytes, text, why)) {
        c.diags.error({}, fmt::format("cannot read '{}': {}", path, why));
        return false;
    }
    std::error_code ec;
    const auto canonical = std::filesystem::weakly_canonical(path, ec);
    Loader(c, c.program, limits, times)
        .load(path, text, std::filesystem::path(path).parent_path(), ec ? path : canonical.string());
    return true;
}

} // namespace frac::front
