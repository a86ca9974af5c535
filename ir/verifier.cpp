// Structural checks of the expression graph; a failure is an internal error, never a user error.
#include "ir/graph.hpp"

#include <fmt/format.h>

namespace frac::ir {

std::string verify_graph(const Graph& g) {
    for (NodeId id = 0; id < g.size(); ++id) {
        const Node& n = g[id];
        const int want = is_series(n.op) ? 1 : arity(n.op);
        for (int i = 0; i < 3; ++i) {
            const NodeId a = n.args[static_cast<std::size_t>(i)];
            if (i < want && a == no_node)
                return fmt::format("%{}: {} lacks argument {}", id, op_name(n.op), i);
            if (!is_series(n.op) && i >= want && a != no_node)
                return fmt::format("%{}: {} has too many arguments", id, op_name(n.op));
            if (a != no_node && a >= id) return fmt::format("%{}: argument %{} is not earlier", id, a);
        }
        if (n.op == Op::Index && (n.imm < 1 || n.imm > max_series_level))
            return fmt::format("%{}: bad index level", id);
        if (n.op == Op::External && (n.imm < 0 || static_cast<std::size_t>(n.imm) >= g.externals.size()))
            return fmt::format("%{}: external #{} out of range", id, n.imm);
        if (n.op == Op::State && (state_level(n.imm) < 1 || state_level(n.imm) > max_series_level))
            return fmt::format("%{}: bad orbit state", id);
        if (n.orbit.size() != 2 * static_cast<std::size_t>(n.series.state_count))
            return fmt::format("%{}: orbit of the wrong size", id);
        for (NodeId a : n.orbit)
            if (a >= id) return fmt::format("%{}: orbit argument %{} is not earlier", id, a);
        if (is_series(n.op)) {
            const SeriesData& s = n.series;
            if (s.level < 1) return fmt::format("%{}: series without level", id);
            if (s.end != infinite_end && s.end < s.start) return fmt::format("%{}: empty series range", id);
            if (s.escape.present &&
                (s.state_count == 0 || s.end != infinite_end || n.op == Op::SeriesSum ||
                 !(s.escape.slope >= 0) || !(s.escape.offset <= 0) || !(s.escape.radius >= 0) ||
                 !(s.escape.growth.lo >= 1) || !(s.escape.scale0.lo > 0)))
                return fmt::format("%{}: malformed escape certificate", id);
            if (s.end == infinite_end) {
                if (n.args[1] == no_node) return fmt::format("%{}: infinite series without tail", id);
                if (!(s.gamma.lo > 0 && s.gamma.hi < 1)) return fmt::format("%{}: decay not in (0, 1)", id);
                for (int i = 1; i < 3; ++i) {
                    const NodeId a = n.args[static_cast<std::size_t>(i)];
                    if (a != no_node && (g[a].index_mask >> s.level) & 1)
                        return fmt::format("%{}: tail coefficient depends on the series index", id);
                }
                for (int i = 0; i < 4; ++i) {
                    const NodeId a = n.point_tail[static_cast<std::size_t>(i)];
                    if ((a == no_node) != (n.args[1 + i / 2] == no_node))
                        return fmt::format("%{}: point bounds of the tail do not match its coefficients", id);
                    if (a != no_node && (a >= id || (g[a].index_mask >> s.level) & 1))
                        return fmt::format("%{}: malformed point bound of the tail", id);
                }
            }
        }
    }
    return {};
}

} // namespace frac::ir
