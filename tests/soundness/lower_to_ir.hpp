// Lowers the oracle's random expressions to the IR graph (with its constant folding), so that the
// engines can be checked against MPFI on the same expressions.
#pragma once

#include "ir/graph.hpp"
#include "tests/soundness/oracle.hpp"

#include <cstdlib>

namespace frac::oracle {

inline ir::NodeId lower_to_ir(ir::Graph& g, const oracle::Expr& e) {
    using oracle::Op;
    auto arg = [&](std::size_t i) { return lower_to_ir(g, e.args[i]); };
    switch (e.op) {
    case Op::Const: return g.constant(e.value);
    case Op::Var: return g.var(e.var);
    case Op::Add: return g.op(ir::Op::Add, arg(0), arg(1));
    case Op::Sub: return g.op(ir::Op::Sub, arg(0), arg(1));
    case Op::Mul: return g.op(ir::Op::Mul, arg(0), arg(1));
    case Op::Div: return g.op(ir::Op::Div, arg(0), arg(1));
    case Op::Neg: return g.op(ir::Op::Neg, arg(0));
    case Op::Sqr: return g.op(ir::Op::Sqr, arg(0));
    case Op::PowInt: return g.op(ir::Op::PowI, arg(0), ir::no_node, ir::no_node, e.n);
    case Op::Pow: return g.op(ir::Op::Pow, arg(0), arg(1));
    case Op::Sqrt: return g.op(ir::Op::Sqrt, arg(0));
    case Op::Abs: return g.op(ir::Op::Abs, arg(0));
    case Op::Min: return g.op(ir::Op::Min, arg(0), arg(1));
    case Op::Max: return g.op(ir::Op::Max, arg(0), arg(1));
    case Op::Floor: return g.op(ir::Op::Floor, arg(0));
    case Op::Ceil: return g.op(ir::Op::Ceil, arg(0));
    case Op::Mod1: return g.op(ir::Op::Mod1, arg(0));
    case Op::Dz: return g.op(ir::Op::Dz, arg(0));
    case Op::Sin: return g.op(ir::Op::Sin, arg(0));
    case Op::Cos: return g.op(ir::Op::Cos, arg(0));
    case Op::Tan: return g.op(ir::Op::Tan, arg(0));
    case Op::Exp: return g.op(ir::Op::Exp, arg(0));
    case Op::Log: return g.op(ir::Op::Log, arg(0));
    case Op::Atan2: return g.op(ir::Op::Atan2, arg(0), arg(1));
    }
    std::abort();
}

} // namespace frac::oracle
