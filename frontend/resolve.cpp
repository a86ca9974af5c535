#include "frontend/resolve.hpp"

#include "frontend/builtins.hpp"

#include <fmt/format.h>
#include <unordered_map>

namespace frac::front {

namespace {

class Resolver {
public:
    Resolver(const Program& p, Diagnostics& d) : p_(p), d_(d) {}

    void run() {
        for (const Item& it : p_.items) declare(it);
        for (const Item& it : p_.items) check(it);
    }

private:
    void declare(const Item& it) {
        if (it.kind == ItemKind::import || it.kind == ItemKind::test || it.kind == ItemKind::print) return;
        if (find_builtin(it.name) || is_builtin_constant(it.name)) {
            d_.error(it.loc, fmt::format("'{}' is a builtin and cannot be redefined", it.name));
            return;
        }
        auto [pos, added] = globals_.emplace(it.name, &it);
        if (!added) {
            d_.error(it.loc, fmt::format("'{}' is already defined", it.name));
            d_.note(pos->second->loc, fmt::format("'{}' was first defined here", it.name));
        }
    }

    void check(const Item& it) {
        scopes_.clear();
        scopes_.emplace_back();
        for (const Param& p : it.params) {
            if (!scopes_.back().emplace(p.name, 0).second)
                d_.error(p.loc, fmt::format("parameter '{}' appears twice", p.name));
        }
        if (it.kind == ItemKind::shape && !it.has_params)
            for (const char* c : {"x", "y", "z"}) scopes_.back().emplace(c, 0);
        if (it.over) expr(*it.over);
        if (it.body) expr(*it.body);
        for (const Expect& e : it.expects) {
            expr(*e.expr);
            if (e.within) expr(*e.within);
        }
    }

    bool is_local(const std::string& name) const {
        for (auto it = scopes_.rbegin(); it != scopes_.rend(); ++it)
            if (it->count(name)) return true;
        return false;
    }

    void expr(const Expr& e) {
        switch (e.kind) {
        case ExprKind::number: return;
        case ExprKind::name:
            if (!is_local(e.text) && !globals_.count(e.text) && !is_builtin_constant(e.text)) {
                if (globals_.count(e.text) == 0 && find_builtin(e.text))
                    d_.error(e.loc, fmt::format("'{}' is a function; call it with arguments", e.text));
                else
                    d_.error(e.loc, fmt::format("unknown name '{}'", e.text));
            }
            return;
        case ExprKind::call: {
            call(e);
            for (const Arg& a : e.args) expr(*a.value);
            return;
        }
        case ExprKind::let: {
            scopes_.emplace_back();
            for (const Binding& b : e.bindings) {
                expr(*b.value);
                scopes_.back()[b.name] = 0;
            }
            expr(*e.kids[0]);
            scopes_.pop_back();
            return;
        }
        case ExprKind::series: {
            expr(*e.kids[0]);
            if (e.kids[1]) expr(*e.kids[1]);
            if (!e.orbit_var.empty()) {
                expr(*e.kids[3]);
                if (e.kids.size() > 4) expr(*e.kids[4]);
                auto m = globals_.find(e.orbit_map);
                if (m == globals_.end() || m->second->kind != ItemKind::fn)
                    d_.error(e.orbit_loc,
                             fmt::format("the map of an orbit must be a function of a point, '{}' is not one",
                                         e.orbit_map));
                else if (m->second->params.size() != 1)
                    d_.error(e.orbit_loc,
                             fmt::format("the map of an orbit takes one point; '{}' takes {} arguments",
                                         e.orbit_map, m->second->params.size()));
            }
            scopes_.emplace_back();
            scopes_.back()[e.var] = 0;
            if (!e.orbit_var.empty()) scopes_.back()[e.orbit_var] = 0;
            expr(*e.kids[2]);
            scopes_.pop_back();
            return;
        }
        case ExprKind::unary:
        case ExprKind::binary:
        case ExprKind::if_:
        case ExprKind::tuple:
        case ExprKind::field:
        case ExprKind::interval:
            for (const ExprPtr& k : e.kids) expr(*k);
            return;
        }
    }

    void call(const Expr& e) {
        const int n = static_cast<int>(e.args.size());
        if (is_local(e.text)) {
            d_.error(e.loc, fmt::format("'{}' is a value, not a function", e.text));
            return;
        }
        if (auto g = globals_.find(e.text); g != globals_.end()) {
            const Item& target = *g->second;
            for (const Arg& a : e.args)
                if (!a.name.empty()) d_.error(a.loc, fmt::format("'{}' takes no named arguments", e.text));
            if (target.kind == ItemKind::const_) {
                d_.error(e.loc, fmt::format("'{}' is a constant, not a function", e.text));
            } else if (target.kind == ItemKind::fn && n != static_cast<int>(target.params.size())) {
                d_.error(e.loc, fmt::format("'{}' takes {} argument{}, {} given", e.text,
                                            target.params.size(), target.params.size() == 1 ? "" : "s", n));
            } else if (target.kind == ItemKind::shape && target.has_params && n != 1 &&
                       n != static_cast<int>(target.params.size())) {
                d_.error(e.loc, fmt::format("shape '{}' takes {} coordinates (or one point), {} given",
                                            e.text, target.params.size(), n));
            }
            return;
        }
        const Builtin* b = find_builtin(e.text);
        if (!b) {
            d_.error(e.loc, fmt::format("unknown function '{}'", e.text));
            return;
        }
        if (n < b->min_args || n > b->max_args) {
            const std::string want = b->min_args == b->max_args ? fmt::format("{}", b->min_args)
                                     : b->max_args >= 64        ? fmt::format("at least {}", b->min_args)
                                                         : fmt::format("{} to {}", b->min_args, b->max_args);
            d_.error(e.loc, fmt::format("'{}' takes {} argument{}, {} given", e.text, want,
                                        b->max_args == 1 ? "" : "s", n));
        }
        if (b->kind != BuiltinKind::dimension)
            for (const Arg& a : e.args)
                if (!a.name.empty()) d_.error(a.loc, fmt::format("'{}' takes no named arguments", e.text));
    }

    const Program& p_;
    Diagnostics& d_;
    std::unordered_map<std::string, const Item*> globals_;
    std::vector<std::unordered_map<std::string, int>> scopes_;
};

} // namespace

void resolve_names(const Program& program, Diagnostics& diags) {
    Resolver(program, diags).run();
}

} // namespace frac::front
