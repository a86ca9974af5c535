// Text form of the expression graph (frac check --emit=ir).
#include "ir/graph.hpp"
#include "ir/series_tail.hpp"
#include "numeric/rational.hpp"

#include <algorithm>
#include <fmt/format.h>

namespace frac::ir {

std::string external_text(std::int64_t index,
                          const std::vector<std::shared_ptr<const ExternalFunction>>& table) {
    const auto k = static_cast<std::size_t>(index);
    const bool bound = index >= 0 && k < table.size() && table[k];
    return fmt::format(" #{} {}", index, bound ? table[k]->name() : std::string("(unbound)"));
}

std::string escape_text(const OrbitEscape& e) {
    std::string s =
        fmt::format(" escape |q| > {}: terms >= ({} (|q| - {}) + {}) * [{}, {}] / [{}, {}]^i", e.radius,
                    e.slope, e.radius, e.offset, e.scale0.lo, e.scale0.hi, e.growth.lo, e.growth.hi);
    if (e.lipschitz > 0)
        s += fmt::format(", term i {}-Lipschitz * ({} / growth)^i", e.lipschitz, e.map_lipschitz);
    return s;
}

std::string print_graph(const Graph& g, const std::vector<NodeId>& roots) {
    std::vector<bool> live(g.size(), false);
    std::vector<NodeId> stack(roots.begin(), roots.end());
    while (!stack.empty()) {
        const NodeId id = stack.back();
        stack.pop_back();
        if (id == no_node || live[id]) continue;
        live[id] = true;
        for (NodeId a : g[id].args)
            if (a != no_node) stack.push_back(a);
        for (NodeId a : g[id].orbit) stack.push_back(a);
        for (NodeId a : g[id].point_tail)
            if (a != no_node) stack.push_back(a);
    }
    std::string out;
    for (NodeId id = 0; id < g.size(); ++id) {
        if (!live[id]) continue;
        const Node& n = g[id];
        out += fmt::format("%{} = {}", id, op_name(n.op));
        switch (op_class(n.op)) {
        case OpClass::leaf:
            if (n.op == Op::Const) {
                out += n.value.is_thin() ? fmt::format(" {}", n.value.lo)
                                         : fmt::format(" [{}, {}] ~{}", n.value.lo, n.value.hi, n.point);
                if (n.exact && !n.value.is_thin()) out += " = " + n.exact->to_string(); // exactly 1/3
            } else if (n.op == Op::State)
                out += fmt::format(" {}.{}", state_level(n.imm), state_component(n.imm));
            else
                out += fmt::format(" {}", n.imm);
            break;
        case OpClass::arith:
        case OpClass::logic:
            for (int i = 0; i < arity(n.op); ++i)
                out += fmt::format("{} %{}", i ? "," : "", n.args[static_cast<std::size_t>(i)]);
            if (n.op == Op::PowI) out += fmt::format(", {}", n.imm);
            if (n.op == Op::External) out += external_text(n.imm, g.externals);
            break;
        case OpClass::series: {
            const SeriesData& s = n.series;
            const std::string end = s.end == infinite_end ? "inf" : fmt::format("{}", s.end);
            out += fmt::format(" level {} in {}..{} term %{}", s.level, s.start, end, n.args[0]);
            if (s.end == infinite_end) {
                const std::string b = n.args[2] == no_node ? "0" : fmt::format("%{}", n.args[2]);
                out += fmt::format(" tail (%{} + {} i) * [{}, {}]^i", n.args[1], b, s.gamma.lo, s.gamma.hi);
                for (int k = 0; k < 2; ++k) {
                    const auto lo = n.point_tail[static_cast<std::size_t>(2 * k)];
                    const auto hi = n.point_tail[static_cast<std::size_t>(2 * k + 1)];
                    if (lo != n.args[static_cast<std::size_t>(1 + k)] || hi != lo)
                        out += fmt::format(" point {} in [%{}, %{}]", k ? "B" : "A", lo, hi);
                }
            }
            if (s.state_count > 0) {
                std::string from, map;
                for (int c = 0; c < s.state_count; ++c) {
                    from += fmt::format("{}%{}", c ? ", " : "", n.orbit[static_cast<std::size_t>(c)]);
                    map += fmt::format("{}%{}", c ? ", " : "",
                                       n.orbit[static_cast<std::size_t>(s.state_count + c)]);
                }
                out += fmt::format(" orbit from ({}) map ({})", from, map);
                if (s.escape.present) out += escape_text(s.escape);
            }
            break;
        }
        }
        if (std::find(roots.begin(), roots.end(), id) != roots.end()) out += "   ; root";
        out += "\n";
    }
    return out;
}

} // namespace frac::ir
