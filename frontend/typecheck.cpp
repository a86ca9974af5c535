#include "frontend/typecheck.hpp"

#include "frontend/builtins.hpp"
#include "frontend/inliner.hpp"

#include <algorithm>
#include <fmt/format.h>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <tuple>
#include <unordered_set>

namespace frac::front {

namespace {

struct Closure;

// A value during checking: its type, and for a function value which function it is (calls of a
// parameter are checked against the function passed).
struct TValue {
    Type type;
    const Item* item = nullptr; // a fn or a shape named as a value
    const Builtin* builtin = nullptr;
    std::shared_ptr<const Closure> closure;
    static TValue of(Type t) {
        TValue v;
        v.type = t;
        return v;
    }
};

struct Closure {
    const Expr* lambda;
    std::vector<std::vector<std::pair<std::string, TValue>>> scopes;
};

class Checker : Inliner<TValue> {
public:
    Checker(const Program& p, const Limits& limits, TypedProgram& out, Diagnostics& d)
        : Inliner(limits.max_inline_depth), p_(p), out_(out), d_(d),
          max_bcifs_unknowns_(limits.max_bcifs_unknowns) {}

    void run() {
        for (const Item& it : p_.items)
            if (it.kind == ItemKind::fn || it.kind == ItemKind::const_ || it.kind == ItemKind::shape ||
                it.kind == ItemKind::automaton)
                globals_[it.name] = &it;
        // The order lowering reports in: shapes first, then automata, constants, tests and prints.
        for (const Item& it : p_.items)
            if (it.kind == ItemKind::shape) guarded(&it, [&] { shape_type(it); });
        for (const Item& it : p_.items)
            if (it.kind == ItemKind::automaton) guarded(&it, [&] { automaton_type(it); });
        for (const Item& it : p_.items) {
            switch (it.kind) {
            case ItemKind::const_:
                if (!failed_.count(&it)) guarded(&it, [&] { const_type(it, it.loc); });
                break;
            case ItemKind::test: test(it); break;
            case ItemKind::print: guarded(&it, [&] { print(it); }); break;
            default: break;
            }
        }
        for (const Item* it : failed_) out_.failed.insert(it);
    }

private:
    struct AlreadyReported {};

    // Runs a check of `what` (an item or an expectation), recording it as failed on an error.
    template <class F>
    void guarded(const void* what, F&& f) {
        try {
            f();
            return;
        } catch (const CompileError& e) {
            d_.error(e.loc, e.what());
            for (const auto& [loc, message] : e.notes) d_.note(loc, message);
        } catch (const AlreadyReported&) {
        }
        out_.failed.insert(what);
    }

    [[noreturn]] static void fail(Location loc, const std::string& message) {
        throw CompileError(loc, message);
    }

    Type record(const Expr& e, Type t) {
        out_.roots[&e] = t;
        return t;
    }

    // ---- items ----
    Type shape_type(const Item& it) {
        if (auto done = out_.items.find(&it); done != out_.items.end()) return done->second;
        if (failed_.count(&it)) throw AlreadyReported{};
        if (!in_progress_.insert(&it).second)
            fail(it.loc, fmt::format("shape '{}' is defined in terms of itself", it.name));
        try {
            int axes = 0;
            if (it.over) {
                const Type box = closed(*it.over, Context::constant, true).type;
                if (box.kind != Type::Kind::box)
                    fail(it.over->loc,
                         fmt::format("'over' needs a box such as [0, 1] × [0, 1], found {}", type_name(box)));
                axes = box.size;
            }
            const int dimension = it.has_params ? static_cast<int>(it.params.size()) : axes ? axes : 2;
            if (dimension < 2 || dimension > 3)
                fail(it.loc, fmt::format("a shape has 2 or 3 coordinates, '{}' has {}", it.name, dimension));
            if (axes && axes != dimension)
                fail(it.over->loc, fmt::format("shape '{}' has {} coordinates but its box has {} axes",
                                               it.name, dimension, axes));
            shape_body(it, dimension, it.loc);
            in_progress_.erase(&it);
            return out_.items[&it] = Type{Type::Kind::shape, dimension};
        } catch (...) {
            in_progress_.erase(&it);
            failed_.insert(&it);
            throw;
        }
    }

    void shape_body(const Item& it, int dimension, Location call_loc) {
        Scope scope;
        static const char* implicit[] = {"x", "y", "z"};
        for (int k = 0; k < dimension; ++k)
            scope.emplace_back(it.has_params ? it.params[static_cast<std::size_t>(k)].name : implicit[k],
                               TValue::of(Type::number()));
        const Type t = inline_body(it, std::move(scope), call_loc, Context::shape).type;
        if (t.kind != Type::Kind::number)
            fail(it.body->loc, fmt::format("a shape's function must be a number (negative inside), found {}",
                                           type_name(t)));
    }

    Type const_type(const Item& it, Location use) {
        if (failed_.count(&it)) throw AlreadyReported{};
        if (auto done = out_.items.find(&it); done != out_.items.end()) return done->second;
        if (!in_progress_.insert(&it).second)
            fail(use, fmt::format("constant '{}' is defined in terms of itself", it.name));
        try {
            const Type t = closed(*it.body, Context::constant).type;
            in_progress_.erase(&it);
            return out_.items[&it] = t;
        } catch (...) {
            in_progress_.erase(&it);
            failed_.insert(&it);
            throw;
        }
    }

    void test(const Item& it) {
        for (const Expect& e : it.expects) {
            guarded(&e, [&] {
                if (e.within) {
                    const Expr& cmp = *e.expr;
                    if (cmp.kind != ExprKind::binary || cmp.op != Tok::eq)
                        fail(e.within->loc, "'within' needs an equality: expect a == b within tolerance");
                    require_number(closed(*cmp.kids[0], Context::test).type, cmp.kids[0]->loc);
                    require_number(closed(*cmp.kids[1], Context::test).type, cmp.kids[1]->loc);
                    require_number(closed(*e.within, Context::test).type, e.within->loc);
                } else {
                    const Type t = closed(*e.expr, Context::test).type;
                    if (t.kind != Type::Kind::boolean)
                        fail(e.expr->loc, fmt::format("'expect' needs a condition, found {}", type_name(t)));
                }
            });
        }
    }

    void print(const Item& it) {
        const Type t = closed(*it.body, Context::test).type;
        if (t.kind == Type::Kind::shape)
            fail(it.body->loc, "cannot print a shape; print enclose(shape, box) or its value at a point");
        if (t.kind == Type::Kind::function || t.kind == Type::Kind::automaton ||
            t.kind == Type::Kind::transform)
            fail(it.body->loc, fmt::format("cannot print {}", type_name(t)));
    }

    // ---- scopes and calls ----
    // A definition's expression, checked as a whole: its type is recorded (TypedProgram::roots).
    TValue closed(const Expr& e, Context ctx, bool box_expected = false) {
        TValue v = in_closed_frame(ctx, [&] { return box_expected ? expected_box(e) : expr(e); });
        record(e, v.type);
        return v;
    }

    // Where a box is expected, `*` between intervals is the ASCII spelling of ×.
    TValue expected_box(const Expr& e) {
        if (e.kind == ExprKind::binary && e.op == Tok::star) {
            const Type a = expected_box(*e.kids[0]).type;
            const Type b = expr(*e.kids[1]).type;
            if (is_box_product(a, b)) return TValue::of(box_product_rule(a, b, e.loc));
        }
        return expr(e);
    }

    TValue inline_body(const Item& it, Scope params, Location call_loc, Context ctx) {
        TValue v = in_call_frame(Frame{ctx, {std::move(params)}, 0}, &it, call_loc, call_note(it, call_loc),
                                 [&] { return expr(*it.body); });
        record(*it.body, v.type);
        return v;
    }

    // ---- expressions ----
    TValue expr(const Expr& e) {
        switch (e.kind) {
        case ExprKind::number: return TValue::of(Type::number());
        case ExprKind::name: return name(e);
        case ExprKind::call: return call(e);
        case ExprKind::unary: return TValue::of(unary_rule(e.op, expr(*e.kids[0]).type, e.kids[0]->loc));
        case ExprKind::binary: {
            const Type a = expr(*e.kids[0]).type;
            const Type b = expr(*e.kids[1]).type;
            return TValue::of(binary_rule(e.op, a, b, e.loc, e.kids[0]->loc, e.kids[1]->loc));
        }
        case ExprKind::if_: {
            require_condition(expr(*e.kids[0]).type, e.kids[0]->loc);
            const Type a = expr(*e.kids[1]).type;
            const Type b = expr(*e.kids[2]).type;
            return TValue::of(if_rule(a, b, e.kids[1]->loc, e.kids[2]->loc));
        }
        case ExprKind::let: return let(e, [&](const Expr& x) { return expr(x); });
        case ExprKind::tuple: {
            const Type t = tuple_rule(e.kids.size(), e.loc);
            for (const ExprPtr& k : e.kids) require_number(expr(*k).type, k->loc);
            return TValue::of(t);
        }
        case ExprKind::field: return TValue::of(field_rule(expr(*e.kids[0]).type, e.text, e.loc));
        case ExprKind::interval:
            require_number(expr(*e.kids[0]).type, e.kids[0]->loc);
            require_number(expr(*e.kids[1]).type, e.kids[1]->loc);
            return TValue::of(Type::interval());
        case ExprKind::series: return series(e);
        case ExprKind::matrix: return TValue::of(matrix_type(e));
        case ExprKind::lambda: {
            TValue v = TValue::of(Type{Type::Kind::function});
            v.closure = std::make_shared<const Closure>(Closure{&e, frames_.back().scopes});
            return v;
        }
        }
        throw InternalError("typecheck: unknown expression kind");
    }

    TValue name(const Expr& e) {
        if (const TValue* v = lookup_local(e.text)) return *v;
        if (auto g = globals_.find(e.text); g != globals_.end()) {
            const Item& it = *g->second;
            if (it.kind == ItemKind::const_) return TValue::of(const_type(it, e.loc));
            TValue v;
            v.item = &it;
            v.type = it.kind == ItemKind::shape       ? shape_type(it)
                     : it.kind == ItemKind::automaton ? automaton_type(it)
                                                      : Type{Type::Kind::function};
            return v;
        }
        if (e.text == "identity") return TValue::of(Type::transform(0));
        if (is_builtin_constant(e.text)) return TValue::of(Type::number());
        if (const Builtin* b = find_builtin(e.text)) {
            TValue v = TValue::of(Type{Type::Kind::function});
            v.builtin = b;
            return v;
        }
        throw InternalError(fmt::format("unresolved name '{}'", e.text));
    }

    TValue call(const Expr& e) {
        if (const TValue* local = lookup_local(e.text)) { // a function parameter
            const TValue f = *local;
            if (f.item) return call_item(*f.item, e);
            if (f.builtin) return call_builtin(*f.builtin, e);
            if (f.closure) {
                std::vector<TValue> args;
                for (const Arg& a : e.args) args.push_back(expr(*a.value));
                return call_closure(*f.closure, std::move(args), e.loc);
            }
            fail(e.loc, fmt::format("'{}' is a value, not a function", e.text));
        }
        if (auto g = globals_.find(e.text); g != globals_.end()) return call_item(*g->second, e);
        const Builtin* b = find_builtin(e.text);
        if (!b) throw InternalError(fmt::format("unresolved function '{}'", e.text));
        return call_builtin(*b, e);
    }

    TValue call_closure(const Closure& c, std::vector<TValue> args, Location call_loc) {
        Frame f{frames_.back().ctx, c.scopes, 0};
        f.scopes.emplace_back();
        for (std::size_t i = 0; i < args.size(); ++i)
            f.scopes.back().emplace_back(c.lambda->bindings[i].name, std::move(args[i]));
        return in_call_frame(std::move(f), nullptr, call_loc, "in this call of the anonymous function",
                             [&] { return expr(*c.lambda->kids[0]); });
    }

    TValue call_item(const Item& it, const Expr& e) {
        if (it.kind == ItemKind::shape) return TValue::of(call_shape(it, e));
        if (it.kind != ItemKind::fn) throw InternalError("call of a non-function");
        Scope params;
        std::vector<Type> signature;
        bool plain = true; // no function-valued argument: the instance depends on the types alone
        for (std::size_t i = 0; i < it.params.size(); ++i) {
            TValue v = expr(*e.args[i].value);
            plain &= !v.item && !v.builtin && !v.closure;
            signature.push_back(v.type);
            params.emplace_back(it.params[i].name, std::move(v));
        }
        const Context ctx = frames_.back().ctx;
        const InstanceKey key{&it, signature, ctx};
        if (plain)
            if (auto done = checked_.find(key); done != checked_.end()) return TValue::of(done->second);
        TValue result = inline_body(it, std::move(params), e.loc, ctx);
        if (plain && !result.item && !result.builtin && !result.closure) {
            checked_[key] = result.type;
            out_.instances.push_back({&it, signature, result.type});
        }
        return result;
    }

    Type call_shape(const Item& it, const Expr& e) {
        const int dim = shape_type(it).size;
        if (e.args.size() == 1) {
            const Type p = expr(*e.args[0].value).type;
            if (p.kind != Type::Kind::point || p.size != dim)
                fail(e.args[0].loc,
                     fmt::format("shape '{}' takes {} coordinates or a point of {}", it.name, dim, dim));
        } else {
            if (static_cast<int>(e.args.size()) != dim)
                fail(e.loc,
                     fmt::format("shape '{}' takes {} coordinates, {} given", it.name, dim, e.args.size()));
            for (const Arg& a : e.args) require_number(expr(*a.value).type, a.loc);
        }
        return Type::number();
    }

    TValue call_builtin(const Builtin& b, const Expr& e) {
        if (b.kind == BuiltinKind::enclose || b.kind == BuiltinKind::dimension) return query(e, b);
        if (b.kind == BuiltinKind::tabulate) {
            if (frames_.back().ctx != Context::test)
                fail(
                    e.loc,
                    "'tabulate' runs a computation on an automaton; it is available in tests and print only");
            const Type a = expr(*e.args[0].value).type;
            if (a.kind != Type::Kind::automaton)
                fail(e.args[0].loc, fmt::format("'tabulate' needs an ifs or cifs, found {}", type_name(a)));
            require_number(expr(*e.args[1].value).type, e.args[1].loc);
            return TValue::of(Type::point(a.size));
        }
        if (b.kind == BuiltinKind::dof) {
            if (frames_.back().ctx != Context::test)
                fail(e.loc, "'dof' reads the solution of a bcifs; it is available in tests and print only");
            const Expr& a = *e.args[0].value;
            const Item* it = nullptr;
            if (a.kind == ExprKind::field && a.kids[0]->kind == ExprKind::name)
                if (auto g = globals_.find(a.kids[0]->text); g != globals_.end()) it = g->second;
            if (!it || it->kind != ItemKind::automaton || !it->automaton->bcifs)
                fail(a.loc, "'dof' counts the free entries of a cell of a bcifs: dof(name.cell)");
            automaton_type(*it);
            const auto& states = it->automaton->states;
            if (std::none_of(states.begin(), states.end(),
                             [&](const StateDecl& s) { return s.name == a.text; }))
                fail(a.loc, fmt::format("bcifs '{}' has no cell '{}'", it->name, a.text));
            return TValue::of(Type::number());
        }
        if (b.kind == BuiltinKind::distance) {
            if (frames_.back().ctx == Context::constant)
                fail(e.loc, "'dist' is computed by the runtime: it is not a constant expression");
            const Type a = expr(*e.args[1].value).type;
            if (a.kind != Type::Kind::automaton)
                fail(e.args[1].loc,
                     fmt::format("'dist' measures the distance to an ifs or cifs, found {}", type_name(a)));
            const Type p = expr(*e.args[0].value).type;
            if (p.kind != Type::Kind::point || p.size != a.size)
                fail(e.args[0].loc,
                     fmt::format("'dist' needs a point of {} coordinates (the automaton's output dimension), "
                                 "found {}",
                                 a.size,
                                 p.kind == Type::Kind::point
                                     ? fmt::format("a point of {} coordinates", p.size)
                                     : type_name(p)));
            return TValue::of(Type::number());
        }
        if (b.kind == BuiltinKind::controls) return TValue::of(controls_type(e));
        if (b.kind == BuiltinKind::kron) {
            Type t[2];
            for (int k = 0; k < 2; ++k) {
                t[k] = expr(*e.args[k].value).type;
                if (t[k].kind != Type::Kind::matrix)
                    fail(e.args[k].loc,
                         fmt::format("'kron' multiplies two matrices, found {}", type_name(t[k])));
            }
            if (t[0].rows * t[1].rows > 4096 || t[0].cols * t[1].cols > 4096)
                fail(e.loc, "'kron' would make a matrix of more than 4096 rows or columns");
            return TValue::of(Type::matrix(t[0].rows * t[1].rows, t[0].cols * t[1].cols));
        }
        if (b.kind == BuiltinKind::primitive)
            fail(e.loc,
                 fmt::format("'{}' draws a state of an automaton: it is written after 'primitive' only",
                             e.text));
        for (const Arg& a : e.args) require_number(expr(*a.value).type, a.loc);
        if (b.kind != BuiltinKind::transform) return TValue::of(Type::number());
        // translate(x, y[, z]), scale(s) or scale(sx, sy[, sz]), rotate(angle), shear(kx, ky).
        const std::string name = e.text;
        const int n = static_cast<int>(e.args.size());
        if (name == "translate") return TValue::of(Type::transform(n));
        if (name == "scale") {
            if (n == 1) return TValue::of(Type::transform(0));
            return TValue::of(Type::transform(n));
        }
        if (name == "shear" && n != 2) fail(e.loc, "'shear' takes 2 arguments, kx and ky (a shear of R2)");
        return TValue::of(Type::transform(2));
    }

    // controls(P0, ..., Pn-1): points of one dimension, as the columns of a (d + 1) × n matrix.
    Type controls_type(const Expr& e) {
        int d = 0;
        for (const Arg& a : e.args) {
            const Type p = expr(*a.value).type;
            if (p.kind != Type::Kind::point)
                fail(a.loc, fmt::format("a control point is a point, found {}", type_name(p)));
            if (d && p.size != d)
                fail(a.loc, fmt::format("control points of {} and {} coordinates", d, p.size));
            d = p.size;
        }
        return Type::matrix(d + 1, static_cast<int>(e.args.size()));
    }

    // [[a, b], [c, d]]: constant numbers, rows of one length (the parser checked the lengths).
    Type matrix_type(const Expr& e) {
        for (const ExprPtr& row : e.kids)
            for (const ExprPtr& k : row->kids) require_number(expr(*k).type, k->loc);
        return Type::matrix(static_cast<int>(e.kids.size()), static_cast<int>(e.kids[0]->kids.size()));
    }

    // ---- automata ----
    static int coordinates(const SpaceDecl& s) { return s.barycentric ? s.n : s.n + 1; }
    static std::string space_text(const SpaceDecl& s) {
        return s.barycentric ? fmt::format("bary({})", s.n) : fmt::format("R{}", s.n);
    }

    Type automaton_type(const Item& it) {
        if (auto done = out_.items.find(&it); done != out_.items.end()) return done->second;
        if (failed_.count(&it)) throw AlreadyReported{};
        try {
            check_automaton(it);
        } catch (...) {
            failed_.insert(&it);
            throw;
        }
        // Its size: the dimension of the space its attractor is drawn in.
        const AutomatonDecl& a = *it.automaton;
        const StateDecl* initial = &initial_state(a);
        const int drawn = initial->space.barycentric ? closed(*a.projection, Context::constant).type.rows - 1
                                                     : initial->space.n;
        return out_.items[&it] = Type{Type::Kind::automaton, drawn};
    }

    void check_automaton(const Item& it) {
        const AutomatonDecl& a = *it.automaton;
        const auto state = [&](const std::string& name) -> const StateDecl& {
            for (const StateDecl& s : a.states)
                if (s.name == name) return s;
            throw InternalError("an unresolved state");
        };
        for (const ArcDecl& arc : a.arcs) {
            const SpaceDecl &from = state(arc.from).space, &to = state(arc.to).space;
            const Type op = closed(*arc.op, Context::constant).type;
            const int rows = coordinates(from), cols = coordinates(to);
            const std::string arc_text = fmt::format("{} -> {}", arc.from, arc.to);
            if (op.kind == Type::Kind::transform) {
                if (from.barycentric || to.barycentric || from.n != to.n)
                    fail(arc.op->loc,
                         fmt::format("the arc {} maps {} into {}: a transform maps a space R2 or R3 into "
                                     "itself; write a matrix of {} rows and {} columns",
                                     arc_text, space_text(to), space_text(from), rows, cols));
                if (op.size && op.size != from.n)
                    fail(arc.op->loc, fmt::format("the arc {} connects states in R{}, its operator is {}",
                                                  arc_text, from.n, type_name(op)));
            } else if (op.kind == Type::Kind::matrix) {
                if (op.rows != rows || op.cols != cols)
                    fail(arc.op->loc,
                         fmt::format(
                             "the arc {} maps {} into {}, so its matrix has {} rows and {} columns; this one "
                             "is {}×{}",
                             arc_text, space_text(to), space_text(from), rows, cols, op.rows, op.cols));
            } else {
                fail(arc.op->loc,
                     fmt::format("an arc's operator is a matrix or a transform, found {}", type_name(op)));
            }
            if (arc.probability)
                require_number(closed(*arc.probability, Context::constant).type, arc.probability->loc);
        }
        if (a.bcifs) check_bcifs(it, a, state);
        const StateDecl& initial = initial_state(a);
        if (a.projection) {
            const Type p = closed(*a.projection, Context::constant).type;
            if (!initial.space.barycentric)
                fail(a.projection->loc,
                     fmt::format("the initial state '{}' is in {}: only a barycentric initial "
                                 "state is projected",
                                 initial.name, space_text(initial.space)));
            if (p.kind != Type::Kind::matrix || p.cols != initial.space.n || (p.rows != 3 && p.rows != 4))
                fail(a.projection->loc,
                     fmt::format("the projection of bary({}) is controls(P1, ..., P{}) with points "
                                 "of R2 or R3, found {}",
                                 initial.space.n, initial.space.n, type_name(p)));
        } else if (initial.space.barycentric) {
            fail(a.initial.empty() ? initial.loc : a.initial_loc,
                 fmt::format("the initial state '{}' is in bary({}): give its control points, as in "
                             "project = controls(P1, ..., P{});",
                             initial.name, initial.space.n, initial.space.n));
        }
        for (const StateDecl& s : a.states)
            if (s.primitive) primitive_type(s);
    }

    // The operators' sizes follow from the cells' spaces; every constraint's products are defined and
    // both sides have one size; the entries and fixed values are numbers (the parameters are numbers).
    template <class State>
    void check_bcifs(const Item& it, const AutomatonDecl& a, const State& state) {
        const BcifsDecl& b = *a.bcifs;
        for (const ParamDecl& p : b.params)
            for (const Expr* e : {p.lo.get(), p.hi.get(), p.value.get()})
                if (e) require_number(closed(*e, Context::constant).type, e->loc);
        std::map<std::pair<std::string, std::string>, const OperatorDecl*> operators;
        const auto size_of = [&](const OperatorDecl& op) {
            return std::pair{coordinates(state(op.cell).space), coordinates(state(op.target).space)};
        };
        for (const OperatorDecl& op : b.operators) {
            operators[{op.cell, op.name}] = &op;
            if (!op.value) continue;
            const auto [rows, cols] = size_of(op);
            const std::string what =
                fmt::format("'{}.{}' maps {} ('{}') into {} ('{}'), so it is a {}×{} matrix", op.cell,
                            op.name, space_text(state(op.target).space), op.target,
                            space_text(state(op.cell).space), op.cell, rows, cols);
            if (op.value->kind == ExprKind::matrix) {
                const auto& m = op.value->kids;
                if (static_cast<int>(m.size()) != rows || static_cast<int>(m.front()->kids.size()) != cols)
                    fail(op.value->loc,
                         fmt::format("{}; this one is {}×{}", what, m.size(), m.front()->kids.size()));
                for (const ExprPtr& row : m)
                    for (const ExprPtr& entry : row->kids)
                        if (!is_unknown(*entry)) require_number(with_params(b, *entry).type, entry->loc);
                continue;
            }
            const Type t = closed(*op.value, Context::constant).type;
            if (t.kind != Type::Kind::matrix || t.rows != rows || t.cols != cols)
                fail(op.value->loc, fmt::format("{}; found {}", what, type_name(t)));
        }
        for (const FixDecl& f : b.fixes) {
            const auto [rows, cols] = size_of(*operators.at({f.cell, f.name}));
            if (f.row >= rows || f.col >= cols)
                fail(f.index_loc, fmt::format("'{}.{}' is {}×{}: entry [{}][{}] is outside it (indices count "
                                              "from 0)",
                                              f.cell, f.name, rows, cols, f.row, f.col));
            require_number(with_params(b, *f.value).type, f.value->loc);
        }
        for (const ConstraintDecl& c : b.constraints) {
            std::pair<int, int> sides[2];
            for (int k = 0; k < 2; ++k) {
                const std::vector<FactorDecl>& side = k == 0 ? c.left : c.right;
                std::optional<std::pair<int, int>> size;
                std::string text;
                for (const FactorDecl& f : side) {
                    std::pair<int, int> fs;
                    if (f.constant) {
                        const Type t = closed(*f.constant, Context::constant).type;
                        if (t.kind != Type::Kind::matrix)
                            fail(f.loc, fmt::format("a factor of a constraint is an operator or a matrix, "
                                                    "found {}",
                                                    type_name(t)));
                        fs = {t.rows, t.cols};
                    } else {
                        fs = size_of(*operators.at({f.cell, f.name}));
                    }
                    const std::string name =
                        f.constant ? fmt::format("a {}×{} matrix", fs.first, fs.second)
                                   : fmt::format("{}.{} ({}×{})", f.cell, f.name, fs.first, fs.second);
                    if (size && size->second != fs.first)
                        fail(f.loc, fmt::format("{} has {} columns, so it cannot be multiplied by {}", text,
                                                size->second, name));
                    size = size ? std::pair{size->first, fs.second} : fs;
                    text = text.empty() ? name : text + " * " + name;
                }
                sides[k] = *size;
            }
            if (sides[0] != sides[1])
                fail(c.loc, fmt::format("the two sides of this constraint differ in size: {}×{} and {}×{}",
                                        sides[0].first, sides[0].second, sides[1].first, sides[1].second));
        }
        check_bcifs_size(it, a, size_of);
    }

    // The solver (frontend/bcifs.hpp) builds and solves a linear system with an unknown per unknown entry
    // of the operators, and its work and memory grow with their number: more than the limit
    // (Limits::max_bcifs_unknowns) is refused before anything is built, at the bcifs, with a note at the
    // declaration whose operators have the most of them (a topology's split, usually). Every count is a
    // product of two sizes below 2^16 summed over the model's operators, far from 2^64.
    template <class SizeOf>
    void check_bcifs_size(const Item& it, const AutomatonDecl& a, const SizeOf& size_of) {
        std::uint64_t unknowns = 0;
        // Unknown entries per declaration (file, line, column): a topology's operators share its location.
        std::map<std::tuple<std::uint32_t, std::uint32_t, std::uint32_t>, std::pair<Location, std::uint64_t>>
            by_declaration;
        for (const OperatorDecl& op : a.bcifs->operators) {
            const auto [rows, cols] = size_of(op);
            std::uint64_t unknown = 0;
            if (!op.value && op.source.empty())
                unknown = static_cast<std::uint64_t>(rows) * static_cast<std::uint64_t>(cols);
            else if (op.value && op.value->kind == ExprKind::matrix)
                for (const ExprPtr& row : op.value->kids)
                    for (const ExprPtr& entry : row->kids) unknown += is_unknown(*entry) ? 1 : 0;
            if (unknown == 0) continue;
            unknowns += unknown;
            auto& d = by_declaration[{op.loc.file, op.loc.line, op.loc.column}];
            d.first = op.loc;
            d.second += unknown;
        }
        if (unknowns <= max_bcifs_unknowns_) return;
        CompileError e(it.loc,
                       fmt::format("bcifs '{}' has {} unknown entries to solve for, more than the limit "
                                   "of {}{}; split its cells into fewer parts or give them fewer "
                                   "control points (a smaller bary(n))",
                                   it.name, unknowns, max_bcifs_unknowns_,
                                   raised_by("FRAC_MAX_BCIFS_UNKNOWNS")));
        const auto most =
            std::max_element(by_declaration.begin(), by_declaration.end(),
                             [](const auto& x, const auto& y) { return x.second.second < y.second.second; });
        if (most != by_declaration.end())
            e.notes.emplace_back(
                most->second.first,
                fmt::format("{} of them are entries of the operators declared here", most->second.second));
        throw e;
    }

    // An entry of an operator or a fixed value: a constant in which the bcifs's parameters are numbers.
    TValue with_params(const BcifsDecl& b, const Expr& e) {
        return in_closed_frame(Context::constant, [&] {
            for (const ParamDecl& p : b.params)
                frames_.back().scopes.back().emplace_back(p.name, TValue::of(Type::number()));
            return expr(e);
        });
    }

    // point(p), segment(p, q), polyline(p, ...), polygon(p, ...) of points in a euclidean state's space;
    // polyline() and polygon() of a barycentric state join its vertices; or a shape of its dimension.
    void primitive_type(const StateDecl& s) {
        const Expr& e = *s.primitive;
        if (e.kind == ExprKind::name) {
            const Type t = closed(e, Context::constant).type;
            if (t.kind != Type::Kind::shape || s.space.barycentric || t.size != s.space.n)
                fail(e.loc, fmt::format("a primitive is a shape of the state's space {} or a point, segment, "
                                        "polyline or polygon; found {}",
                                        space_text(s.space), type_name(t)));
            return;
        }
        const Builtin* b = e.kind == ExprKind::call ? find_builtin(e.text) : nullptr;
        if (!b || b->kind != BuiltinKind::primitive)
            fail(e.loc,
                 "a primitive is point(p), segment(p, q), polyline(p, ...), polygon(p, ...) or a shape");
        if (s.space.barycentric) {
            if (!e.args.empty() || (e.text != "polyline" && e.text != "polygon"))
                fail(e.loc,
                     fmt::format("a state in bary({}) draws polyline() or polygon(): its vertices joined",
                                 s.space.n));
            return;
        }
        if (e.args.empty()) fail(e.loc, fmt::format("'{}' needs points of R{}", e.text, s.space.n));
        for (const Arg& a : e.args) {
            const Type p = closed(*a.value, Context::constant).type;
            if (p.kind != Type::Kind::point || p.size != s.space.n)
                fail(a.loc, fmt::format("a point of the state's space R{} is expected, found {}", s.space.n,
                                        p.kind == Type::Kind::point
                                            ? fmt::format("a point of {} coordinates", p.size)
                                            : type_name(p)));
        }
    }

    TValue query(const Expr& e, const Builtin& b) {
        if (frames_.back().ctx != Context::test)
            fail(e.loc,
                 fmt::format("'{}' runs a computation on a shape; it is available in tests and print only",
                             e.text));
        const TValue s = expr(*e.args[0].value);
        if (b.kind == BuiltinKind::dimension && s.type.kind == Type::Kind::automaton) {
            if (e.args.size() > 1)
                fail(e.args[1].loc,
                     "the dimension of an automaton is computed from its maps: it takes no levels");
            return TValue::of(Type::number());
        }
        if (s.type.kind != Type::Kind::shape)
            fail(e.args[0].loc, fmt::format("'{}' needs a shape as its first argument", e.text));
        if (b.kind == BuiltinKind::enclose) {
            const Type box = expected_box(*e.args[1].value).type;
            if (box.kind != Type::Kind::box)
                fail(e.args[1].loc, fmt::format("'enclose' needs a box, found {}", type_name(box)));
            if (box.size != s.type.size)
                fail(e.args[1].loc, fmt::format("shape '{}' has {} coordinates, the box has {} axes",
                                                s.item->name, s.type.size, box.size));
            return TValue::of(Type::interval());
        }
        bool have_from = false, have_to = false;
        for (std::size_t i = 1; i < e.args.size(); ++i) {
            const Arg& a = e.args[i];
            require_number(expr(*a.value).type, a.loc);
            if (a.name == "from")
                have_from = true;
            else if (a.name == "to")
                have_to = true;
            else if (a.name != "split")
                fail(a.loc, "'dimension' takes named arguments from:, to: and split:");
        }
        if (!have_from || !have_to) fail(e.loc, "'dimension' needs from: and to: levels");
        return TValue::of(Type::number());
    }

    TValue series(const Expr& e) {
        require_number(expr(*e.kids[0]).type, e.kids[0]->loc);
        if (e.kids[1]) require_number(expr(*e.kids[1]).type, e.kids[1]->loc);
        // By index: checking the orbit's map pushes frames (and may move them).
        const std::size_t frame = frames_.size() - 1;
        const auto scope = [&]() -> Scope& { return frames_[frame].scopes.back(); };
        frames_[frame].scopes.emplace_back();
        struct Pop {
            std::vector<Frame>& f;
            std::size_t i;
            ~Pop() { f[i].scopes.pop_back(); }
        } pop{frames_, frame};
        if (!e.series->orbit_var.empty()) {
            // The initial point is outside the series (the index is not visible to it).
            const Type init = expr(*e.kids[3]).type;
            if (e.kids.size() > 4) expr(*e.kids[4]);
            if (init.kind != Type::Kind::point)
                fail(e.kids[3]->loc, fmt::format("an orbit starts at a point, found {}", type_name(init)));
            scope().emplace_back(e.series->var, TValue::of(Type::number()));
            const TValue* local_map = lookup_local(e.series->orbit_map);
            if (local_map && !local_map->item && !local_map->closure)
                fail(e.series->orbit_loc,
                     fmt::format("the map of an orbit must be a function of a point defined with "
                                 "'fn'; '{}' is bound to a builtin or a shape",
                                 e.series->orbit_map));
            Type next;
            if (local_map && local_map->closure) {
                next = call_closure(*local_map->closure, {TValue::of(init)}, e.series->orbit_loc).type;
            } else {
                const Item& map = local_map ? *local_map->item : *globals_.at(e.series->orbit_map);
                if (map.kind != ItemKind::fn)
                    fail(e.series->orbit_loc,
                         fmt::format("the map of an orbit must be a function of a point defined with "
                                     "'fn'; '{}' is bound to a builtin or a shape",
                                     e.series->orbit_map));
                next = inline_body(map, {{map.params[0].name, TValue::of(init)}}, e.series->orbit_loc,
                                   frames_.back().ctx)
                           .type;
            }
            if (next != init)
                fail(e.series->orbit_loc, fmt::format("the map '{}' must return a point of {} coordinates",
                                                      e.series->orbit_map, init.size));
            scope().emplace_back(e.series->orbit_var, TValue::of(init));
        } else {
            scope().emplace_back(e.series->var, TValue::of(Type::number()));
        }
        require_number(expr(*e.kids[2]).type, e.kids[2]->loc);
        return TValue::of(Type::number());
    }

    struct InstanceKey {
        const Item* item;
        std::vector<Type> params;
        Context ctx;
        bool operator<(const InstanceKey& o) const {
            if (item != o.item) return item < o.item;
            if (ctx != o.ctx) return ctx < o.ctx;
            if (params.size() != o.params.size()) return params.size() < o.params.size();
            for (std::size_t i = 0; i < params.size(); ++i) {
                const Type &a = params[i], &b = o.params[i];
                if (a.kind != b.kind) return a.kind < b.kind;
                if (a.size != b.size) return a.size < b.size;
                if (a.rows != b.rows) return a.rows < b.rows;
                if (a.cols != b.cols) return a.cols < b.cols;
            }
            return false;
        }
    };

    const Program& p_;
    TypedProgram& out_;
    Diagnostics& d_;
    std::uint64_t max_bcifs_unknowns_;
    std::unordered_map<std::string, const Item*> globals_;
    std::unordered_set<const Item*> in_progress_, failed_;
    std::map<InstanceKey, Type> checked_;
};

} // namespace

void typecheck(const Program& program, const Limits& limits, TypedProgram& out, Diagnostics& diags) {
    Checker(program, limits, out, diags).run();
}

std::string print_types(const Program& program, const TypedProgram& typed, std::uint32_t file) {
    std::string out;
    const auto type_of = [&](const Expr* e) {
        const Type* t = typed.roots.find(e);
        return t ? type_spelling(*t) : std::string("unchecked");
    };
    for (const Item& it : program.items) {
        if (file != 0 && it.loc.file != file) continue;
        switch (it.kind) {
        case ItemKind::const_: out += fmt::format("const {} : {}\n", it.name, type_of(it.body.get())); break;
        case ItemKind::shape: {
            auto t = typed.items.find(&it);
            out += fmt::format("shape {} : {}{}\n", it.name,
                               t == typed.items.end() ? std::string("unchecked") : type_spelling(t->second),
                               it.over ? " over " + type_of(it.over.get()) : "");
            break;
        }
        case ItemKind::fn: {
            std::set<std::string> printed; // an instance checked in shapes and in tests is one signature
            for (const FunctionInstance& f : typed.instances) {
                if (f.function != &it) continue;
                std::string params;
                for (std::size_t i = 0; i < f.params.size(); ++i)
                    params +=
                        fmt::format("{}{}: {}", i ? ", " : "", it.params[i].name, type_spelling(f.params[i]));
                const std::string line =
                    fmt::format("fn {}({}) -> {}\n", it.name, params, type_spelling(f.result));
                if (printed.insert(line).second) out += line;
            }
            break;
        }
        case ItemKind::test:
            out += fmt::format("test \"{}\" : {} expectations\n", it.name, it.expects.size());
            break;
        case ItemKind::print: out += fmt::format("print : {}\n", type_of(it.body.get())); break;
        case ItemKind::automaton: {
            const AutomatonDecl& a = *it.automaton;
            out += fmt::format("{} {} : automaton\n",
                               a.bcifs            ? "bcifs"
                               : a.graph_directed ? "cifs"
                                                  : "ifs",
                               it.name);
            for (const ArcDecl& arc : a.arcs)
                out += fmt::format("  {} -> {}{} : {}\n", arc.from, arc.to,
                                   arc.label.empty() ? "" : " " + arc.label, type_of(arc.op.get()));
            break;
        }
        case ItemKind::import: break;
        }
    }
    return out;
}

} // namespace frac::front
