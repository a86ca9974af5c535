// S-expression form of the syntax tree (frac check --emit=ast).
#include "frontend/ast.hpp"

#include <fmt/format.h>

namespace frac::front {

namespace {

const char* op_text(Tok op) {
    switch (op) {
    case Tok::plus: return "+";
    case Tok::minus: return "-";
    case Tok::star: return "*";
    case Tok::slash: return "/";
    case Tok::caret: return "^";
    case Tok::amp: return "&";
    case Tok::bar: return "|";
    case Tok::tilde: return "~";
    case Tok::times: return "×";
    case Tok::lt: return "<";
    case Tok::le: return "<=";
    case Tok::gt: return ">";
    case Tok::ge: return ">=";
    case Tok::eq: return "==";
    case Tok::ne: return "!=";
    case Tok::kw_and: return "and";
    case Tok::kw_or: return "or";
    case Tok::kw_not: return "not";
    default: return token_name(op);
    }
}

std::string print_factors(const std::vector<FactorDecl>& side) {
    std::vector<std::string> out;
    for (const FactorDecl& f : side)
        out.push_back(f.constant ? print_expr(*f.constant) : f.cell + "." + f.name);
    return fmt::format("({})", fmt::join(out, " "));
}

std::string print_bcifs(const BcifsDecl& b) {
    std::string out;
    if (b.seed) out += fmt::format("\n  (seed {})", *b.seed);
    for (const ParamDecl& p : b.params)
        out += fmt::format("\n  (param {}{}{})", p.name,
                           p.lo ? fmt::format(" (in {} {})", print_expr(*p.lo), print_expr(*p.hi)) : "",
                           p.value ? " " + print_expr(*p.value) : "");
    for (const OperatorDecl& op : b.operators)
        out += fmt::format("\n  ({} {}.{} {} {})", op.boundary ? "boundary" : "subdivide", op.cell, op.name,
                           op.target, op.value ? print_expr(*op.value) : "?");
    for (const ConstraintDecl& c : b.constraints)
        out += fmt::format("\n  (== {} {})", print_factors(c.left), print_factors(c.right));
    for (const FixDecl& f : b.fixes)
        out += fmt::format("\n  (fix {}.{} {} {} {})", f.cell, f.name, f.row, f.col, print_expr(*f.value));
    return out;
}

} // namespace

std::string print_product(const std::vector<FactorDecl>& side) {
    std::vector<std::string> out;
    for (const FactorDecl& f : side)
        out.push_back(f.constant ? print_expr(*f.constant) : f.cell + "." + f.name);
    return fmt::format("{}", fmt::join(out, " * "));
}

std::string print_expr(const Expr& e) {
    auto kids = [&](std::size_t from = 0) {
        std::string s;
        for (std::size_t i = from; i < e.kids.size(); ++i)
            s += " " + (e.kids[i] ? print_expr(*e.kids[i]) : "inf");
        return s;
    };
    switch (e.kind) {
    case ExprKind::number:
    case ExprKind::name: return e.text;
    case ExprKind::call: {
        std::string s = "(call " + e.text;
        for (const Arg& a : e.args) s += " " + (a.name.empty() ? "" : a.name + ": ") + print_expr(*a.value);
        return s + ")";
    }
    case ExprKind::unary:
    case ExprKind::binary: return fmt::format("({}{})", op_text(e.op), kids());
    case ExprKind::if_: return fmt::format("(if{})", kids());
    case ExprKind::let: {
        std::string s = "(let (";
        for (std::size_t i = 0; i < e.bindings.size(); ++i)
            s +=
                (i ? " " : "") + fmt::format("({} {})", e.bindings[i].name, print_expr(*e.bindings[i].value));
        return s + ")" + kids() + ")";
    }
    case ExprKind::tuple: return fmt::format("(point{})", kids());
    case ExprKind::field: return fmt::format("(. {}{})", e.text, kids());
    case ExprKind::interval: return fmt::format("(interval{})", kids());
    case ExprKind::matrix: return fmt::format("(matrix{})", kids());
    case ExprKind::lambda: {
        std::string names;
        for (const Binding& b : e.bindings) names += (names.empty() ? "" : " ") + b.name;
        return fmt::format("(fn ({}){})", names, kids());
    }
    case ExprKind::series:
        if (!e.series->orbit_var.empty())
            return fmt::format("({} {} {} {} (orbit {} {} {}{}) {})", e.text, e.series->var,
                               print_expr(*e.kids[0]), e.kids[1] ? print_expr(*e.kids[1]) : "inf",
                               e.series->orbit_var, print_expr(*e.kids[3]), e.series->orbit_map,
                               e.kids.size() > 4 ? " (escape " + print_expr(*e.kids[4]) + ")" : "",
                               print_expr(*e.kids[2]));
        return fmt::format("({} {}{})", e.text, e.series->var, kids());
    }
    return "?";
}

std::string print_ast(const Program& p, std::uint32_t file) {
    std::string out;
    for (const Item& it : p.items) {
        if (file != 0 && it.loc.file != file) continue;
        std::string params;
        for (std::size_t i = 0; i < it.params.size(); ++i) params += (i ? " " : "") + it.params[i].name;
        switch (it.kind) {
        case ItemKind::import: out += fmt::format("(import \"{}\")\n", it.name); break;
        case ItemKind::fn:
            out += fmt::format("(fn {} ({}) {})\n", it.name, params, print_expr(*it.body));
            break;
        case ItemKind::const_: out += fmt::format("(const {} {})\n", it.name, print_expr(*it.body)); break;
        case ItemKind::shape:
            out += fmt::format("(shape {} ({}){} {})\n", it.name, params,
                               it.over ? " (over " + print_expr(*it.over) + ")" : "", print_expr(*it.body));
            break;
        case ItemKind::test:
            out += fmt::format("(test \"{}\"", it.name);
            for (const Expect& e : it.expects)
                out += fmt::format("\n  (expect {}{})", print_expr(*e.expr),
                                   e.within ? " (within " + print_expr(*e.within) + ")" : "");
            out += ")\n";
            break;
        case ItemKind::print: out += fmt::format("(print {})\n", print_expr(*it.body)); break;
        case ItemKind::automaton: {
            const AutomatonDecl& a = *it.automaton;
            out += fmt::format("({} {}", a.bcifs ? "bcifs" : a.graph_directed ? "cifs" : "ifs", it.name);
            for (const StateDecl& s : a.states)
                out += fmt::format("\n  (state {} {}{})", s.name,
                                   s.source.empty()
                                       ? fmt::format("{}{}", s.space.barycentric ? "bary" : "R", s.space.n)
                                       : fmt::format("(from {}.{})", s.source, s.source_cell),
                                   s.primitive ? " (primitive " + print_expr(*s.primitive) + ")" : "");
            for (const ArcDecl& arc : a.arcs)
                out += fmt::format("\n  (arc {} {}{} {}{})", arc.from, arc.to,
                                   arc.label.empty() ? "" : " " + arc.label, print_expr(*arc.op),
                                   arc.probability ? " (prob " + print_expr(*arc.probability) + ")" : "");
            if (a.bcifs) out += print_bcifs(*a.bcifs);
            if (!a.initial.empty()) out += fmt::format("\n  (initial {})", a.initial);
            if (a.projection) out += fmt::format("\n  (project {})", print_expr(*a.projection));
            out += ")\n";
            break;
        }
        }
    }
    return out;
}

} // namespace frac::front
