#include "ir/automaton.hpp"

#include <fmt/format.h>

namespace frac::ir {

std::string space_name(Space s) {
    if (s.kind == Space::Kind::euclidean) return fmt::format("R{}", s.dimension);
    return fmt::format("bary({})", s.dimension + 1);
}

Operator Operator::from_exact(const num::Matrix<num::Rational>& m) {
    Operator op;
    op.exact = m;
    op.enclosure = num::enclose(m);
    op.nearest = num::Matrix<double>(m.rows(), m.cols());
    for (std::size_t r = 0; r < m.rows(); ++r)
        for (std::size_t c = 0; c < m.cols(); ++c) op.nearest(r, c) = m(r, c).to_double();
    return op;
}

Operator Operator::from_enclosure(const num::Matrix<num::Interval>& m) {
    Operator op;
    op.enclosure = m;
    op.nearest = num::Matrix<double>(m.rows(), m.cols());
    for (std::size_t r = 0; r < m.rows(); ++r)
        for (std::size_t c = 0; c < m.cols(); ++c) op.nearest(r, c) = num::midpoint(m(r, c));
    return op;
}

std::vector<std::size_t> Automaton::arcs_from(std::size_t s) const {
    std::vector<std::size_t> out;
    for (std::size_t i = 0; i < arcs.size(); ++i)
        if (arcs[i].from == s) out.push_back(i);
    return out;
}

int Automaton::output_dimension() const {
    if (projection) return static_cast<int>(projection->rows()) - 1;
    return states.at(initial).space.dimension;
}

num::Matrix<num::Rational> affine_functional(Space s) {
    const int n = s.coordinates();
    num::Matrix<num::Rational> w(1, static_cast<std::size_t>(n));
    if (s.kind == Space::Kind::euclidean) {
        w(0, static_cast<std::size_t>(n - 1)) = 1;
    } else {
        for (int i = 0; i < n; ++i) w(0, static_cast<std::size_t>(i)) = 1;
    }
    return w;
}

namespace {

std::string entry_text(const Operator& op, std::size_t r, std::size_t c) {
    if (op.exact) return (*op.exact)(r, c).to_string();
    const num::Interval v = op.enclosure(r, c);
    if (v.lo == v.hi) return fmt::format("{}", v.lo);
    return fmt::format("[{}, {}]", v.lo, v.hi);
}

std::string matrix_text(const Operator& op, const std::string& indent) {
    std::string out;
    for (std::size_t r = 0; r < op.rows(); ++r) {
        out += indent + "[";
        for (std::size_t c = 0; c < op.cols(); ++c) out += (c ? ", " : "") + entry_text(op, r, c);
        out += "]\n";
    }
    return out;
}

const char* primitive_name(Primitive::Kind k) {
    switch (k) {
    case Primitive::Kind::none: return "none";
    case Primitive::Kind::points: return "points";
    case Primitive::Kind::polyline: return "polyline";
    case Primitive::Kind::polygon: return "polygon";
    case Primitive::Kind::shape: return "shape";
    }
    return "?";
}

} // namespace

std::string print_automaton(const Automaton& a) {
    std::string out = fmt::format("automaton {}: {} states, {} arcs, initial {}\n", a.name, a.states.size(),
                                  a.arcs.size(), a.states.at(a.initial).name);
    for (const State& s : a.states) {
        out += fmt::format("  state {} : {}, primitive {}", s.name, space_name(s.space),
                           primitive_name(s.primitive.kind));
        if (s.primitive.kind == Primitive::Kind::shape) out += fmt::format(" #{}", s.primitive.shape);
        if (s.primitive.kind != Primitive::Kind::none && s.primitive.kind != Primitive::Kind::shape)
            out += fmt::format(" ({} points)", s.primitive.points.cols());
        out += "\n";
    }
    for (const Arc& arc : a.arcs) {
        out += fmt::format("  arc {} -> {}", a.states.at(arc.from).name, a.states.at(arc.to).name);
        if (!arc.label.empty()) out += " " + arc.label;
        if (arc.probability) out += fmt::format(" p={}", *arc.probability);
        out += arc.op.exact ? " (exact)\n" : "\n";
        out += matrix_text(arc.op, "    ");
    }
    for (const Arc& b : a.embeddings) {
        out += fmt::format("  boundary {} <- {} {}{}\n", a.states.at(b.from).name, a.states.at(b.to).name,
                           b.label, b.op.exact ? " (exact)" : "");
        out += matrix_text(b.op, "    ");
    }
    if (a.projection) {
        out += "  projection\n";
        out += matrix_text(*a.projection, "    ");
    }
    return out;
}

} // namespace frac::ir
