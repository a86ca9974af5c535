// frac analyze: the differential analysis of an automaton's subdivision operators
// (runtime/automata/analysis).
#include "cli/commands.hpp"

#include "ir/automaton_check.hpp"
#include "runtime/automata/analysis.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <stdexcept>

namespace frac::cli {

namespace {

using num::Interval;
using num::Rational;

std::string vector_text(const std::vector<std::string>& entries) {
    return "(" + fmt::format("{}", fmt::join(entries, ", ")) + ")";
}

std::string exact_text(const std::vector<Rational>& v) {
    std::vector<std::string> s;
    for (const Rational& r : v) s.push_back(r.to_string());
    return vector_text(s);
}

// Six digits; rounding noise around 0 (the midpoint of an enclosure of 0) is printed as 0.
std::string approx_text(const std::vector<double>& v) {
    std::vector<std::string> s;
    for (double x : v) s.push_back(fmt::format("{:.6g}", std::abs(x) < 5e-13 ? 0.0 : x));
    return vector_text(s);
}

std::vector<double> midpoints(const std::vector<Interval>& v) {
    std::vector<double> m;
    for (const Interval& x : v) m.push_back(num::midpoint(x));
    return m;
}

std::vector<double> to_doubles(const std::vector<Rational>& v) {
    std::vector<double> d;
    for (const Rational& r : v) d.push_back(r.to_double());
    return d;
}

// The control points that draw a barycentric state: the initial state's projection, else the first
// arc into the state from a euclidean one (as `controls(...)` in a cifs). Its name goes to `name`.
const ir::Operator* projection_of(const ir::Automaton& a, std::size_t state, std::string& name) {
    if (state == a.initial && a.projection) {
        name = "project";
        return &*a.projection;
    }
    for (std::size_t i = 0; i < a.arcs.size(); ++i) {
        const ir::Arc& arc = a.arcs[i];
        if (arc.to == state && a.states[arc.from].space.kind == ir::Space::Kind::euclidean) {
            name = arc.label.empty() ? fmt::format("{} -> {}", a.states[arc.from].name, a.states[state].name)
                                     : arc.label;
            return &arc.op;
        }
    }
    return nullptr;
}

// P x in R^d (the homogeneous last row dropped); a direction (sum x = 0) is scaled to unit length.
std::vector<double> project(const ir::Operator& p, const std::vector<double>& x, bool direction) {
    std::vector<double> y(p.rows() - 1, 0.0);
    for (std::size_t r = 0; r + 1 < p.rows(); ++r)
        for (std::size_t c = 0; c < x.size(); ++c) y[r] += p.nearest(r, c) * x[c];
    if (direction) {
        double norm = 0;
        for (double v : y) norm += v * v;
        norm = std::sqrt(norm);
        if (norm > 0)
            for (double& v : y) v /= norm;
    }
    return y;
}

std::string value_text(const rt::Eigenpair& e) {
    if (e.exact) {
        const std::string m = e.multiplicity > 1 ? fmt::format(", multiplicity {}", e.multiplicity) : "";
        return fmt::format("{} (exact{})", e.exact->to_string(), m);
    }
    const std::string how = e.verified ? "verified" : "NOT verified";
    if (e.is_complex())
        return fmt::format("{:.6g} ± {:.6g}i, modulus {:.6g} ({})", e.re, std::abs(e.im),
                           num::midpoint(e.modulus()), how);
    return fmt::format("{:.6g} ({})", e.re, how);
}

void print_operator(const ir::Automaton& a, const rt::OperatorAnalysis& o) {
    const ir::State& s = a.states[o.state];
    std::cout << fmt::format("{}: {} -> {} in {}\n", o.label, s.name, s.name, ir::space_name(s.space));
    std::string pname;
    const ir::Operator* p = projection_of(a, o.state, pname);
    const std::vector<double> fixed =
        o.exact_fixed ? to_doubles(*o.exact_fixed) : midpoints(o.fixed.vector_re);
    if (o.exact_fixed)
        std::cout << fmt::format("  fixed point {} (exact)", exact_text(*o.exact_fixed));
    else if (o.fixed.verified)
        std::cout << fmt::format("  fixed point {} (verified)", approx_text(fixed));
    else
        std::cout << "  fixed point: NOT verified";
    if (p && !fixed.empty())
        std::cout << fmt::format(", through {}: {}", pname, approx_text(project(*p, fixed, false)));
    std::cout << "\n";
    for (std::size_t i = 0; i < o.others.size(); ++i) {
        const rt::Eigenpair& e = o.others[i];
        std::cout << fmt::format("  λ{} = {}", i + 2, value_text(e));
        if (e.exact_vector)
            std::cout << fmt::format(", eigenvector {}", exact_text(*e.exact_vector));
        else if (e.verified && !e.is_complex())
            std::cout << fmt::format(", eigenvector {}", approx_text(midpoints(e.vector_re)));
        std::cout << "\n";
    }
    std::cout << fmt::format("  behaviour: {}: {}\n", rt::behaviour_name(o.behaviour), o.reason);
    if (o.behaviour == rt::Behaviour::tangent) {
        const rt::Eigenpair& l2 = o.others.front();
        if (p) {
            std::vector<double> v = midpoints(l2.vector_re);
            if (l2.exact_vector) v = to_doubles(*l2.exact_vector);
            const std::vector<double> d = project(*p, v, true);
            bool degenerate = true;
            for (double v : d) degenerate = degenerate && v == 0;
            std::cout << (degenerate
                              ? fmt::format("  half-tangent: the control points of {} project v2 to 0\n",
                                            pname)
                              : fmt::format("  half-tangent along ±{} (through {})\n", approx_text(d),
                                            pname));
        }
    }
    if (o.edge) {
        const rt::Eigenpair& edge = o.others[*o.edge];
        std::vector<std::string> v(a.arcs[o.arc].op.rows(), "0");
        v[o.edge_from] = "-1";
        v[o.edge_from + 1] = "1";
        const std::string value = edge.exact ? edge.exact->to_string() : fmt::format("{:.6g}", edge.re);
        const std::string rival = o.c1_exact_rival ? o.c1_exact_rival->to_string()
                                                   : fmt::format("{:.6g}", num::midpoint(o.c1_rival));
        const char* verdict = !o.c1_condition   ? "undecided (the enclosures overlap)"
                              : *o.c1_condition ? "holds"
                                                : "fails";
        std::cout << fmt::format(
            "  C1 condition at this vertex (seed 002): λ{} = {} of the polygon edge {} ≥ {}: {}\n",
            *o.edge + 2, value, vector_text(v), rival, verdict);
    }
    if (o.behaviour == rt::Behaviour::spiral) {
        const rt::Eigenpair& l2 = o.others.front();
        std::cout << fmt::format("  turns by {:.6g} degrees and shrinks by {:.6g} each step\n",
                                 std::atan2(std::abs(l2.im), l2.re) * 180 / std::acos(-1.0),
                                 num::midpoint(l2.modulus()));
    }
    // The arcs to other states place copies of their curves around this fixed point (seed 004's T^l,
    // T^r into the junction state i): along v2 when their control polygons have a component on it.
    for (const rt::OperatorAnalysis::Copy& copy : o.copies) {
        const ir::Arc& arc = a.arcs[copy.arc];
        const char* along = copy.along == rt::OperatorAnalysis::Copy::Along::yes
                                ? "has a component on v2: its half-tangent is along v2"
                            : copy.along == rt::OperatorAnalysis::Copy::Along::no
                                ? "has no component on v2: its half-tangent is another eigenvector's"
                                : "has components on v2 that contain 0: undecided";
        std::cout << fmt::format("  junction: the copy of {} through {} {}\n", a.states[arc.to].name,
                                 ir::arc_name(a, copy.arc), along);
    }
    if (o.behaviour == rt::Behaviour::spiral || o.behaviour == rt::Behaviour::oscillation) {
        std::vector<std::string> copies;
        for (const ir::Arc& arc : a.arcs)
            if (arc.from == o.state && arc.to != o.state) copies.push_back(a.states[arc.to].name);
        if (!copies.empty())
            std::cout << fmt::format(
                "  junction: the copies of {} {} into the fixed point, with no tangent\n",
                fmt::join(copies, ", "), o.behaviour == rt::Behaviour::spiral ? "spiral" : "oscillate");
    }
    const bool all_along =
        std::all_of(o.copies.begin(), o.copies.end(), [](const rt::OperatorAnalysis::Copy& c) {
            return c.along == rt::OperatorAnalysis::Copy::Along::yes;
        });
    if (o.copies.size() > 1 && all_along)
        std::cout << "  junction: G1, the copies meet at the fixed point along the one line ±v2\n";
}

} // namespace

int run_analyze(const std::string& file, const std::string& name) {
    auto c = compile_or_report(file);
    if (!c) return front::exit_compile_error;
    const ir::Automaton& a = find_automaton(*c, name).automaton;
    rt::AutomatonAnalysis result;
    try {
        result = rt::analyze(a);
    } catch (const std::invalid_argument& e) {
        throw RunError(e.what());
    }
    std::cout << fmt::format("analysis of {}\n", a.name);
    for (const rt::OperatorAnalysis& o : result.operators) print_operator(a, o);
    for (const rt::JunctionAnalysis& j : result.junctions) {
        const auto& ops = result.operators;
        std::string pname, through;
        if (const ir::Operator* p = projection_of(a, ops[j.left].state, pname))
            through =
                fmt::format(" (through {}: {})", pname, approx_text(project(*p, midpoints(j.point), false)));
        std::cout << fmt::format("junction {}(x_{}) = {}(x_{}){} at {}{}: {}\n", ops[j.left].label,
                                 ops[j.left_end].label, ops[j.right].label, ops[j.right_end].label,
                                 j.meet_exact ? " exactly" : "", approx_text(midpoints(j.point)), through,
                                 j.reason);
    }
    return 0;
}

} // namespace frac::cli
