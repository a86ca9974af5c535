#include "frontend/builtins.hpp"

namespace frac::front {

namespace {

using ir::Op;

constexpr Builtin builtins[] = {
    {"sqrt", BuiltinKind::unary, 1, 1, Op::Sqrt},
    {"abs", BuiltinKind::unary, 1, 1, Op::Abs},
    {"floor", BuiltinKind::unary, 1, 1, Op::Floor},
    {"ceil", BuiltinKind::unary, 1, 1, Op::Ceil},
    {"dz", BuiltinKind::unary, 1, 1, Op::Dz},
    {"sin", BuiltinKind::unary, 1, 1, Op::Sin},
    {"cos", BuiltinKind::unary, 1, 1, Op::Cos},
    {"tan", BuiltinKind::unary, 1, 1, Op::Tan},
    {"exp", BuiltinKind::unary, 1, 1, Op::Exp},
    {"log", BuiltinKind::unary, 1, 1, Op::Log},
    {"atan2", BuiltinKind::binary, 2, 2, Op::Atan2},
    {"min", BuiltinKind::variadic, 2, 64, Op::Min},
    {"max", BuiltinKind::variadic, 2, 64, Op::Max},
    {"mod", BuiltinKind::mod, 2, 2, Op::Mod1},
    {"pow", BuiltinKind::pow, 2, 2, Op::Pow},
    {"enclose", BuiltinKind::enclose, 2, 2, Op::Const},
    {"dimension", BuiltinKind::dimension, 1, 4, Op::Const},
    {"translate", BuiltinKind::transform, 2, 3, Op::Const},
    {"rotate", BuiltinKind::transform, 1, 1, Op::Const},
    {"scale", BuiltinKind::transform, 1, 3, Op::Const},
    {"shear", BuiltinKind::transform, 2, 2, Op::Const},
    {"controls", BuiltinKind::controls, 1, 64, Op::Const},
    {"tabulate", BuiltinKind::tabulate, 2, 2, Op::Const},
    {"dist", BuiltinKind::distance, 2, 2, Op::External},
    {"dof", BuiltinKind::dof, 1, 1, Op::Const},
    {"kron", BuiltinKind::kron, 2, 2, Op::Const},
    {"point", BuiltinKind::primitive, 1, 1, Op::Const},
    {"segment", BuiltinKind::primitive, 2, 2, Op::Const},
    {"polyline", BuiltinKind::primitive, 0, 64, Op::Const},
    {"polygon", BuiltinKind::primitive, 0, 64, Op::Const},
};

} // namespace

const Builtin* find_builtin(const std::string& name) {
    for (const Builtin& b : builtins)
        if (name == b.name) return &b;
    return nullptr;
}

std::vector<std::string> builtin_names() {
    std::vector<std::string> names;
    for (const Builtin& b : builtins) names.push_back(b.name);
    return names;
}

bool is_builtin_constant(const std::string& name) {
    return name == "pi" || name == "e" || name == "identity";
}

} // namespace frac::front
