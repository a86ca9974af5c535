#include "frontend/resolve.hpp"

#include "frontend/builtins.hpp"
#include "frontend/loader.hpp"
#include "frontend/suggest.hpp"

#include <algorithm>
#include <fmt/format.h>
#include <map>
#include <optional>
#include <set>
#include <unordered_map>
#include <unordered_set>

namespace frac::front {

namespace {

class Resolver {
public:
    Resolver(const Program& p, Diagnostics& d) : p_(p), d_(d) {}

    void run() {
        for (const Item& it : p_.items) declare(it);
        infer_signatures();
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

    // ---- function parameters ----
    // A parameter of a function is itself a function, of a fixed number of arguments, when the body
    // calls it, uses it as an orbit's map, or passes it on where a function is expected. Repeated until
    // nothing changes, as a function may pass a parameter on to one defined after it.
    static constexpr int value = -1;
    struct ParamType {
        int arity = value; // value, or the number of arguments of a function parameter
        Location first_use;
    };

    void infer_signatures() {
        for (const Item& it : p_.items)
            if (it.kind == ItemKind::fn) signatures_[&it].assign(it.params.size(), ParamType{});
        for (bool changed = true; changed;) {
            changed = false;
            for (const Item& it : p_.items) {
                if (it.kind != ItemKind::fn) continue;
                infer_fn_ = &it;
                shadows_.clear();
                changed |= infer(*it.body);
            }
        }
        infer_fn_ = nullptr;
    }

    // Index of an unshadowed parameter of the function being inferred, or -1.
    int param_index(const std::string& name) const {
        for (const auto& s : shadows_)
            if (s.count(name)) return -1;
        for (std::size_t k = 0; k < infer_fn_->params.size(); ++k)
            if (infer_fn_->params[k].name == name) return static_cast<int>(k);
        return -1;
    }

    bool mark_function(const std::string& name, int arity, Location loc) {
        const int k = param_index(name);
        if (k < 0) return false;
        ParamType& t = signatures_[infer_fn_][static_cast<std::size_t>(k)];
        if (t.arity != value) return false; // a different arity is reported at the call
        t.arity = arity;
        t.first_use = loc;
        return true;
    }

    const std::vector<ParamType>* signature(const std::string& callee) const {
        auto g = globals_.find(callee);
        if (g == globals_.end() || g->second->kind != ItemKind::fn) return nullptr;
        return &signatures_.at(g->second);
    }

    bool infer(const Expr& e) {
        bool changed = false;
        switch (e.kind) {
        case ExprKind::call: {
            changed |= mark_function(e.text, static_cast<int>(e.args.size()), e.loc);
            const std::vector<ParamType>* sig = param_index(e.text) < 0 ? signature(e.text) : nullptr;
            for (std::size_t i = 0; i < e.args.size(); ++i) {
                const Expr& a = *e.args[i].value;
                if (sig && i < sig->size() && (*sig)[i].arity != value && a.kind == ExprKind::name)
                    changed |= mark_function(a.text, (*sig)[i].arity, a.loc);
                changed |= infer(a);
            }
            return changed;
        }
        case ExprKind::let:
            shadows_.emplace_back();
            for (const Binding& b : e.bindings) {
                changed |= infer(*b.value);
                shadows_.back().insert(b.name);
            }
            changed |= infer(*e.kids[0]);
            shadows_.pop_back();
            return changed;
        case ExprKind::lambda:
            shadows_.emplace_back();
            for (const Binding& b : e.bindings) shadows_.back().insert(b.name);
            changed |= infer(*e.kids[0]);
            shadows_.pop_back();
            return changed;
        case ExprKind::series:
            changed |= infer(*e.kids[0]);
            if (e.kids[1]) changed |= infer(*e.kids[1]);
            if (!e.series->orbit_var.empty()) {
                changed |= infer(*e.kids[3]);
                changed |= mark_function(e.series->orbit_map, 1, e.series->orbit_loc);
            }
            shadows_.push_back({e.series->var, e.series->orbit_var});
            changed |= infer(*e.kids[2]);
            shadows_.pop_back();
            return changed;
        default:
            for (const ExprPtr& k : e.kids)
                if (k) changed |= infer(*k);
            return changed;
        }
    }

    // ---- checks ----
    void check(const Item& it) {
        checked_ = &it;
        scopes_.clear();
        scopes_.emplace_back();
        // The box after `over` is a constant: the shape's coordinates are not in its scope.
        if (it.over) {
            over_of_ = &it;
            expr(*it.over);
            over_of_ = nullptr;
        }
        for (std::size_t k = 0; k < it.params.size(); ++k) {
            const Param& p = it.params[k];
            const int arity = it.kind == ItemKind::fn ? signatures_.at(&it)[k].arity : value;
            if (!scopes_.back().emplace(p.name, arity).second)
                d_.error(p.loc, fmt::format("parameter '{}' appears twice", p.name));
        }
        if (it.kind == ItemKind::shape && !it.has_params)
            for (const char* c : {"x", "y", "z"}) scopes_.back().emplace(c, value);
        if (it.body) expr(*it.body);
        for (const Expect& e : it.expects) {
            expr(*e.expr);
            if (e.within) expr(*e.within);
        }
        if (it.automaton) automaton(*it.automaton);
    }

    // States are names of their automaton only: each defined once, every arc and the initial state
    // naming one of them.
    void automaton(const AutomatonDecl& a) {
        std::map<std::string, Location> states;
        for (const StateDecl& s : a.states) {
            if (auto [pos, added] = states.emplace(s.name, s.loc); !added) {
                d_.error(s.loc, fmt::format("state '{}' is already defined", s.name));
                d_.note(pos->second, fmt::format("'{}' was first defined here", s.name));
            }
            if (s.primitive) expr(*s.primitive);
        }
        std::vector<std::string> names;
        for (const auto& [n, loc] : states) names.push_back(n);
        const auto known = [&](const std::string& name, Location loc, const char* what) {
            if (states.count(name)) return;
            const auto near = closest_name(name, names);
            d_.error(loc, fmt::format("{} '{}' is no {} of this {}{} ({}: {})", what, name,
                                      a.bcifs ? "cell" : "state", a.bcifs ? "bcifs" : "automaton",
                                      near ? fmt::format("; did you mean '{}'?", *near) : "",
                                      a.bcifs ? "cells" : "states", list_names(names)));
        };
        for (const ArcDecl& arc : a.arcs) {
            known(arc.from, arc.from_loc, "the arc's source");
            known(arc.to, arc.to_loc, "the arc's target");
            expr(*arc.op);
            if (arc.probability) expr(*arc.probability);
        }
        if (!a.initial.empty()) known(a.initial, a.initial_loc, "the initial state");
        if (a.projection) expr(*a.projection);
        if (a.states.empty())
            d_.error(checked_->loc, fmt::format("automaton '{}' has no state", checked_->name));
        if (a.bcifs) {
            bcifs(*a.bcifs, known);
        } else if (a.arcs.empty()) {
            d_.error(checked_->loc, fmt::format("automaton '{}' has no map", checked_->name));
        }
    }

    // Operators are named cell.name, each defined once; the parameters are names of the entries only.
    template <class Known>
    void bcifs(const BcifsDecl& b, const Known& known_cell) {
        std::map<std::pair<std::string, std::string>, Location> operators;
        for (const OperatorDecl& op : b.operators) {
            known_cell(op.cell, op.loc, "the operator's cell");
            known_cell(op.target, op.target_loc, op.boundary ? "the embedded cell" : "the target cell");
            if (auto [pos, added] = operators.emplace(std::pair{op.cell, op.name}, op.loc); !added) {
                d_.error(op.loc, fmt::format("operator '{}.{}' is already defined", op.cell, op.name));
                d_.note(pos->second, fmt::format("'{}.{}' was first defined here", op.cell, op.name));
            }
        }
        if (operators.empty())
            d_.error(checked_->loc, fmt::format("bcifs '{}' has no operator", checked_->name));
        const auto known_operator = [&](const std::string& cell, const std::string& name, Location loc) {
            if (operators.count({cell, name})) return;
            std::vector<std::string> names;
            for (const auto& [key, where] : operators)
                if (key.first == cell) names.push_back(key.first + "." + key.second);
            d_.error(loc, fmt::format("'{}.{}' is no operator of this bcifs{}", cell, name,
                                      names.empty() ? fmt::format(" ('{}' has none)", cell)
                                                    : fmt::format(" (operators of '{}': {})", cell,
                                                                  list_names(names))));
        };
        std::map<std::string, Location> params;
        for (const ParamDecl& p : b.params) {
            if (auto [pos, added] = params.emplace(p.name, p.loc); !added) {
                d_.error(p.loc, fmt::format("parameter '{}' is already defined", p.name));
                d_.note(pos->second, fmt::format("'{}' was first defined here", p.name));
            }
            for (const Expr* e : {p.lo.get(), p.hi.get(), p.value.get()})
                if (e) expr(*e);
        }
        scopes_.emplace_back();
        for (const auto& [name, loc] : params) scopes_.back().emplace(name, value);
        for (const OperatorDecl& op : b.operators) {
            if (!op.value) continue;
            if (op.value->kind != ExprKind::matrix) {
                expr(*op.value);
                continue;
            }
            for (const ExprPtr& row : op.value->kids)
                for (const ExprPtr& entry : row->kids)
                    if (!is_unknown(*entry)) expr(*entry);
        }
        for (const FixDecl& f : b.fixes) {
            known_operator(f.cell, f.name, f.loc);
            expr(*f.value);
        }
        scopes_.pop_back();
        for (const ConstraintDecl& c : b.constraints)
            for (const auto* side : {&c.left, &c.right})
                for (const FactorDecl& f : *side) {
                    if (f.constant)
                        expr(*f.constant);
                    else
                        known_operator(f.cell, f.name, f.loc);
                }
    }

    // The kind of a local name: `value`, a function parameter's arity, or nullopt when not local.
    std::optional<int> local(const std::string& name) const {
        for (auto it = scopes_.rbegin(); it != scopes_.rend(); ++it)
            if (auto found = it->find(name); found != it->end()) return found->second;
        return std::nullopt;
    }
    bool is_local(const std::string& name) const { return local(name).has_value(); }

    // Whether a bare name denotes a function (of the program, a builtin, or a function parameter).
    bool names_function(const std::string& name) const {
        if (auto l = local(name)) return *l != value;
        if (auto g = globals_.find(name); g != globals_.end()) return g->second->kind == ItemKind::fn;
        return find_builtin(name) != nullptr;
    }

    // A name used as a value: each scope and the globals are looked up once.
    void name(const Expr& e) {
        if (is_unknown(e)) {
            d_.error(e.loc,
                     "'?' (an unknown) is a whole entry of an operator's matrix, or the whole operator");
            return;
        }
        const std::optional<int> l = local(e.text);
        const auto g = l ? globals_.end() : globals_.find(e.text);
        const bool global = g != globals_.end();
        if (!l && !global) {
            if (is_builtin_constant(e.text)) return;
            if (find_builtin(e.text))
                d_.error(e.loc, fmt::format("'{}' is a function; call it with arguments", e.text));
            else
                unknown(e.loc, "name", e.text);
            return;
        }
        const bool function = l ? *l != value : g->second->kind == ItemKind::fn;
        if (function && !is_builtin_constant(e.text))
            d_.error(e.loc, fmt::format("'{}' is a function; call it with arguments, or pass it where a "
                                        "function is expected",
                                        e.text));
    }

    void expr(const Expr& e) {
        switch (e.kind) {
        case ExprKind::number: return;
        case ExprKind::name: name(e); return;
        case ExprKind::call: call(e); return;
        case ExprKind::let: {
            scopes_.emplace_back();
            for (const Binding& b : e.bindings) {
                expr(*b.value);
                scopes_.back()[b.name] = value;
            }
            expr(*e.kids[0]);
            scopes_.pop_back();
            return;
        }
        case ExprKind::series: {
            expr(*e.kids[0]);
            if (e.kids[1]) expr(*e.kids[1]);
            if (!e.series->orbit_var.empty()) {
                expr(*e.kids[3]);
                if (e.kids.size() > 4) expr(*e.kids[4]);
                auto m = globals_.find(e.series->orbit_map);
                if (const std::optional<int> l = local(e.series->orbit_map)) {
                    if (*l == value)
                        d_.error(
                            e.series->orbit_loc,
                            fmt::format("the map of an orbit must be a function of a point, '{}' is a value",
                                        e.series->orbit_map));
                } else if (m == globals_.end() || m->second->kind != ItemKind::fn)
                    d_.error(e.series->orbit_loc,
                             fmt::format("the map of an orbit must be a function of a point, '{}' is not one",
                                         e.series->orbit_map));
                else if (m->second->params.size() != 1)
                    d_.error(e.series->orbit_loc,
                             fmt::format("the map of an orbit takes one point; '{}' takes {} arguments",
                                         e.series->orbit_map, m->second->params.size()));
            }
            scopes_.emplace_back();
            scopes_.back()[e.series->var] = value;
            if (!e.series->orbit_var.empty()) scopes_.back()[e.series->orbit_var] = value;
            expr(*e.kids[2]);
            scopes_.pop_back();
            return;
        }
        case ExprKind::lambda:
            d_.error(e.loc, "an anonymous function is an argument where a function is expected (a parameter "
                            "that the callee calls)");
            return;
        case ExprKind::unary:
        case ExprKind::binary:
        case ExprKind::if_:
        case ExprKind::tuple:
        case ExprKind::field:
        case ExprKind::interval:
        case ExprKind::matrix:
            for (const ExprPtr& k : e.kids) expr(*k);
            return;
        }
    }

    void call(const Expr& e) {
        const int n = static_cast<int>(e.args.size());
        const std::vector<ParamType>* sig = is_local(e.text) ? nullptr : signature(e.text);
        for (std::size_t i = 0; i < e.args.size(); ++i) {
            const Arg& a = e.args[i];
            if (sig && i < sig->size() && (*sig)[i].arity != value) {
                function_argument(a, (*sig)[i].arity, e.text, globals_.at(e.text)->params[i].name);
            } else if (sig && i < sig->size() && a.value->kind == ExprKind::name &&
                       names_function(a.value->text) && !is_builtin_constant(a.value->text)) {
                d_.error(a.loc,
                         fmt::format("'{}' expects a value for its parameter '{}', but '{}' is a function",
                                     e.text, globals_.at(e.text)->params[i].name, a.value->text));
            } else {
                expr(*a.value);
            }
        }
        if (const std::optional<int> l = local(e.text)) {
            if (*l == value) {
                d_.error(e.loc, fmt::format("'{}' is a value, not a function", e.text));
            } else if (*l != n) {
                d_.error(e.loc, fmt::format("function parameter '{}' takes {} argument{}, {} given", e.text,
                                            *l, *l == 1 ? "" : "s", n));
                for (std::size_t k = 0; k < checked_->params.size(); ++k)
                    if (checked_->params[k].name == e.text)
                        d_.note(signatures_.at(checked_)[k].first_use,
                                fmt::format("its number of arguments, {}, comes from this use", *l));
            } else {
                for (const Arg& a : e.args)
                    if (!a.name.empty())
                        d_.error(a.loc, fmt::format("'{}' takes no named arguments", e.text));
            }
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
            unknown(e.loc, "function", e.text);
            return;
        }
        if (n < b->min_args || n > b->max_args) {
            // A variadic builtin's bound that was passed: "at least" below it, "at most" above it (with
            // the way around it), else the range.
            const bool variadic = b->max_args >= 64;
            const std::string want = b->min_args == b->max_args    ? fmt::format("{}", b->min_args)
                                     : variadic && n < b->min_args ? fmt::format("at least {}", b->min_args)
                                     : variadic                    ? fmt::format("at most {}", b->max_args)
                                                : fmt::format("{} to {}", b->min_args, b->max_args);
            d_.error(e.loc, fmt::format("'{}' takes {} argument{}, {} given{}", e.text, want,
                                        b->max_args == 1 ? "" : "s", n,
                                        variadic && n > b->max_args
                                            ? fmt::format(" (nest the calls: {0}({0}(...), ...))", e.text)
                                            : ""));
        }
        if (b->kind != BuiltinKind::dimension)
            for (const Arg& a : e.args)
                if (!a.name.empty()) d_.error(a.loc, fmt::format("'{}' takes no named arguments", e.text));
    }

    // An argument passed where `callee` expects a function of `arity` arguments: the name of a
    // function of that arity (of the program, a builtin, a shape, or a function parameter).
    void function_argument(const Arg& a, int arity, const std::string& callee, const std::string& param) {
        const auto plural = [](int k) { return k == 1 ? "" : "s"; };
        const std::string expected =
            fmt::format("'{}' expects a function of {} argument{} for its parameter '{}'", callee, arity,
                        plural(arity), param);
        if (!a.name.empty()) d_.error(a.loc, fmt::format("'{}' takes no named arguments", callee));
        const Expr& v = *a.value;
        if (v.kind == ExprKind::lambda) {
            const int given = static_cast<int>(v.bindings.size());
            if (given != arity)
                d_.error(v.loc, fmt::format("{}, but this function takes {} argument{}", expected, given,
                                            plural(given)));
            scopes_.emplace_back();
            for (const Binding& b : v.bindings)
                if (!scopes_.back().emplace(b.name, value).second)
                    d_.error(b.loc, fmt::format("parameter '{}' appears twice", b.name));
            expr(*v.kids[0]);
            scopes_.pop_back();
            return;
        }
        if (v.kind != ExprKind::name) {
            d_.error(v.loc, expected + "; pass the name of a function, or fn (...) = ...");
            expr(v);
            return;
        }
        auto mismatch = [&](int given) {
            d_.error(v.loc,
                     fmt::format("{}, but '{}' takes {} argument{}", expected, v.text, given, plural(given)));
        };
        if (const std::optional<int> l = local(v.text)) {
            if (*l == value)
                d_.error(v.loc, fmt::format("{}, but '{}' is a value", expected, v.text));
            else if (*l != arity)
                mismatch(*l);
            return;
        }
        if (auto g = globals_.find(v.text); g != globals_.end()) {
            const Item& f = *g->second;
            if (f.kind == ItemKind::const_) {
                d_.error(v.loc, fmt::format("{}, but '{}' is a constant", expected, v.text));
            } else if (f.kind == ItemKind::fn) {
                const auto& sig = signatures_.at(&f);
                if (std::any_of(sig.begin(), sig.end(), [](const ParamType& t) { return t.arity != value; }))
                    d_.error(v.loc,
                             fmt::format("{}, but '{}' takes functions as arguments and cannot be passed "
                                         "on (function parameters are called with values)",
                                         expected, v.text));
                else if (static_cast<int>(f.params.size()) != arity)
                    mismatch(static_cast<int>(f.params.size()));
            } else if (f.kind == ItemKind::shape) {
                const bool fits = arity == 1 || (f.has_params ? arity == static_cast<int>(f.params.size())
                                                              : arity == 2 || arity == 3);
                if (!fits)
                    d_.error(v.loc, fmt::format("{}, but shape '{}' takes a point or its coordinates",
                                                expected, v.text));
            }
            return;
        }
        if (const Builtin* b = find_builtin(v.text)) {
            if (b->kind == BuiltinKind::enclose || b->kind == BuiltinKind::dimension)
                d_.error(v.loc, fmt::format("{}; '{}' runs a computation on a shape and cannot be passed",
                                            expected, v.text));
            else if (arity < b->min_args || arity > b->max_args)
                mismatch(b->min_args);
            return;
        }
        if (is_builtin_constant(v.text))
            d_.error(v.loc, fmt::format("{}, but '{}' is a constant", expected, v.text));
        else
            unknown(v.loc, "name", v.text);
    }

    // An unknown name: the closest known one when it is a likely misspelling, and the standard library
    // module that defines the name when the model does not import it.
    void unknown(Location loc, const char* what, const std::string& name) {
        if (over_of_) {
            const bool coordinate = std::any_of(over_of_->params.begin(), over_of_->params.end(),
                                                [&](const Param& p) { return p.name == name; }) ||
                                    (!over_of_->has_params && (name == "x" || name == "y" || name == "z"));
            if (coordinate) {
                d_.error(loc,
                         fmt::format("the box after 'over' is a constant: '{}' is a coordinate of shape '{}'",
                                     name, over_of_->name));
                return;
            }
        }
        std::vector<std::string> known;
        for (const auto& scope : scopes_)
            for (const auto& [local_name, kind] : scope) known.push_back(local_name);
        for (const auto& [global, item] : globals_) known.push_back(global);
        std::sort(known.begin() + static_cast<std::ptrdiff_t>(known.size() - globals_.size()), known.end());
        for (const char* c : {"pi", "e"}) known.push_back(c);
        for (const std::string& b : builtin_names()) known.push_back(b);
        std::optional<std::string> near = closest_name(name, known);
        for (const auto& [global, item] : globals_) // a name of a module imported `as alias`
            if (!near && global.size() > name.size() && global.ends_with("." + name)) near = global;
        // Else a library name, misspelt or not: the note then says which module to import.
        std::string library_name = name;
        if (!near)
            for (const auto& [module, names] : stdlib_names())
                if (auto n = closest_name(name, {names.begin(), names.end()}); n && !names.count(name)) {
                    near = library_name = *n;
                    break;
                }
        d_.error(loc, fmt::format("unknown {} '{}'{}", what, name,
                                  near ? fmt::format("; did you mean '{}'?", *near) : ""));
        for (const auto& [module, names] : stdlib_names())
            if (names.count(library_name)) {
                d_.note(loc, fmt::format("'{}' is defined in the standard library module \"{}\": add "
                                         "import \"{}\"; at the top of the file",
                                         library_name, module, module));
                break;
            }
    }

    // The names each standard library module defines, from its own parse.
    static const std::map<std::string, std::set<std::string>>& stdlib_names() {
        static const std::map<std::string, std::set<std::string>> names = [] {
            std::map<std::string, std::set<std::string>> all;
            for (const auto& [module, text] : embedded_stdlib()) {
                Diagnostics ignored; // the library compiles; its tests say so
                const Program p = parse(lex(text, 1, ignored), ignored);
                for (const Item& it : p.items)
                    if (it.kind == ItemKind::fn || it.kind == ItemKind::const_ || it.kind == ItemKind::shape)
                        all[module].insert(it.name);
            }
            return all;
        }();
        return names;
    }

    const Program& p_;
    Diagnostics& d_;
    std::unordered_map<std::string, const Item*> globals_;
    std::vector<std::unordered_map<std::string, int>> scopes_; // name -> `value` or a function's arity
    std::unordered_map<const Item*, std::vector<ParamType>> signatures_;
    const Item* infer_fn_ = nullptr;
    const Item* checked_ = nullptr; // the item whose body is being checked
    const Item* over_of_ = nullptr; // the shape whose `over` box is being checked
    std::vector<std::unordered_set<std::string>> shadows_;
};

} // namespace

void resolve_names(const Program& program, Diagnostics& diags) {
    Resolver(program, diags).run();
}

} // namespace frac::front
