#include "frontend/types.hpp"

#include <fmt/format.h>

namespace frac::front {

namespace {

[[noreturn]] void fail(Location loc, const std::string& message) {
    throw CompileError(loc, message);
}

bool is_number(Type t) {
    return t.kind == Type::Kind::number || t.kind == Type::Kind::interval;
}

bool is_linear(Type t) {
    return t.kind == Type::Kind::matrix || t.kind == Type::Kind::transform;
}

// The product of two matrices or transforms (composition, right to left).
Type compose_rule(Type a, Type b, Location e) {
    using K = Type::Kind;
    if (a.kind == K::transform && b.kind == K::transform) {
        if (a.size && b.size && a.size != b.size)
            fail(e, fmt::format("transforms of R{} and R{} do not compose", a.size, b.size));
        return Type::transform(a.size ? a.size : b.size);
    }
    // A transform of R^d is a (d + 1) × (d + 1) matrix in homogeneous coordinates.
    const auto as_matrix = [](Type t, int n) {
        return t.kind == K::matrix ? t : Type::matrix(t.size ? t.size + 1 : n, t.size ? t.size + 1 : n);
    };
    const Type ma = as_matrix(a, b.kind == K::matrix ? b.rows : 0);
    const Type mb = as_matrix(b, a.kind == K::matrix ? a.cols : 0);
    if (ma.cols != mb.rows)
        fail(e, fmt::format("the product of {} and {} is undefined: {} columns against {} rows", type_name(a),
                            type_name(b), ma.cols, mb.rows));
    return Type::matrix(ma.rows, mb.cols);
}

Type arithmetic_rule(Tok op, Type a, Type b, Location e, Location la, Location lb) {
    using K = Type::Kind;
    const bool pa = a.kind == K::point, pb = b.kind == K::point;
    if (is_linear(a) || is_linear(b)) {
        if (op == Tok::star) {
            if (is_linear(a) && is_linear(b)) return compose_rule(a, b, e);
            if (a.kind == K::matrix && is_number(b)) return a;
            if (b.kind == K::matrix && is_number(a)) return b;
            if (a.kind == K::matrix && pb && a.cols == b.size) return Type::point(a.rows);
        }
        if ((op == Tok::plus || op == Tok::minus) && a.kind == K::matrix && a == b) return a;
        fail(e, fmt::format("'{}' is not defined between {} and {}",
                            op == Tok::star    ? "*"
                            : op == Tok::slash ? "/"
                            : op == Tok::plus  ? "+"
                                               : "-",
                            type_name(a), type_name(b)));
    }
    if (!pa && !pb) {
        require_number(a, la);
        require_number(b, lb);
        return Type::number();
    }
    const bool mul = op == Tok::star || op == Tok::slash;
    if (pa && pb) {
        if (mul) fail(e, "points multiply or divide by numbers only");
        if (a.size != b.size) fail(e, "points of different dimensions");
        return a;
    }
    if (!mul) fail(e, "a point and a number cannot be added; use a point");
    if (pb && op == Tok::slash) fail(e, "a number cannot be divided by a point");
    if (pa)
        require_number(b, lb);
    else
        require_number(a, la);
    return pa ? a : b;
}

} // namespace

std::string type_name(Type t) {
    switch (t.kind) {
    case Type::Kind::number: return "a number";
    case Type::Kind::boolean: return "a condition";
    case Type::Kind::point: return "a point";
    case Type::Kind::interval: return "an interval";
    case Type::Kind::box: return "a box";
    case Type::Kind::matrix: return fmt::format("a {}×{} matrix", t.rows, t.cols);
    case Type::Kind::transform: return t.size ? fmt::format("a transform of R{}", t.size) : "a transform";
    case Type::Kind::shape: return "a shape";
    case Type::Kind::function: return "a function";
    case Type::Kind::automaton: return "an automaton";
    }
    return "a value";
}

std::string type_spelling(Type t) {
    switch (t.kind) {
    case Type::Kind::number: return "number";
    case Type::Kind::boolean: return "condition";
    case Type::Kind::point: return fmt::format("point{}", t.size);
    case Type::Kind::interval: return "interval";
    case Type::Kind::box: return fmt::format("box{}", t.size);
    case Type::Kind::matrix: return fmt::format("matrix{}x{}", t.rows, t.cols);
    case Type::Kind::transform: return t.size ? fmt::format("transform{}", t.size) : "transform";
    case Type::Kind::shape: return fmt::format("shape{}", t.size);
    case Type::Kind::function: return "function";
    case Type::Kind::automaton: return "automaton";
    }
    return "?";
}

ValueKind value_kind(Type t) {
    switch (t.kind) {
    case Type::Kind::boolean: return ValueKind::boolean;
    case Type::Kind::point: return ValueKind::point;
    case Type::Kind::interval: return ValueKind::interval;
    case Type::Kind::box: return ValueKind::box;
    default: return ValueKind::scalar;
    }
}

void require_number(Type t, Location loc) {
    if (t.kind == Type::Kind::shape) fail(loc, "a shape is not a number here; call it with coordinates");
    if (t.kind == Type::Kind::function) fail(loc, "a function is not a number here; call it with arguments");
    if (!is_number(t)) fail(loc, fmt::format("expected a number, found {}", type_name(t)));
}

void require_condition(Type t, Location loc) {
    if (t.kind != Type::Kind::boolean) fail(loc, fmt::format("expected a condition, found {}", type_name(t)));
}

Type unary_rule(Tok op, Type a, Location la) {
    switch (op) {
    case Tok::kw_not: require_condition(a, la); return Type::boolean();
    case Tok::plus:
    case Tok::minus:
        if (a.kind == Type::Kind::point) return a;
        [[fallthrough]];
    case Tok::tilde: require_number(a, la); return Type::number();
    default: break;
    }
    throw InternalError("unknown unary operator");
}

Type binary_rule(Tok op, Type a, Type b, Location e, Location la, Location lb) {
    switch (op) {
    case Tok::kw_and:
    case Tok::kw_or:
        require_condition(a, la);
        require_condition(b, lb);
        return Type::boolean();
    case Tok::lt:
    case Tok::le:
    case Tok::gt:
    case Tok::ge:
    case Tok::eq:
    case Tok::ne:
        require_number(a, la);
        require_number(b, lb);
        return Type::boolean();
    case Tok::amp:
    case Tok::bar:
    case Tok::caret:
        require_number(a, la);
        require_number(b, lb);
        return Type::number();
    case Tok::times:
        if (a.kind != Type::Kind::interval && a.kind != Type::Kind::box)
            fail(la, fmt::format("'×' builds a box from intervals, found {}", type_name(a)));
        if (b.kind != Type::Kind::interval)
            fail(lb, fmt::format("'×' builds a box from intervals, found {}", type_name(b)));
        return box_product_rule(a, b, e);
    case Tok::plus:
    case Tok::minus:
    case Tok::star:
    case Tok::slash: return arithmetic_rule(op, a, b, e, la, lb);
    default: break;
    }
    throw InternalError("unknown binary operator");
}

bool is_box_product(Type a, Type b) {
    return (a.kind == Type::Kind::interval || a.kind == Type::Kind::box) && b.kind == Type::Kind::interval;
}

Type box_product_rule(Type a, Type b, Location e) {
    const int axes = (a.kind == Type::Kind::box ? a.size : 1) + (b.kind == Type::Kind::box ? b.size : 1);
    if (axes > 3) fail(e, "boxes have 2 or 3 axes");
    return Type::box(axes);
}

Type if_rule(Type a, Type b, Location lthen, Location lelse) {
    using K = Type::Kind;
    if (a.kind != K::number && a.kind != K::point && a.kind != K::boolean)
        fail(lthen,
             fmt::format("'if' chooses between numbers, points or conditions, found {}", type_name(a)));
    if (a != b)
        fail(lelse, fmt::format("the branches of 'if' differ: {} and {}", type_name(a), type_name(b)));
    return a;
}

Type field_rule(Type p, const std::string& field, Location e) {
    if (p.kind != Type::Kind::point)
        fail(e, fmt::format("'.{}' needs a point, found {}", field, type_name(p)));
    const int k = field == "x" ? 0 : field == "y" ? 1 : field == "z" ? 2 : 99;
    if (k >= p.size) fail(e, fmt::format("a point of {} coordinates has no component '{}'", p.size, field));
    return Type::number();
}

Type tuple_rule(std::size_t components, Location e) {
    if (components > 3) fail(e, fmt::format("points have 2 or 3 coordinates, this one has {}", components));
    return Type::point(static_cast<int>(components));
}

} // namespace frac::front
