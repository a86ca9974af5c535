#include "frontend/lower.hpp"

#include "frontend/bcifs.hpp"
#include "frontend/builtins.hpp"
#include "frontend/consteval.hpp"
#include "frontend/inliner.hpp"
#include "frontend/operators.hpp"
#include "frontend/orbit_escape.hpp"
#include "frontend/series_bounds.hpp"
#include "frontend/typecheck.hpp"
#include "ir/automaton_check.hpp"
#include "numeric/rational.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string_view>
#include <unordered_map>
#include <unordered_set>

namespace frac::front {

using ir::Op;

namespace {

struct Closure;

// The nodes of a value: held inline up to a point's three coordinates, as nearly every value is a
// number or a point (more, a query's components, go to the heap).
class NodeList {
public:
    NodeList() = default;
    NodeList(std::initializer_list<NodeId> nodes) {
        for (NodeId n : nodes) push_back(n);
    }
    std::vector<NodeId> vector() const { return {begin(), end()}; }

    void push_back(NodeId n) {
        if (size_ < inline_.size()) {
            inline_[size_] = n;
        } else {
            if (size_ == inline_.size()) heap_.assign(inline_.begin(), inline_.end());
            heap_.push_back(n);
        }
        ++size_;
    }
    std::size_t size() const { return size_; }
    bool empty() const { return size_ == 0; }
    NodeId* begin() { return size_ <= inline_.size() ? inline_.data() : heap_.data(); }
    NodeId* end() { return begin() + size_; }
    const NodeId* begin() const { return size_ <= inline_.size() ? inline_.data() : heap_.data(); }
    const NodeId* end() const { return begin() + size_; }
    NodeId& operator[](std::size_t i) { return begin()[i]; }
    NodeId operator[](std::size_t i) const { return begin()[i]; }

private:
    std::size_t size_ = 0;
    std::array<NodeId, 3> inline_{};
    std::vector<NodeId> heap_; // all of them, when more than fit inline
};

// A value during lowering: its graph nodes (or constant box) and, for a function or shape used as a
// value, which one.
struct Value {
    ValueKind kind = ValueKind::scalar;
    NodeList nodes;
    std::vector<Interval> box;
    const Item* shape = nullptr; // a shape used as a value (enclose, dimension), or passed as a function
    // A function passed as an argument (resolve_names checked its uses): inlined where it is called.
    const Item* function = nullptr;
    const Builtin* builtin = nullptr;
    std::shared_ptr<const Closure> closure;    // an anonymous function
    const Item* automaton = nullptr;           // an ifs or cifs named as a value (dimension, dist)
    std::shared_ptr<const LinearValue> linear; // a matrix or a transform (operators of automata)

    static Value of(ValueKind kind, NodeId n) {
        Value v;
        v.kind = kind;
        v.nodes = {n};
        return v;
    }
    static Value scalar(NodeId n) { return of(ValueKind::scalar, n); }
    static Value boolean(NodeId n) { return of(ValueKind::boolean, n); }

    // Its type, for the typing rules (types.hpp) that the type checker applied before.
    Type type() const {
        if (shape) return Type{Type::Kind::shape};
        if (function || builtin || closure) return Type{Type::Kind::function};
        if (automaton) return Type{Type::Kind::automaton};
        if (linear && linear->transform) return Type::transform(linear->dimension);
        if (linear)
            return Type::matrix(static_cast<int>(linear->in(0).rows()),
                                static_cast<int>(linear->in(0).cols()));
        switch (kind) {
        case ValueKind::scalar: return Type::number();
        case ValueKind::boolean: return Type::boolean();
        case ValueKind::point: return Type::point(static_cast<int>(nodes.size()));
        case ValueKind::interval: return Type::interval();
        case ValueKind::box: return Type::box(static_cast<int>(box.size()));
        }
        return Type::number();
    }
};

// An anonymous function with the scopes it was written in. It is only ever an argument, so it is
// called while those scopes (and the series whose indices they hold) are still active.
struct Closure {
    const Expr* lambda;
    std::vector<std::vector<std::pair<std::string, Value>>> scopes;
};

class Lowering : Inliner<Value> {
public:
    Lowering(const Program& p, const TypedProgram& typed, const SourceManager& sm, const Limits& limits,
             Module& m, Diagnostics& d, const ConstantValues* constants = nullptr,
             std::optional<std::uint64_t> free_entry_seed = std::nullopt)
        : Inliner(limits.max_inline_depth), p_(p), typed_(typed), sm_(sm), limits_(limits), m_(m),
          g_(m.graph), d_(d), constants_(constants), free_entry_seed_(free_entry_seed) {}

    // The constant stage (consteval.hpp): each constant lowered into this lowering's own graph and read
    // back as exact values or enclosures.
    void evaluate_constants(ConstantValues& out) {
        declare();
        for (const Item& it : p_.items) {
            if (it.kind != ItemKind::const_ || typed_.failed.count(&it)) continue;
            bool ok = false;
            guarded([&] {
                const Value v = const_value(it, it.loc);
                if (std::optional<ConstantValue> c = constant_of(v)) out.values[&it] = std::move(*c);
                ok = true;
            });
            if (!ok) out.failed.insert(&it);
        }
    }

    void declare() {
        for (const Item& it : p_.items) {
            if (it.kind == ItemKind::fn || it.kind == ItemKind::const_ || it.kind == ItemKind::shape ||
                it.kind == ItemKind::automaton)
                globals_[it.name] = &it;
        }
    }

    // The components of fn `map` (of one point) applied to the point (Var(0), ..., Var(d - 1)).
    std::vector<NodeId> point_map(const Item& map, int dimension) {
        Value p;
        p.kind = ValueKind::point;
        for (int k = 0; k < dimension; ++k) p.nodes.push_back(g_.var(k));
        if (map.kind != ItemKind::fn || map.params.size() != 1)
            fail(map.loc,
                 fmt::format("'{}' is not a map of the plane: a map is a fn of one point", map.name));
        const Value q = inline_body(map, {{map.params[0].name, p}}, map.loc, Context::shape);
        if (q.kind != ValueKind::point || static_cast<int>(q.nodes.size()) != dimension)
            fail(map.body->loc,
                 fmt::format("the map '{}' must return a point of {} coordinates", map.name, dimension));
        return q.nodes.vector();
    }

    void run() {
        declare();
        // Shapes first, in source order, so that tests can refer to any of them; then automata.
        for (const Item& it : p_.items)
            if (it.kind == ItemKind::shape && !typed_.failed.count(&it)) guarded([&] { shape_info(it); });
        for (const Item& it : p_.items)
            if (it.kind == ItemKind::automaton && !typed_.failed.count(&it))
                guarded([&] { automaton_info(it); });
        for (const Item& it : p_.items) {
            if (typed_.failed.count(&it)) continue; // its type error is reported
            switch (it.kind) {
            case ItemKind::const_: guarded([&] { constant(it); }); break;
            case ItemKind::test: test(it); break;
            case ItemKind::print: guarded([&] { print(it); }); break;
            case ItemKind::import:
            case ItemKind::fn:
            case ItemKind::shape:
            case ItemKind::automaton: break;
            }
        }
        for (std::size_t k = 0; k < m_.externals.size(); ++k) {
            auto it = automaton_index_.find(external_items_[k]);
            if (it == automaton_index_.end()) {
                d_.error(m_.externals[k].loc,
                         fmt::format("'dist' needs the automaton '{}', which did not compile",
                                     m_.externals[k].automaton_name));
                continue;
            }
            m_.externals[k].automaton = it->second;
        }
    }

private:
    // Thrown when a definition used here failed to compile: its error is already reported.
    struct AlreadyReported {};

    template <class F>
    void guarded(F&& f) {
        try {
            f();
        } catch (const CompileError& e) {
            d_.error(e.loc, e.what());
            for (const auto& [loc, message] : e.notes) d_.note(loc, message);
        } catch (const AlreadyReported&) {
        }
    }

    [[noreturn]] static void fail(Location loc, const std::string& message) {
        throw CompileError(loc, message);
    }

    // ---- items ----
    std::size_t shape_info(const Item& it) {
        if (auto done = shape_index_.find(&it); done != shape_index_.end()) {
            if (done->second == failed) throw AlreadyReported{};
            if (done->second == in_progress)
                fail(it.loc, fmt::format("shape '{}' is defined in terms of itself", it.name));
            return done->second;
        }
        shape_index_[&it] = in_progress;
        try {
            return build_shape(it);
        } catch (...) {
            shape_index_[&it] = failed;
            throw;
        }
    }

    std::size_t build_shape(const Item& it) {
        ShapeInfo info;
        info.name = it.name;
        info.loc = it.loc;
        // The type checker checked the box and the dimension.
        info.dimension = typed_.items.at(&it).size;
        if (it.over) {
            info.box = closed(*it.over, Context::constant, true).box;
            for (std::size_t a = 0; a < info.box.size(); ++a) {
                // Covers split the box from its width: it must be a real interval the doubles can span.
                const Interval x = info.box[a];
                if (!(std::isfinite(x.lo) && std::isfinite(x.hi) && x.lo < x.hi &&
                      std::isfinite(x.hi - x.lo)))
                    fail(
                        it.over->loc,
                        fmt::format("axis {} of the box of shape '{}' is [{}, {}]: a box needs finite bounds "
                                    "with lo < hi, and a width below the largest double",
                                    a + 1, it.name, x.lo, x.hi));
            }
        }
        if (info.box.empty()) info.box.assign(static_cast<std::size_t>(info.dimension), Interval{0.0, 1.0});
        std::vector<Value> coords;
        for (int k = 0; k < info.dimension; ++k) coords.push_back(Value::scalar(g_.var(k)));
        info.root = shape_body(it, coords, it.loc);
        m_.shapes.push_back(info);
        shape_index_[&it] = m_.shapes.size() - 1;
        return m_.shapes.size() - 1;
    }

    // The shape's function applied to the given coordinates.
    NodeId shape_body(const Item& it, const std::vector<Value>& coords, Location call_loc) {
        const int dim = it.has_params ? static_cast<int>(it.params.size()) : static_cast<int>(coords.size());
        Scope scope;
        static const char* implicit[] = {"x", "y", "z"};
        for (int k = 0; k < dim; ++k)
            scope.emplace_back(it.has_params ? it.params[static_cast<std::size_t>(k)].name : implicit[k],
                               coords[static_cast<std::size_t>(k)]);
        return scalar(inline_body(it, std::move(scope), call_loc, Context::shape), it.body->loc);
    }

    void constant(const Item& it) {
        if (!failed_consts_.count(&it)) const_value(it, it.loc); // a failure was reported where it happened
    }

    // A value of the constant stage as graph-independent numbers; nullopt for what it cannot hold (a
    // builtin or an anonymous function named by a constant), which lowering then lowers itself.
    std::optional<ConstantValue> constant_of(const Value& v) const {
        ConstantValue c;
        c.kind = v.kind;
        c.box = v.box;
        c.linear = v.linear;
        c.item = v.shape ? v.shape : v.function ? v.function : v.automaton;
        if (v.builtin || v.closure) return std::nullopt;
        for (NodeId n : v.nodes) {
            if (!g_.is_const(n)) return std::nullopt;
            ConstantComponent k;
            if (const num::Rational* q = g_.exact_value(n))
                k.exact = std::make_shared<const num::Rational>(*q);
            k.enclosure = g_[n].value;
            k.point = g_[n].point;
            c.components.push_back(std::move(k));
        }
        return c;
    }

    // The value of the constant stage as a lowering value in this graph.
    Value value_of(const ConstantValue& c) {
        Value v;
        v.kind = c.kind;
        v.box = c.box;
        v.linear = c.linear;
        if (c.item) {
            (c.item->kind == ItemKind::shape       ? v.shape
             : c.item->kind == ItemKind::automaton ? v.automaton
                                                   : v.function) = c.item;
        }
        for (const ConstantComponent& k : c.components)
            v.nodes.push_back(k.exact ? g_.constant(*k.exact) : g_.constant(k.enclosure, k.point));
        return v;
    }

    Value const_value(const Item& it, Location use) {
        if (constants_) {
            if (auto c = constants_->values.find(&it); c != constants_->values.end())
                return value_of(c->second);
            if (constants_->failed.count(&it)) throw AlreadyReported{};
        }
        if (failed_consts_.count(&it)) throw AlreadyReported{};
        if (auto c = consts_.find(&it); c != consts_.end()) {
            if (!c->second) fail(use, fmt::format("constant '{}' is defined in terms of itself", it.name));
            return *c->second;
        }
        consts_[&it] = std::nullopt;
        try {
            const Value v = closed(*it.body, Context::constant);
            consts_[&it] = v;
            return v;
        } catch (...) {
            consts_.erase(&it);
            failed_consts_.insert(&it);
            throw;
        }
    }

    void test(const Item& it) {
        TestInfo t;
        t.name = it.name;
        t.loc = it.loc;
        for (const Expect& e : it.expects) {
            if (typed_.failed.count(&e)) continue;
            guarded([&] {
                Expectation x;
                x.loc = e.loc;
                x.source = sm_.line_text(e.loc);
                if (e.within) {
                    const Expr& cmp = *e.expr;
                    const NodeId a = scalar(closed(*cmp.kids[0], Context::test), cmp.kids[0]->loc);
                    const NodeId b = scalar(closed(*cmp.kids[1], Context::test), cmp.kids[1]->loc);
                    const NodeId tol = scalar(closed(*e.within, Context::test), e.within->loc);
                    x.truth = g_.op(Op::Le, g_.op(Op::Abs, g_.op(Op::Sub, a, b)), tol);
                    x.shown = {a, b};
                } else {
                    x.truth = boolean(closed(*e.expr, Context::test), e.expr->loc);
                    if (e.expr->kind == ExprKind::binary && e.expr->kids.size() == 2) {
                        for (const ExprPtr& side : e.expr->kids) {
                            const Value s = closed(*side, Context::test);
                            if (s.kind == ValueKind::scalar) x.shown.push_back(s.nodes[0]);
                        }
                    }
                }
                t.expects.push_back(std::move(x));
            });
        }
        m_.tests.push_back(std::move(t));
    }

    void print(const Item& it) {
        const Value v = closed(*it.body, Context::test);
        m_.prints.push_back({it.loc, v.kind, v.nodes.vector(), v.box});
    }

    // ---- scopes and inlining ----
    Value closed(const Expr& e, Context ctx, bool box_expected = false) {
        return in_closed_frame(ctx, [&] { return box_expected ? expected_box(e) : expr(e); });
    }

    // Where a box is expected (`over`, enclose's box), `*` between intervals is the ASCII spelling of
    // The box a × b of an interval or box `a` and an interval `b`.
    Value box_product(const Value& a, const Value& b, Location loc) {
        box_product_rule(a.type(), b.type(), loc);
        Value r;
        r.kind = ValueKind::box;
        r.box = a.box;
        r.box.push_back(b.box[0]);
        return r;
    }

    // ×: a number is never a box, so there the product of intervals cannot be meant.
    Value expected_box(const Expr& e) {
        if (e.kind == ExprKind::binary && e.op == Tok::star) {
            const Value a = expected_box(*e.kids[0]);
            const Value b = expr(*e.kids[1]);
            if (is_box_product(a.type(), b.type())) return box_product(a, b, e.loc);
        }
        return expr(e);
    }

    // Inlines a function or shape body; `ctx` is what the body may use (a shape's body never runs queries).
    Value inline_body(const Item& it, Scope params, Location call_loc, Context ctx) {
        // A body sees its parameters and the globals; series levels continue from the caller's.
        const int level = frames_.empty() ? 0 : frames_.back().level;
        return in_call_frame(Frame{ctx, {std::move(params)}, level}, &it, call_loc, call_note(it, call_loc),
                             [&] { return expr(*it.body); });
    }

    // ---- expressions ----
    NodeId scalar(const Value& v, Location loc) {
        require_number(v.type(), loc);
        if (v.kind == ValueKind::interval) return g_.constant(v.box[0], num::midpoint(v.box[0]));
        return v.nodes[0];
    }
    NodeId boolean(const Value& v, Location loc) {
        require_condition(v.type(), loc);
        return v.nodes[0];
    }

    Value expr(const Expr& e) {
        switch (e.kind) {
        case ExprKind::number: return number(e);
        case ExprKind::name: return name(e);
        case ExprKind::call: return call(e);
        case ExprKind::unary: return unary(e);
        case ExprKind::binary: return binary(e);
        case ExprKind::if_: return if_expr(e);
        case ExprKind::let: return let(e, [&](const Expr& x) { return expr(x); });
        case ExprKind::tuple: {
            tuple_rule(e.kids.size(), e.loc);
            Value v;
            v.kind = ValueKind::point;
            for (const ExprPtr& k : e.kids) v.nodes.push_back(scalar(expr(*k), k->loc));
            return v;
        }
        case ExprKind::field: {
            const Value p = expr(*e.kids[0]);
            field_rule(p.type(), e.text, e.loc);
            return Value::scalar(p.nodes[e.text == "x" ? 0 : e.text == "y" ? 1 : 2]);
        }
        case ExprKind::interval: {
            const NodeId lo = scalar(expr(*e.kids[0]), e.kids[0]->loc);
            const NodeId hi = scalar(expr(*e.kids[1]), e.kids[1]->loc);
            if (!g_.is_const(lo) || !g_.is_const(hi))
                fail(e.loc, "the bounds of an interval must be constants");
            const Interval v{g_[lo].value.lo, g_[hi].value.hi};
            if (!(v.lo <= v.hi) || std::isnan(v.lo) || std::isnan(v.hi))
                fail(e.loc, "the lower bound of an interval must not exceed its upper bound");
            Value r;
            r.kind = ValueKind::interval;
            r.box = {v};
            return r;
        }
        case ExprKind::series: return series(e);
        case ExprKind::matrix: return matrix(e);
        case ExprKind::lambda: {
            Value v;
            v.closure = std::make_shared<const Closure>(Closure{&e, frames_.back().scopes});
            return v;
        }
        }
        throw InternalError("lower: unknown expression kind");
    }

    Value number(const Expr& e) {
        if (auto known = literals_.find(e.text); known != literals_.end())
            return Value::scalar(known->second);
        const Interval v = num::from_decimal(e.text);
        if (!std::isfinite(v.lo) || !std::isfinite(v.hi))
            fail(e.loc, fmt::format("number '{}' is too large", e.text));
        // A literal keeps its exact value as written (0.1 is 1/10), for exact folding and solving.
        const std::optional<num::Rational> exact = num::Rational::parse_decimal(e.text);
        const NodeId n = exact ? g_.constant(*exact) : g_.constant(v, std::strtod(e.text.c_str(), nullptr));
        literals_.emplace(e.text, n);
        return Value::scalar(n);
    }

    Value name(const Expr& e) {
        if (const Value* v = lookup_local(e.text)) return *v;
        if (auto g = globals_.find(e.text); g != globals_.end()) {
            const Item& it = *g->second;
            if (it.kind == ItemKind::const_) return const_value(it, e.loc);
            Value v;
            (it.kind == ItemKind::shape       ? v.shape
             : it.kind == ItemKind::automaton ? v.automaton
                                              : v.function) = &it;
            return v;
        }
        if (e.text == "identity") return linear_value(front::identity());
        if (e.text == "pi") return Value::scalar(g_.constant(num::pi(), M_PI));
        if (e.text == "e") return Value::scalar(g_.constant(num::e(), M_E));
        if (const Builtin* b = find_builtin(e.text)) {
            Value v;
            v.builtin = b;
            return v;
        }
        throw InternalError(fmt::format("unresolved name '{}'", e.text));
    }

    Value call(const Expr& e) {
        if (const Value* local = lookup_local(e.text)) { // a function parameter
            const Value f = *local;
            if (f.function) return call_item(*f.function, e);
            if (f.shape) return Value::scalar(call_shape(*f.shape, e));
            if (f.builtin) return call_builtin(*f.builtin, e);
            if (f.closure) {
                std::vector<Value> args;
                for (const Arg& a : e.args) args.push_back(expr(*a.value));
                return call_closure(*f.closure, std::move(args), e.loc);
            }
            throw InternalError(fmt::format("'{}' is a value, not a function", e.text));
        }
        if (auto g = globals_.find(e.text); g != globals_.end()) return call_item(*g->second, e);
        const Builtin* b = find_builtin(e.text);
        if (!b) throw InternalError(fmt::format("unresolved function '{}'", e.text));
        return call_builtin(*b, e);
    }

    Value call_closure(const Closure& c, std::vector<Value> args, Location call_loc) {
        Frame f{frames_.back().ctx, c.scopes, frames_.back().level}; // new series go above the caller's
        f.scopes.emplace_back();
        for (std::size_t i = 0; i < args.size(); ++i)
            f.scopes.back().emplace_back(c.lambda->bindings[i].name, std::move(args[i]));
        return in_call_frame(std::move(f), nullptr, call_loc, "in this call of the anonymous function",
                             [&] { return expr(*c.lambda->kids[0]); });
    }

    Value call_item(const Item& it, const Expr& e) {
        if (it.kind == ItemKind::fn) {
            Scope params;
            for (std::size_t i = 0; i < it.params.size(); ++i)
                params.emplace_back(it.params[i].name, expr(*e.args[i].value));
            return inline_body(it, std::move(params), e.loc, frames_.back().ctx);
        }
        if (it.kind == ItemKind::shape) return Value::scalar(call_shape(it, e));
        throw InternalError("call of a non-function");
    }

    Value call_builtin(const Builtin& builtin, const Expr& e) {
        const Builtin* b = &builtin;
        auto arg = [&](std::size_t i) { return scalar(expr(*e.args[i].value), e.args[i].loc); };
        switch (b->kind) {
        case BuiltinKind::unary: return Value::scalar(g_.op(b->op, arg(0)));
        case BuiltinKind::binary: return Value::scalar(g_.op(b->op, arg(0), arg(1)));
        case BuiltinKind::variadic: {
            NodeId acc = arg(0);
            for (std::size_t i = 1; i < e.args.size(); ++i) acc = g_.op(b->op, acc, arg(i));
            return Value::scalar(acc);
        }
        case BuiltinKind::mod: {
            const NodeId x = arg(0), m = arg(1);
            if (g_.is_const(m) && g_[m].value == Interval(1.0)) return Value::scalar(g_.op(Op::Mod1, x));
            // x mod m = m * ((x / m) mod 1)
            return Value::scalar(g_.op(Op::Mul, m, g_.op(Op::Mod1, g_.op(Op::Div, x, m))));
        }
        case BuiltinKind::pow: return Value::scalar(power(arg(0), arg(1)));
        case BuiltinKind::enclose:
        case BuiltinKind::dimension: return query(e, *b);
        case BuiltinKind::transform: {
            std::vector<Entry> args;
            for (const Arg& a : e.args) args.push_back(entry(expr(*a.value), a.loc));
            if (e.text == "translate") return linear_value(translate(args));
            if (e.text == "scale") return linear_value(scale(args));
            if (e.text == "shear") return linear_value(shear(args[0], args[1]));
            // rotate(angle): its cosine and sine folded as constants of the graph.
            const NodeId angle = arg(0);
            return linear_value(rotate(entry(Value::scalar(g_.op(Op::Cos, angle)), e.loc),
                                       entry(Value::scalar(g_.op(Op::Sin, angle)), e.loc)));
        }
        case BuiltinKind::controls: {
            std::vector<std::vector<Entry>> points;
            for (const Arg& a : e.args) {
                std::vector<Entry> p;
                for (NodeId n : expr(*a.value).nodes) p.push_back(entry(Value::scalar(n), a.loc));
                points.push_back(std::move(p));
            }
            return linear_value(LinearValue::matrix(controls(points)));
        }
        case BuiltinKind::primitive: break; // only after `primitive` (automaton_info)
        case BuiltinKind::tabulate: return tabulate(e);
        case BuiltinKind::distance: return distance(e);
        case BuiltinKind::dof: return dof(e);
        case BuiltinKind::kron:
            return linear_value(LinearValue::matrix(
                kronecker(expr(*e.args[0].value).linear->in(0), expr(*e.args[1].value).linear->in(0))));
        }
        throw InternalError("unknown builtin kind");
    }

    // dist(p, A): an External node over p's coordinates (padded with 0 to three), one external function
    // per automaton. The automaton's index is known once automata are lowered (after shapes): run()
    // fills it in.
    Value distance(const Expr& e) {
        const Value pv = expr(*e.args[0].value);
        const Value av = expr(*e.args[1].value);
        if (!av.automaton) throw InternalError("dist: not an automaton");
        std::size_t k = 0;
        while (k < external_items_.size() && external_items_[k] != av.automaton) ++k;
        if (k == external_items_.size()) {
            ExternalUse use;
            use.kind = ExternalUse::Kind::distance;
            use.loc = e.loc;
            use.automaton_name = av.automaton->name;
            m_.externals.push_back(std::move(use));
            external_items_.push_back(av.automaton);
            g_.externals.resize(m_.externals.size());
        }
        if (pv.nodes.empty() || pv.nodes.size() > 3)
            throw InternalError("dist: the point has " + std::to_string(pv.nodes.size()) + " coordinates");
        NodeId c[3];
        for (std::size_t i = 0; i < 3; ++i) c[i] = i < pv.nodes.size() ? pv.nodes[i] : g_.constant(0.0);
        return Value::scalar(g_.external(static_cast<std::int64_t>(k), c[0], c[1], c[2]));
    }

    // The index of an automaton in the module; a located error when it did not compile (its own errors
    // are reported), saying what cannot be had of it.
    std::size_t lowered(const Item* it, Location loc, const char* consequence) {
        const auto found = automaton_index_.find(it);
        if (found == automaton_index_.end())
            fail(loc, fmt::format("'{}' did not compile, so {}", it->name, consequence));
        return found->second;
    }

    // dof(A.cell): a number known once A's constraints are solved (the type checker checked the form).
    Value dof(const Expr& e) {
        const Expr& a = *e.args[0].value;
        const Item* it = globals_.at(a.kids[0]->text);
        const AutomatonInfo& info = m_.automata[lowered(it, e.loc, "its degrees of freedom are unknown")];
        for (std::size_t s = 0; s < info.automaton.states.size(); ++s)
            if (info.automaton.states[s].name == a.text)
                return Value::scalar(g_.constant(num::Rational(info.dof[s])));
        throw InternalError("dof: an unchecked cell");
    }

    // tabulate(A, t): F(t) at t = i / N^p, N the arcs per state, read as p digits (seed 003, sec. 2).
    Value tabulate(const Expr& e) {
        const Value av = expr(*e.args[0].value);
        const std::size_t index = lowered(av.automaton, e.args[0].loc, "it cannot be tabulated");
        const ir::Automaton& a = m_.automata[index].automaton;
        const NodeId tn = scalar(expr(*e.args[1].value), e.args[1].loc);
        const num::Rational* t = g_.exact_value(tn);
        if (!t || t->sign() < 0 || *t >= num::Rational(1))
            fail(e.args[1].loc, "'tabulate' needs an exact t with 0 <= t < 1, such as 3/8");
        const std::size_t base = a.arcs_from(a.initial).size();
        Query q;
        q.loc = e.loc;
        q.kind = Query::Kind::automaton_point;
        q.shape = index;
        num::Rational scaled = *t;
        constexpr int max_digits = 60;
        for (int p = 0; !scaled.is_integer(); ++p) {
            if (p == max_digits || base < 2)
                fail(e.args[1].loc,
                     fmt::format("t = {} is not of the form i / {}^p (p <= {}): '{}' has {} maps per state",
                                 t->to_string(), base, max_digits, av.automaton->name, base));
            scaled *= num::Rational(static_cast<long>(base));
            const num::Rational digit(mpq_class(scaled.numerator() / scaled.denominator()));
            q.address.push_back(static_cast<std::size_t>(digit.to_double()));
            scaled -= digit;
        }
        Value r;
        r.kind = ValueKind::point;
        for (int k = 0; k < a.output_dimension(); ++k) {
            q.component = k;
            m_.queries.push_back(q);
            r.nodes.push_back(g_.var(static_cast<int>(m_.queries.size() - 1)));
        }
        return r;
    }

    // ---- operators and automata ----
    static Value linear_value(LinearValue l) {
        Value v;
        v.linear = std::make_shared<const LinearValue>(std::move(l));
        return v;
    }

    // A constant entry of an operator, exact when it folded exactly.
    Entry entry(const Value& v, Location loc) {
        const NodeId n = scalar(v, loc);
        if (!g_.is_const(n)) fail(loc, "the entries of an operator must be constants");
        Entry x;
        if (const num::Rational* q = g_.exact_value(n)) x.exact = *q;
        x.enclosure = g_[n].value;
        if (!std::isfinite(x.enclosure.lo) || !std::isfinite(x.enclosure.hi))
            fail(loc, "the entries of an operator must be finite");
        return x;
    }

    Value matrix(const Expr& e) {
        std::vector<std::vector<Entry>> rows;
        for (const ExprPtr& row : e.kids) {
            rows.emplace_back();
            for (const ExprPtr& k : row->kids) rows.back().push_back(entry(expr(*k), k->loc));
        }
        return linear_value(LinearValue::matrix(operator_of(rows)));
    }

    Value linear_arithmetic(const Expr& e, const Value& a, const Value& b) {
        const Location la = e.kids[0]->loc, lb = e.kids[1]->loc;
        if (e.op == Tok::star && a.linear && b.linear) return linear_value(compose(*a.linear, *b.linear));
        if (e.op == Tok::star && a.linear && b.kind == ValueKind::point) {
            std::vector<std::vector<Entry>> column;
            for (NodeId n : b.nodes) column.push_back({entry(Value::scalar(n), lb)});
            const ir::Operator p = compose(a.linear->in(0), operator_of(column));
            Value r;
            r.kind = ValueKind::point;
            for (std::size_t i = 0; i < p.rows(); ++i) {
                const num::Interval v = p.enclosure(i, 0);
                r.nodes.push_back(p.exact ? g_.constant((*p.exact)(i, 0)) : g_.constant(v, num::midpoint(v)));
            }
            return r;
        }
        if (e.op == Tok::star) {
            const bool left = !a.linear; // number * matrix or matrix * number
            return linear_value(LinearValue::matrix(
                scale_by(entry(left ? a : b, left ? la : lb), (left ? b : a).linear->in(0))));
        }
        return linear_value(LinearValue::matrix(add(a.linear->in(0), b.linear->in(0), e.op == Tok::minus)));
    }

    // The operator of an arc, as a matrix from the space of `to` into the space of `from`.
    ir::Operator arc_operator(const Value& v, const ir::Space& from) {
        return v.linear->transform ? v.linear->in(from.dimension) : v.linear->in(0);
    }

    static ir::Space space_of(const SpaceDecl& s) {
        return s.barycentric ? ir::Space::barycentric(s.n) : ir::Space::euclidean(s.n);
    }

    // What a state draws, as homogeneous columns of its space (the type checker checked the form).
    ir::Primitive primitive_of(const StateDecl& s, const ir::Space& space) {
        ir::Primitive p;
        const Expr& e = *s.primitive;
        if (e.kind == ExprKind::name) {
            p.kind = ir::Primitive::Kind::shape;
            p.shape = shape_info(*globals_.at(e.text));
            return p;
        }
        p.kind = e.text == "point"     ? ir::Primitive::Kind::points
                 : e.text == "polygon" ? ir::Primitive::Kind::polygon
                                       : ir::Primitive::Kind::polyline;
        const std::size_t n = static_cast<std::size_t>(space.coordinates());
        if (e.args.empty()) { // a barycentric state: its vertices
            p.points = num::Matrix<double>(n, n);
            for (std::size_t i = 0; i < n; ++i) p.points(i, i) = 1;
            return p;
        }
        p.points = num::Matrix<double>(n, e.args.size());
        for (std::size_t c = 0; c < e.args.size(); ++c) {
            const Value v = closed(*e.args[c].value, Context::constant);
            for (std::size_t r = 0; r + 1 < n; ++r)
                p.points(r, c) = num::midpoint(entry(Value::scalar(v.nodes[r]), e.args[c].loc).enclosure);
            p.points(n - 1, c) = 1;
        }
        return p;
    }

    // The checks that need the operators' values (ir/automaton_check.hpp): barycentric columns summing
    // to 1, probabilities, dead ends, unreachable states (a warning), and a proof of contraction.
    // A fif's pieces contract under the metric of seed 001's eq. 2, d((t, X), (t', X')) = |t - t'| +
    // (1 - A) / (2B) |X - X'| (A = max |a_i|, B > max |b_i|, max norm on X): each shear contracts by
    // s = max((1 + A) / 2, C) with C = max |C_i| (max row sum), so s < 1 iff A < 1 and C < 1. Bounds
    // from the operators' enclosures. Returns the proof, or reports the first piece that fails.
    std::optional<std::string> fif_contraction(const AutomatonInfo& info) {
        double a_max = 0, c_max = 0;
        for (std::size_t i = 0; i < info.automaton.arcs.size(); ++i) {
            const ir::Arc& arc = info.automaton.arcs[i];
            if (arc.label.empty()) continue; // the union's identity arcs (an RFIF), taken once
            const auto& m = arc.op.enclosure;
            const double a = num::magnitude(m(0, 0));
            double c = 0;
            for (std::size_t r = 1; r + 1 < m.rows(); ++r) {
                double row = 0;
                for (std::size_t k = 1; k + 1 < m.cols(); ++k) row += num::magnitude(m(r, k));
                c = std::max(c, row);
            }
            if (a >= 1)
                d_.error(
                    info.arc_locs.at(i),
                    fmt::format("'{}': piece {} does not contract (eq. 2): |a| = {:.6g} >= 1, its domain is "
                                "no longer than its range",
                                info.name, arc.label, a));
            else if (c >= 1)
                d_.error(
                    info.arc_locs.at(i),
                    fmt::format("'{}': piece {} does not contract (eq. 2): its vertical scaling has norm "
                                "{:.6g} >= 1",
                                info.name, arc.label, c));
            if (a >= 1 || c >= 1) return std::nullopt;
            a_max = std::max(a_max, a);
            c_max = std::max(c_max, c);
        }
        return fmt::format(
            "contractive under the metric of eq. 2: s = max((1 + A)/2, C) = {:.6g} < 1 (A = max "
            "|a_i| = {:.6g}, C = max |c_i| = {:.6g})",
            std::max((1 + a_max) / 2, c_max), a_max, c_max);
    }

    void check(AutomatonInfo& info, bool cells = false, const FifDecl* fif = nullptr) {
        std::optional<std::string> eq2;
        if (fif && !(eq2 = fif_contraction(info))) throw AlreadyReported{};
        ir::ContractivityResult proof;
        bool failed = false;
        ir::ContractivityOptions options;
        if (eq2) options.max_products = 0; // proven already: no search over paths
        for (const ir::AutomatonProblem& p : ir::check_automaton(info.automaton, options, &proof)) {
            if (eq2 && p.kind == ir::AutomatonProblem::Kind::contractivity) continue;
            // A bcifs reaches its lower cells through boundary operators, which are no arcs.
            if (cells && p.kind == ir::AutomatonProblem::Kind::unreachable) continue;
            const Location loc = p.arc     ? info.arc_locs.at(*p.arc)
                                 : p.state ? info.state_locs.at(*p.state)
                                           : info.loc;
            if (p.severity == ir::AutomatonProblem::Severity::warning) {
                d_.warning(loc, p.message);
                continue;
            }
            d_.error(loc, p.kind == ir::AutomatonProblem::Kind::contractivity
                              ? fmt::format("'{}': {}", info.name, p.message)
                              : p.message);
            failed = true;
        }
        if (failed) throw AlreadyReported{};
        info.contraction = eq2 ? *eq2 : proof.message;
    }

    // ---- bcifs ----
    static bool mentions(const Expr& e, const std::vector<std::string>& names) {
        if (e.kind == ExprKind::name && std::find(names.begin(), names.end(), e.text) != names.end())
            return true;
        for (const ExprPtr& k : e.kids)
            if (k && mentions(*k, names)) return true;
        for (const Arg& a : e.args)
            if (a.value && mentions(*a.value, names)) return true;
        for (const Binding& b : e.bindings)
            if (b.value && mentions(*b.value, names)) return true;
        return false;
    }

    num::Rational exact_entry(const Expr& e) {
        const Entry x = entry(closed(e, Context::constant), e.loc);
        if (!x.exact)
            fail(e.loc, "a parameter's range and value are exact numbers (integers, decimals, fractions)");
        return *x.exact;
    }

    // The tolerance under which a bcifs with inexact entries solves its constraints (linear_system.hpp).
    static constexpr double inexact_tolerance = 1e-9;

    // A known entry of a bcifs: exact when it can be; else the nearest double, and the system is solved
    // in floating point with a tolerance (the first such entry is named in `frac solve`).
    num::Rational system_entry(const Expr& e, BcifsSystem& sys) {
        const Entry x = entry(closed(e, Context::constant), e.loc);
        if (x.exact) return *x.exact;
        return inexact(num::midpoint(x.enclosure), e.loc, sys);
    }
    num::Rational inexact(double nearest, Location loc, BcifsSystem& sys) {
        if (!std::isfinite(nearest)) fail(loc, "an entry of a bcifs is a finite number");
        if (!sys.tolerance) {
            sys.tolerance = inexact_tolerance;
            sys.inexact_at = loc;
        }
        return num::Rational::from_double(nearest);
    }

    // An entry as an affine form over the parameters (variable k is sys.params[k]).
    num::AffineForm affine_entry(const Expr& e, BcifsSystem& sys) {
        const std::vector<std::string>& params = sys.params;
        num::AffineForm f;
        if (!mentions(e, params)) {
            f.constant = system_entry(e, sys);
            return f;
        }
        if (e.kind == ExprKind::name)
            return num::AffineForm::variable(
                static_cast<std::size_t>(std::find(params.begin(), params.end(), e.text) - params.begin()));
        if (e.kind == ExprKind::unary && (e.op == Tok::minus || e.op == Tok::plus))
            return affine_entry(*e.kids[0], sys) * num::Rational(e.op == Tok::minus ? -1 : 1);
        if (e.kind == ExprKind::binary) {
            const num::AffineForm a = affine_entry(*e.kids[0], sys), b = affine_entry(*e.kids[1], sys);
            if (e.op == Tok::plus) return a + b;
            if (e.op == Tok::minus) return a - b;
            if (e.op == Tok::star && a.is_constant()) return b * a.constant;
            if (e.op == Tok::star && b.is_constant()) return a * b.constant;
            if (e.op == Tok::slash && b.is_constant() && !b.constant.is_zero())
                return a * (num::Rational(1) / b.constant);
        }
        fail(e.loc, "an entry must be affine in the parameters: a sum of parameters times numbers");
    }

    // The solved operator `d.source`.`d.source_cell`.`d.name` of a cell taken from another bcifs
    // (cell_import.hpp), lowered first when it comes later in the source.
    num::Matrix<num::Rational> taken_operator(const OperatorDecl& d, const Item& taker) {
        const Item* source = globals_.at(d.source);
        if (!typed_.failed.count(source)) guarded([&] { automaton_info(*source); });
        const auto index = automaton_index_.find(source);
        if (index == automaton_index_.end())
            fail(d.loc,
                 fmt::format("'{}' takes a cell from '{}', which did not compile", taker.name, d.source));
        const ir::Automaton& a = m_.automata[index->second].automaton;
        for (const std::vector<ir::Arc>* arcs : {&a.arcs, &a.embeddings})
            for (const ir::Arc& arc : *arcs)
                if (a.states[arc.from].name == d.source_cell && arc.label == d.name && arc.op.exact)
                    return *arc.op.exact;
        throw InternalError("a taken operator missing from its lowered source");
    }

    // The layout of every triangle topology whose boundary operators it generated (so its corners are
    // the control points p(0, 0), p(k-1, 0), p(0, k-1)), for the tessellation.
    static void triangle_patches(const BcifsDecl& b, ir::Automaton& a,
                                 const std::function<std::size_t(const std::string&)>& index) {
        for (const TopologyDecl& t : b.topologies) {
            if (t.kind != "triangle") continue;
            const bool generated =
                std::all_of(b.operators.begin(), b.operators.end(), [&](const OperatorDecl& o) {
                    return o.cell != t.cell || !o.boundary || o.generated;
                });
            if (!generated) continue;
            ir::TrianglePatch p;
            p.state = index(t.cell);
            p.n = t.n;
            const std::size_t m = static_cast<std::size_t>(a.states[p.state].space.coordinates());
            std::size_t k = 1;
            while (k * (k + 1) / 2 < m) ++k;
            p.corners = {0, k - 1, m - 1};
            const std::size_t ups = static_cast<std::size_t>(t.n * (t.n + 1) / 2);
            for (std::size_t i = 0; i < static_cast<std::size_t>(t.n * t.n); ++i)
                for (std::size_t j = 0; j < a.arcs.size(); ++j)
                    if (a.arcs[j].from == p.state && a.arcs[j].label == fmt::format("T{}", i))
                        (i < ups ? p.up : p.down).push_back(j);
            if (p.up.size() + p.down.size() == static_cast<std::size_t>(t.n * t.n))
                a.triangle_patches.push_back(p);
        }
    }

    // The faces of every cube topology, for the meshing of solids: its boundary operators B0 ... B5 from
    // the face cell, generated or written.
    static void volume_cells(const BcifsDecl& b, ir::Automaton& a,
                             const std::function<std::size_t(const std::string&)>& index) {
        for (const TopologyDecl& t : b.topologies) {
            if (t.kind != "cube") continue;
            ir::VolumeCell v;
            v.state = index(t.cell);
            std::size_t found = 0;
            for (std::size_t face = 0; face < v.faces.size(); ++face)
                for (std::size_t j = 0; j < a.embeddings.size(); ++j)
                    if (a.embeddings[j].from == v.state &&
                        a.embeddings[j].label == fmt::format("B{}", face)) {
                        v.faces[face] = j;
                        ++found;
                        break;
                    }
            if (found == v.faces.size()) a.volume_cells.push_back(v);
        }
    }

    // The constraint system of a bcifs, from its declaration (the type checker checked every size).
    BcifsSystem bcifs_system(const Item& it, const std::function<std::size_t(const std::string&)>& index) {
        const AutomatonDecl& decl = *it.automaton;
        const BcifsDecl& b = *decl.bcifs;
        BcifsSystem sys;
        sys.name = it.name;
        sys.loc = it.loc;
        for (const ParamDecl& p : b.params) sys.params.push_back(p.name);
        for (const StateDecl& s : decl.states) {
            sys.cells.push_back(s.name);
            sys.cell_order.push_back(space_of(s.space).coordinates());
        }
        std::map<std::pair<std::string, std::string>, std::size_t> op_index;
        for (const OperatorDecl& d : b.operators) {
            BcifsSystem::Operator o;
            o.cell = d.cell;
            o.name = d.name;
            o.loc = d.loc;
            o.cell_index = index(d.cell);
            const ir::Space from = space_of(decl.states[o.cell_index].space),
                            to = space_of(decl.states[index(d.target)].space);
            o.rows = static_cast<std::size_t>(from.coordinates());
            o.cols = static_cast<std::size_t>(to.coordinates());
            o.barycentric =
                from.kind == ir::Space::Kind::barycentric && to.kind == ir::Space::Kind::barycentric;
            o.entries.assign(o.rows * o.cols, std::nullopt);
            if (!d.source.empty()) {
                const num::Matrix<num::Rational> m = taken_operator(d, it);
                for (std::size_t r = 0; r < o.rows; ++r)
                    for (std::size_t c = 0; c < o.cols; ++c)
                        o.entries[r * o.cols + c] = num::AffineForm{m(r, c), {}};
            } else if (d.value && d.value->kind == ExprKind::matrix) {
                for (std::size_t r = 0; r < o.rows; ++r)
                    for (std::size_t c = 0; c < o.cols; ++c) {
                        const Expr& x = *d.value->kids[r]->kids[c];
                        if (!is_unknown(x)) o.entries[r * o.cols + c] = affine_entry(x, sys);
                    }
            } else if (d.value) {
                const ir::Operator m = closed(*d.value, Context::constant).linear->in(0);
                for (std::size_t r = 0; r < o.rows; ++r)
                    for (std::size_t c = 0; c < o.cols; ++c) {
                        num::AffineForm f;
                        f.constant = m.exact ? (*m.exact)(r, c) : inexact(m.nearest(r, c), d.value->loc, sys);
                        o.entries[r * o.cols + c] = f;
                    }
            }
            op_index[{d.cell, d.name}] = sys.operators.size();
            sys.operators.push_back(std::move(o));
        }
        for (const ConstraintDecl& c : b.constraints) {
            BcifsSystem::Constraint k;
            k.loc = c.loc;
            k.text = print_product(c.left) + " == " + print_product(c.right);
            for (int s = 0; s < 2; ++s)
                for (const FactorDecl& f : s == 0 ? c.left : c.right) {
                    BcifsSystem::Factor x;
                    if (f.constant) {
                        const ir::Operator m = closed(*f.constant, Context::constant).linear->in(0);
                        x.constant = num::Matrix<num::Rational>(m.rows(), m.cols());
                        for (std::size_t r = 0; r < m.rows(); ++r)
                            for (std::size_t cc = 0; cc < m.cols(); ++cc)
                                x.constant(r, cc) =
                                    m.exact ? (*m.exact)(r, cc) : inexact(m.nearest(r, cc), f.loc, sys);
                    } else {
                        x.op = op_index.at({f.cell, f.name});
                    }
                    (s == 0 ? k.left : k.right).push_back(std::move(x));
                }
            sys.constraints.push_back(std::move(k));
        }
        for (const FixDecl& f : b.fixes) {
            BcifsSystem::Fix x;
            x.op = op_index.at({f.cell, f.name});
            x.row = static_cast<std::size_t>(f.row);
            x.col = static_cast<std::size_t>(f.col);
            x.value = affine_entry(*f.value, sys);
            x.loc = f.loc;
            sys.fixes.push_back(std::move(x));
        }
        return sys;
    }

    // Solves the constraints, then gives the free entries and parameters values: a parameter its own,
    // or the middle of its range; the free entries the most uniform operators (bcifs.hpp), then, while
    // the compiler cannot prove the system contractive, those values moved by small steps drawn from a
    // fixed seed (the same on every machine). With --seed N the free entries are drawn from N instead:
    // the most uniform values moved by up to 1/4 (multiples of 1/64), drawn again until the system is
    // proven contractive — a random geometry (seed 002 Fig. 11 right) that the seed reproduces.
    void bcifs_info(const Item& it, AutomatonInfo& info,
                    const std::function<std::size_t(const std::string&)>& index) {
        const AutomatonDecl& decl = *it.automaton;
        const BcifsDecl& b = *decl.bcifs;
        const BcifsSystem sys = bcifs_system(it, index);
        const std::optional<BcifsSolution> sol = solve_bcifs(sys, d_, limits_.max_bcifs_dense);
        if (!sol) throw AlreadyReported{};
        std::vector<num::Rational> values(sol->variable_names.size());
        std::vector<std::size_t> chosen; // the variables the compiler gave values
        for (std::size_t p = 0; p < b.params.size(); ++p) {
            const ParamDecl& d = b.params[p];
            const num::Rational lo = d.lo ? exact_entry(*d.lo) : num::Rational(0);
            const num::Rational hi = d.hi ? exact_entry(*d.hi) : num::Rational(1);
            if (hi < lo) fail(d.loc, fmt::format("parameter '{}' has an empty range", d.name));
            if (!d.value) {
                values[p] = (lo + hi) / num::Rational(2);
                chosen.push_back(p);
                continue;
            }
            values[p] = exact_entry(*d.value);
            if (values[p] < lo || values[p] > hi)
                fail(d.value->loc, fmt::format("'{}' = {} is outside its range [{}, {}]", d.name,
                                               values[p].to_string(), lo.to_string(), hi.to_string()));
        }
        const std::vector<num::Rational> uniform = most_uniform_values(sys, *sol, values);
        for (std::size_t v : sol->free) chosen.push_back(v);
        // The command line's seed, else the model's own (seed N;), else none: the most uniform values.
        const std::optional<std::uint64_t> seed = free_entry_seed_ ? free_entry_seed_ : b.seed;
        std::uint64_t state = seed.value_or(0) * 0x2545f4914f6cdd1dull + 1;
        const auto next = [&] { // splitmix64
            std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
            z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
            z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
            return z ^ (z >> 31);
        };
        ir::Automaton& a = info.automaton;
        a.initial = index(initial_state(decl).name);
        const bool seeded = seed && !sol->free.empty();
        const int attempts = sol->free.empty() ? 1 : seeded ? 64 : 8;
        bool contracts = false;
        // The proofs' work, shared by the attempts (Limits::max_bcifs_proof_work): each attempt gets a
        // whole proof's budget, or none is made.
        double proof_work_left = static_cast<double>(limits_.max_bcifs_proof_work);
        const double per_proof = std::min(ir::ContractivityOptions{}.max_work, proof_work_left);
        int tried = 0;              // choices whose proof ran
        bool out_of_budget = false; // the limit stopped the search
        for (int attempt = 0; attempt < attempts && !contracts; ++attempt) {
            if (attempts > 1 && proof_work_left < per_proof) {
                out_of_budget = true;
                break;
            }
            for (std::size_t k = 0; k < sol->free.size(); ++k)
                values[sol->free[k]] =
                    uniform[k] + (seeded         ? num::Rational(static_cast<long>(next() % 33) - 16, 64)
                                  : attempt == 0 ? num::Rational(0)
                                                 : num::Rational(static_cast<long>(next() % 9) - 4, 64));
            a.arcs.clear();
            a.embeddings.clear();
            info.arc_locs.clear();
            for (std::size_t j = 0; j < sys.operators.size(); ++j) {
                const auto& o = sys.operators[j];
                num::Matrix<num::Rational> m(o.rows, o.cols);
                for (std::size_t r = 0; r < o.rows; ++r)
                    for (std::size_t c = 0; c < o.cols; ++c) {
                        const num::AffineForm& f = sol->entries[j][r * o.cols + c];
                        num::Rational x = f.constant;
                        for (const auto& [v, coef] : f.terms) x += coef * values[v];
                        m(r, c) = x;
                    }
                ir::Arc arc;
                arc.from = o.cell_index;
                arc.to = index(b.operators[j].target);
                arc.label = o.name;
                arc.op = ir::Operator::from_exact(m);
                if (b.operators[j].boundary) {
                    a.embeddings.push_back(std::move(arc));
                } else {
                    a.arcs.push_back(std::move(arc));
                    info.arc_locs.push_back(o.loc);
                }
            }
            if (attempts == 1) {
                contracts = true;
                continue;
            }
            ir::ContractivityOptions proof;
            proof.max_work = per_proof;
            const ir::ContractivityResult r = ir::prove_contractive(a, proof);
            // A budget too small for a single product proves nothing: not a try.
            if (!r.proven && r.work == 0) {
                out_of_budget = true;
                break;
            }
            ++tried;
            contracts = r.proven;
            proof_work_left -= r.work;
        }
        triangle_patches(b, a, index);
        volume_cells(b, a, index);
        if (!contracts) {
            if (out_of_budget)
                fail(it.loc,
                     fmt::format("the limit of {} steps of contraction proofs stopped the search for "
                                 "values of the {} free entries of '{}' that make it contractive, "
                                 "after {} of {} {}{}; fix some of them (frac solve shows them)",
                                 limits_.max_bcifs_proof_work, sol->free.size(), it.name, tried, attempts,
                                 seeded ? "draws" : "choices", raised_by("FRAC_MAX_BCIFS_PROOF_WORK")));
            fail(it.loc,
                 seeded ? fmt::format("no values drawn from seed {} for the {} free entries of '{}' make it "
                                      "contractive ({} draws); try another seed, or fix some of them (frac "
                                      "solve shows them)",
                                      *seed, sol->free.size(), it.name, attempts)
                        : fmt::format("the compiler found no values of the {} free entries of '{}' that make "
                                      "it contractive (the most uniform operators and {} nearby); fix some "
                                      "of them (frac solve shows them)",
                                      sol->free.size(), it.name, attempts - 1));
        }
        info.solution = print_bcifs_solution(sys, *sol);
        std::vector<std::string> given;
        for (std::size_t p = 0; p < b.params.size(); ++p)
            if (b.params[p].value)
                given.push_back(fmt::format("{} = {}", b.params[p].name, values[p].to_string()));
        if (!given.empty()) info.solution += fmt::format("  parameters: {}\n", fmt::join(given, ", "));
        if (!chosen.empty()) {
            std::vector<std::string> given;
            for (std::size_t v : chosen)
                given.push_back(fmt::format("{} = {}", sol->variable_names[v], values[v].to_string()));
            info.solution +=
                fmt::format("  values chosen{}: {}\n", seeded ? fmt::format(" (seed {})", *seed) : "",
                            fmt::join(given, ", "));
        }
        info.dof = sol->dof;
    }

    // A fif's points, evaluated before its shears (which divide by differences of their t): finite, t
    // strictly increasing.
    void fif_points(const FifDecl& f, AutomatonInfo& info) {
        for (const ExprPtr& point : f.values) {
            const Value v = closed(*point, Context::constant);
            std::vector<double> coordinates;
            for (const NodeId node : v.nodes) {
                const Entry x = entry(Value::scalar(node), point->loc);
                if (!std::isfinite(x.enclosure.lo) || !std::isfinite(x.enclosure.hi))
                    fail(point->loc, "a fif's point has coordinates that are finite numbers");
                coordinates.push_back(num::midpoint(x.enclosure));
            }
            if (!info.fif_points.empty() && !(coordinates[0] > info.fif_points.back()[0]))
                fail(point->loc, fmt::format("the points of a fif have increasing t: {} follows {}",
                                             coordinates[0], info.fif_points.back()[0]));
            info.fif_points.push_back(std::move(coordinates));
        }
    }

    void automaton_info(const Item& it) {
        if (!automata_lowered_.insert(&it).second) return; // taken cells lower their source first
        const AutomatonDecl& decl = *it.automaton;
        AutomatonInfo info;
        info.name = it.name;
        info.loc = it.loc;
        ir::Automaton& a = info.automaton;
        a.name = it.name;
        const auto index = [&](const std::string& state) {
            for (std::size_t i = 0; i < decl.states.size(); ++i)
                if (decl.states[i].name == state) return i;
            throw InternalError("an unresolved state");
        };
        for (const StateDecl& s : decl.states) {
            ir::State st;
            st.name = s.name;
            st.space = space_of(s.space);
            if (s.primitive) st.primitive = primitive_of(s, st.space);
            a.states.push_back(std::move(st));
            info.state_locs.push_back(s.loc);
        }
        if (decl.bcifs) bcifs_info(it, info, index);
        if (decl.fif) fif_points(*decl.fif, info);
        for (const ArcDecl& d : decl.arcs) {
            ir::Arc arc;
            arc.from = index(d.from);
            arc.to = index(d.to);
            arc.label = d.label;
            arc.op = arc_operator(closed(*d.op, Context::constant), a.states[arc.from].space);
            if (d.probability) {
                const Entry p = entry(closed(*d.probability, Context::constant), d.probability->loc);
                if (!(p.enclosure.lo >= 0 && p.enclosure.hi <= 1))
                    fail(d.probability->loc, "a probability is a number from 0 to 1");
                arc.probability = p.exact ? p.exact->to_double() : num::midpoint(p.enclosure);
            }
            a.arcs.push_back(std::move(arc));
            info.arc_locs.push_back(d.loc);
        }
        a.initial = index(initial_state(decl).name);
        if (decl.projection) a.projection = closed(*decl.projection, Context::constant).linear->in(0);
        check(info, decl.bcifs != nullptr, decl.fif.get());
        m_.automata.push_back(std::move(info));
        automaton_index_[&it] = m_.automata.size() - 1;
    }

    NodeId call_shape(const Item& it, const Expr& e) {
        shape_info(it);
        std::vector<Value> coords; // the type checker checked their number
        if (e.args.size() == 1) {
            for (NodeId n : expr(*e.args[0].value).nodes) coords.push_back(Value::scalar(n));
        } else {
            for (const Arg& a : e.args) coords.push_back(Value::scalar(scalar(expr(*a.value), a.loc)));
        }
        return shape_body(it, coords, e.loc);
    }

    Value query(const Expr& e, const Builtin& b) {
        // The type checker checked where queries are used and the types of their arguments.
        const Value s = expr(*e.args[0].value);
        Query q;
        q.loc = e.loc;
        if (s.automaton) {
            q.kind = Query::Kind::automaton_dimension;
            q.shape = lowered(s.automaton, e.args[0].loc, "it has no dimension");
            m_.queries.push_back(q);
            return Value::scalar(g_.var(static_cast<int>(m_.queries.size() - 1)));
        }
        q.shape = shape_info(*s.shape);
        const ShapeInfo& info = m_.shapes[q.shape];
        if (b.kind == BuiltinKind::enclose) {
            q.kind = Query::Kind::enclose;
            q.box = expected_box(*e.args[1].value).box;
        } else {
            q.kind = Query::Kind::dimension;
            q.box = info.box;
            for (std::size_t i = 1; i < e.args.size(); ++i) {
                const Arg& a = e.args[i];
                std::int64_t v = 0;
                const NodeId n = scalar(expr(*a.value), a.loc);
                if (!g_.const_integer(n, v))
                    fail(a.loc, fmt::format("'{}:' needs an integer constant", a.name));
                (a.name == "from" ? q.from : a.name == "to" ? q.to : q.split) = static_cast<int>(v);
            }
            if (q.from < 0 || q.to <= q.from) fail(e.loc, "'dimension' needs 0 <= from < to");
        }
        m_.queries.push_back(q);
        return Value::scalar(g_.var(static_cast<int>(m_.queries.size() - 1)));
    }

    NodeId power(NodeId base, NodeId exponent) {
        std::int64_t k = 0;
        if (g_.const_integer(exponent, k)) {
            if (k == 1) return base;
            if (k == 2) return g_.op(Op::Sqr, base);
            return g_.op(Op::PowI, base, ir::no_node, ir::no_node, k);
        }
        return g_.op(Op::Pow, base, exponent);
    }

    Value unary(const Expr& e) {
        const Value v = expr(*e.kids[0]);
        const Type t = unary_rule(e.op, v.type(), e.kids[0]->loc);
        if (e.op == Tok::kw_not) return Value::boolean(g_.op(Op::Not, v.nodes[0]));
        if (e.op == Tok::plus)
            return t.kind == Type::Kind::point ? v : Value::scalar(scalar(v, e.kids[0]->loc));
        if (t.kind == Type::Kind::point) {
            Value r = v;
            for (NodeId& n : r.nodes) n = g_.op(Op::Neg, n);
            return r;
        }
        return Value::scalar(g_.op(Op::Neg, scalar(v, e.kids[0]->loc)));
    }

    Value binary(const Expr& e) {
        const Location la = e.kids[0]->loc, lb = e.kids[1]->loc;
        const Value a = expr(*e.kids[0]);
        const Value b = expr(*e.kids[1]);
        binary_rule(e.op, a.type(), b.type(), e.loc, la, lb);
        switch (e.op) {
        case Tok::kw_and: return Value::boolean(g_.op(Op::And, boolean(a, la), boolean(b, lb)));
        case Tok::kw_or: return Value::boolean(g_.op(Op::Or, boolean(a, la), boolean(b, lb)));
        case Tok::lt: return Value::boolean(g_.op(Op::Lt, scalar(a, la), scalar(b, lb)));
        case Tok::le: return Value::boolean(g_.op(Op::Le, scalar(a, la), scalar(b, lb)));
        case Tok::gt: return Value::boolean(g_.op(Op::Gt, scalar(a, la), scalar(b, lb)));
        case Tok::ge: return Value::boolean(g_.op(Op::Ge, scalar(a, la), scalar(b, lb)));
        case Tok::eq: return Value::boolean(g_.op(Op::Eq, scalar(a, la), scalar(b, lb)));
        case Tok::ne: return Value::boolean(g_.op(Op::Ne, scalar(a, la), scalar(b, lb)));
        case Tok::amp: return Value::scalar(g_.op(Op::Max, scalar(a, la), scalar(b, lb)));
        case Tok::bar: return Value::scalar(g_.op(Op::Min, scalar(a, la), scalar(b, lb)));
        case Tok::caret: return Value::scalar(power(scalar(a, la), scalar(b, lb)));
        case Tok::times: return box_product(a, b, e.loc);
        case Tok::plus:
        case Tok::minus:
        case Tok::star:
        case Tok::slash: return arithmetic(e, a, b);
        default: break;
        }
        throw InternalError("unknown binary operator");
    }

    Value arithmetic(const Expr& e, const Value& a, const Value& b) {
        const Op op = e.op == Tok::plus    ? Op::Add
                      : e.op == Tok::minus ? Op::Sub
                      : e.op == Tok::star  ? Op::Mul
                                           : Op::Div;
        const Location la = e.kids[0]->loc, lb = e.kids[1]->loc;
        if (a.linear || b.linear) return linear_arithmetic(e, a, b);
        const bool pa = a.kind == ValueKind::point, pb = b.kind == ValueKind::point;
        if (!pa && !pb) return Value::scalar(g_.op(op, scalar(a, la), scalar(b, lb)));
        Value r;
        r.kind = ValueKind::point;
        if (pa && pb) { // the typing rule allows + and - of points of one dimension
            for (std::size_t i = 0; i < a.nodes.size(); ++i)
                r.nodes.push_back(g_.op(op, a.nodes[i], b.nodes[i]));
            return r;
        }
        const Value& p = pa ? a : b;
        const NodeId s = pa ? scalar(b, lb) : scalar(a, la);
        for (NodeId n : p.nodes) r.nodes.push_back(pa ? g_.op(op, n, s) : g_.op(op, s, n));
        return r;
    }

    Value if_expr(const Expr& e) {
        const NodeId c = boolean(expr(*e.kids[0]), e.kids[0]->loc);
        const Value a = expr(*e.kids[1]);
        const Value b = expr(*e.kids[2]);
        if_rule(a.type(), b.type(), e.kids[1]->loc, e.kids[2]->loc);
        Value r = a;
        for (std::size_t i = 0; i < a.nodes.size(); ++i)
            r.nodes[i] = g_.op(Op::Select, c, a.nodes[i], b.nodes[i]);
        return r;
    }

    // The radius of `escape R`: a positive constant, on an infinite min or max series.
    NodeId escape_radius_of(const Expr& e, bool infinite) {
        const Expr& r = *e.kids[4];
        if (!infinite)
            fail(e.series->escape_loc,
                 "an escape certificate needs an infinite series (a finite one has no tail)");
        if (e.text == "sum")
            fail(e.series->escape_loc, "an escape certificate applies to min and max series, not to a sum");
        const NodeId radius = scalar(expr(r), r.loc);
        if (!g_.is_const(radius) || !(g_[radius].value.lo >= 0) || !std::isfinite(g_[radius].value.hi))
            fail(r.loc, "the escape radius must be a finite constant >= 0");
        return radius;
    }
    ir::OrbitEscape prove_escape(const Expr& e, Op kind, NodeId body, const std::vector<NodeId>& orbit,
                                 const ir::SeriesData& data, NodeId radius) {
        const std::vector<NodeId> map(orbit.begin() + data.state_count, orbit.end());
        std::string why;
        std::optional<ir::OrbitEscape> escape;
        {
            num::UpwardRounding up;
            escape = prove_orbit_escape(g_, body, map, data.level, kind, g_[radius].value, why);
        }
        if (!escape) fail(e.series->escape_loc, "cannot prove this escape certificate: " + why);
        if (!(escape->slope > 0))
            // The bound (s (|q| - r) + d) * scale is then never positive (negative for a max): it proves
            // no cell outside the shape, and covers run every term of the orbit in vain.
            d_.warning(
                e.series->escape_loc,
                fmt::format("this escape certificate cannot make a term {}: the term is bounded {} on "
                            "the orbit point only by s |q| + d with s = 0; write it so that it grows "
                            "with the norm of the orbit point (for example through sqrt(p.x^2 + p.y^2))",
                            kind == Op::SeriesMin ? "positive" : "negative",
                            kind == Op::SeriesMin ? "below" : "above"));
        return *escape;
    }

    Value series(const Expr& e) {
        const std::size_t frame = frames_.size() - 1; // frames_ grows while the body is lowered
        auto integer = [&](const Expr& x, const char* what) {
            const NodeId n = scalar(expr(x), x.loc);
            std::int64_t v = 0;
            if (!g_.const_integer(n, v))
                fail(x.loc, fmt::format("the {} of a series index must be an integer constant", what));
            return v;
        };
        ir::SeriesData data;
        data.start = integer(*e.kids[0], "start");
        const bool infinite = e.kids[1] == nullptr;
        if (!infinite) {
            data.end = integer(*e.kids[1], "end");
            if (data.end < data.start)
                fail(e.loc, fmt::format("empty index range {}..{}", data.start, data.end));
            if (data.end - data.start + 1 > limits_.max_finite_terms)
                fail(e.loc,
                     fmt::format(
                         "this series has {} terms, over the limit of {}{}: use an infinite series, whose "
                         "tail is bounded",
                         data.end - data.start + 1, limits_.max_finite_terms,
                         raised_by("FRAC_MAX_SERIES_TERMS")));
        } else if (data.start < 0) {
            fail(e.kids[0]->loc, "an infinite series must start at an index >= 0");
        }
        if (frames_[frame].level + 1 > limits_.max_series_nesting)
            fail(e.loc, fmt::format("series nested deeper than the limit of {}{}", limits_.max_series_nesting,
                                    raised_by("FRAC_MAX_SERIES_NESTING")));
        data.level = ++frames_[frame].level;
        frames_[frame].scopes.emplace_back();
        frames_[frame].scopes.back().emplace_back(e.series->var, Value::scalar(g_.index(data.level)));
        struct Restore {
            std::vector<Frame>& frames;
            std::size_t frame;
            ~Restore() {
                frames[frame].scopes.pop_back();
                --frames[frame].level;
            }
        } restore{frames_, frame};
        std::vector<NodeId> orbit; // initial point, then the map applied to the state
        NodeId escape_radius = ir::no_node;
        if (!e.series->orbit_var.empty()) {
            // The initial point is outside the series (the index is not visible to it).
            frames_[frame].scopes.pop_back();
            const Value init = expr(*e.kids[3]);
            if (e.kids.size() > 4) escape_radius = escape_radius_of(e, infinite);
            frames_[frame].scopes.emplace_back();
            frames_[frame].scopes.back().emplace_back(e.series->var, Value::scalar(g_.index(data.level)));
            data.state_count = static_cast<int>(init.nodes.size());
            Value state;
            state.kind = ValueKind::point;
            for (int c = 0; c < data.state_count; ++c) state.nodes.push_back(g_.state(data.level, c));
            const Value* local_map = lookup_local(e.series->orbit_map); // a function parameter (type checked)
            Value next;
            if (local_map && local_map->closure) {
                next = call_closure(*local_map->closure, {state}, e.series->orbit_loc);
            } else {
                const Item& map = local_map ? *local_map->function : *globals_.at(e.series->orbit_map);
                next =
                    inline_body(map, {{map.params[0].name, state}}, e.series->orbit_loc, frames_.back().ctx);
            }
            frames_[frame].scopes.back().emplace_back(e.series->orbit_var, state);
            orbit = init.nodes.vector();
            orbit.insert(orbit.end(), next.nodes.begin(), next.nodes.end());
        }
        const NodeId body = scalar(expr(*e.kids[2]), e.kids[2]->loc);
        const Op kind = e.text == "sum" ? Op::SeriesSum : e.text == "min" ? Op::SeriesMin : Op::SeriesMax;
        if (!infinite) return Value::scalar(g_.series(kind, data, body, ir::no_node, ir::no_node, orbit));
        std::string why;
        std::optional<TermBound> bound;
        {
            num::UpwardRounding up;
            bound = bound_series_term(g_, body, data.level, kind, why);
        }
        if (!bound) fail(e.loc, "cannot bound this infinite series: " + why);
        data.gamma = bound->gamma;
        data.one_sided = kind == Op::SeriesMin ? !bound->no_upper.empty()
                                               : kind == Op::SeriesMax && !bound->no_lower.empty();
        if (escape_radius != ir::no_node)
            data.escape = prove_escape(e, kind, body, orbit, data, escape_radius);
        return Value::scalar(g_.series(kind, data, body, bound->a, bound->b, orbit));
    }

    static constexpr std::size_t in_progress = static_cast<std::size_t>(-1);
    static constexpr std::size_t failed = static_cast<std::size_t>(-2);
    const Program& p_;
    const TypedProgram& typed_;
    const SourceManager& sm_;
    Limits limits_;
    Module& m_;
    ir::Graph& g_;
    Diagnostics& d_;
    const ConstantValues* constants_ = nullptr;
    std::unordered_map<std::string, const Item*> globals_;
    std::unordered_map<const Item*, std::size_t> shape_index_;
    std::unordered_map<const Item*, std::size_t> automaton_index_;
    std::unordered_set<const Item*> automata_lowered_; // attempted, whether or not they compiled
    std::optional<std::uint64_t> free_entry_seed_;
    std::vector<const Item*> external_items_; // the automaton of each of m_.externals
    std::unordered_map<const Item*, std::optional<Value>> consts_;
    std::unordered_set<const Item*> failed_consts_;
    // The node of each literal's text (the syntax tree outlives the lowering): a model repeats its
    // literals, each parsed once.
    std::unordered_map<std::string_view, NodeId> literals_;
};

} // namespace

void lower(const Program& program, const TypedProgram& typed, const SourceManager& sources,
           const Limits& limits, Module& out, Diagnostics& diags, const ConstantValues* constants,
           std::optional<std::uint64_t> free_entry_seed) {
    Lowering(program, typed, sources, limits, out, diags, constants, free_entry_seed).run();
}

void evaluate_constants(const Program& program, const TypedProgram& typed, const SourceManager& sources,
                        const Limits& limits, ConstantValues& out, Diagnostics& diags) {
    Module scratch; // the constants fold in a graph of their own
    Lowering(program, typed, sources, limits, scratch, diags).evaluate_constants(out);
}

std::vector<NodeId> lower_point_map(const Program& program, const TypedProgram& typed,
                                    const SourceManager& sources, const Limits& limits, Module& out,
                                    const Item& map, int dimension) {
    Diagnostics unused; // errors are thrown as CompileError
    Lowering lowering(program, typed, sources, limits, out, unused);
    lowering.declare();
    return lowering.point_map(map, dimension);
}

} // namespace frac::front
