#include "frontend/cell_import.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace frac::front {

namespace {

const StateDecl* find_state(const AutomatonDecl& a, const std::string& name) {
    for (const StateDecl& s : a.states)
        if (s.name == name) return &s;
    return nullptr;
}

} // namespace

void import_cells(AutomatonDecl& a, const BcifsSource& source, Diagnostics& diags) {
    BcifsDecl& b = *a.bcifs;
    for (StateDecl& cell : a.states) {
        if (cell.source.empty()) continue;
        const Item* from = source(cell.source, cell.source_loc);
        if (!from) continue;
        const StateDecl* original = find_state(*from->automaton, cell.source_cell);
        if (!original) {
            diags.error(cell.source_loc,
                        fmt::format("bcifs '{}' has no cell '{}'", cell.source, cell.source_cell));
            continue;
        }
        cell.space = original->space;
        cell.space.loc = cell.source_loc;
        // The source's operators of this cell whose target this bcifs also takes from the same source.
        for (const OperatorDecl& o : from->automaton->bcifs->operators) {
            if (o.cell != cell.source_cell) continue;
            const auto target = std::find_if(a.states.begin(), a.states.end(), [&](const StateDecl& s) {
                return s.source == cell.source && s.source_cell == o.target;
            });
            if (target == a.states.end()) continue;
            const auto written =
                std::find_if(b.operators.begin(), b.operators.end(),
                             [&](const OperatorDecl& w) { return w.cell == cell.name && w.name == o.name; });
            if (written != b.operators.end()) {
                diags.error(written->loc,
                            fmt::format("'{}.{}' is written here and also taken from '{}.{}' (a taken "
                                        "cell keeps its source's operators; name the new one otherwise)",
                                        cell.name, o.name, cell.source, cell.source_cell));
                continue;
            }
            OperatorDecl copy;
            copy.cell = cell.name;
            copy.name = o.name;
            copy.target = target->name;
            copy.boundary = o.boundary;
            copy.loc = cell.loc;
            copy.target_loc = target->loc;
            copy.source = cell.source;
            copy.source_cell = cell.source_cell;
            b.operators.push_back(std::move(copy));
        }
    }
}

} // namespace frac::front
