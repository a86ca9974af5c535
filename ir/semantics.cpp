#include "ir/semantics.hpp"

#include <cmath>
#include <stdexcept>

namespace frac::ir {

namespace {

Interval truth(bool proven_true, bool proven_false) {
    if (proven_true) return tv_true;
    if (proven_false) return tv_false;
    return tv_unknown;
}

} // namespace

Interval apply_interval(Op op, const Interval* a, std::int64_t imm) {
    using namespace frac::num;
    const bool any_empty = a[0].is_empty() || (arity(op) > 1 && a[1].is_empty());
    switch (op) {
    case Op::Add: return add(a[0], a[1]);
    case Op::Sub: return sub(a[0], a[1]);
    case Op::Mul: return mul(a[0], a[1]);
    case Op::Div: return div(a[0], a[1]);
    case Op::Neg: return neg(a[0]);
    case Op::Sqr: return sqr(a[0]);
    case Op::PowI: return powi(a[0], imm);
    case Op::Pow: return pow(a[0], a[1]);
    case Op::Sqrt: return sqrt(a[0]);
    case Op::Abs: return abs(a[0]);
    case Op::Min: return min(a[0], a[1]);
    case Op::Max: return max(a[0], a[1]);
    case Op::Floor: return floor(a[0]);
    case Op::Ceil: return ceil(a[0]);
    case Op::Mod1: return mod1(a[0]);
    case Op::Dz: return dz(a[0]);
    case Op::Sin: return sin(a[0]);
    case Op::Cos: return cos(a[0]);
    case Op::Tan: return tan(a[0]);
    case Op::Exp: return exp(a[0]);
    case Op::Log: return log(a[0]);
    case Op::Atan2: return atan2(a[0], a[1]);
    case Op::External: break; // the engines call the tape's function: semantics has no table
    case Op::Lt:
        if (any_empty) return Interval::empty();
        return truth(a[0].hi < a[1].lo, a[0].lo >= a[1].hi);
    case Op::Le:
        if (any_empty) return Interval::empty();
        return truth(a[0].hi <= a[1].lo, a[0].lo > a[1].hi);
    case Op::Gt:
        if (any_empty) return Interval::empty();
        return truth(a[0].lo > a[1].hi, a[0].hi <= a[1].lo);
    case Op::Ge:
        if (any_empty) return Interval::empty();
        return truth(a[0].lo >= a[1].hi, a[0].hi < a[1].lo);
    case Op::Eq:
        if (any_empty) return Interval::empty();
        return truth(a[0].is_thin() && a[0] == a[1], a[0].hi < a[1].lo || a[1].hi < a[0].lo);
    case Op::Ne:
        if (any_empty) return Interval::empty();
        return truth(a[0].hi < a[1].lo || a[1].hi < a[0].lo, a[0].is_thin() && a[0] == a[1]);
    case Op::And:
        if (any_empty) return Interval::empty();
        return {std::fmin(a[0].lo, a[1].lo), std::fmin(a[0].hi, a[1].hi)};
    case Op::Or:
        if (any_empty) return Interval::empty();
        return {std::fmax(a[0].lo, a[1].lo), std::fmax(a[0].hi, a[1].hi)};
    case Op::Not:
        if (any_empty) return Interval::empty();
        return {1.0 - a[0].hi, 1.0 - a[0].lo}; // exact on {0, 1}
    case Op::Select:
        if (a[0].is_empty()) return Interval::empty();
        if (a[0] == tv_true) return a[1];
        if (a[0] == tv_false) return a[2];
        return hull(a[1], a[2]);
#include "ir/non_operation_cases.def"
        break;
    }
    throw std::logic_error(std::string("apply_interval: not an operation: ") + op_name(op));
}

double apply_point(Op op, const double* a, std::int64_t imm) {
    switch (op) {
    case Op::Add: return a[0] + a[1];
    case Op::Sub: return a[0] - a[1];
    case Op::Mul: return a[0] * a[1];
    case Op::Div: return a[0] / a[1];
    case Op::Neg: return -a[0];
    case Op::Sqr: return a[0] * a[0];
    case Op::PowI: return std::pow(a[0], static_cast<double>(imm));
    case Op::Pow: return std::pow(a[0], a[1]);
    case Op::Sqrt: return std::sqrt(a[0]);
    case Op::Abs: return std::fabs(a[0]);
    case Op::Min: return std::fmin(a[0], a[1]);
    case Op::Max: return std::fmax(a[0], a[1]);
    case Op::Floor: return std::floor(a[0]);
    case Op::Ceil: return std::ceil(a[0]);
    case Op::Mod1: return num::point::mod1(a[0]);
    case Op::Dz: return num::point::dz(a[0]);
    case Op::Sin: return std::sin(a[0]);
    case Op::Cos: return std::cos(a[0]);
    case Op::Tan: return std::tan(a[0]);
    case Op::Exp: return std::exp(a[0]);
    case Op::Log: return std::log(a[0]);
    case Op::Atan2: return std::atan2(a[0], a[1]);
    case Op::External: break;
    case Op::Lt: return a[0] < a[1];
    case Op::Le: return a[0] <= a[1];
    case Op::Gt: return a[0] > a[1];
    case Op::Ge: return a[0] >= a[1];
    case Op::Eq: return a[0] == a[1];
    case Op::Ne: return a[0] != a[1];
    case Op::And: return a[0] > 0.5 && a[1] > 0.5;
    case Op::Or: return a[0] > 0.5 || a[1] > 0.5;
    case Op::Not: return !(a[0] > 0.5);
    case Op::Select: return a[0] > 0.5 ? a[1] : a[2];
#include "ir/non_operation_cases.def"
        break;
    }
    throw std::logic_error(std::string("apply_point: not an operation: ") + op_name(op));
}

} // namespace frac::ir
