#include "frontend/inline_size.hpp"

#include <fmt/format.h>
#include <string>
#include <unordered_map>
#include <vector>

namespace frac::front {

namespace {

class InlineSize {
public:
    explicit InlineSize(const Program& p) {
        for (const Item& it : p.items)
            if (it.kind == ItemKind::fn) functions_[it.name].push_back(&it);
    }

    // Nodes of `e` with its direct calls inlined. A double: a chain of doublings passes every integer type
    // (and inf is still "too large").
    double of(const Expr& e) {
        double n = 1;
        for (const ExprPtr& k : e.kids)
            if (k) n += of(*k);
        for (const Arg& a : e.args)
            if (a.value) n += of(*a.value);
        for (const Binding& b : e.bindings)
            if (b.value) n += of(*b.value);
        if (e.kind == ExprKind::call)
            if (const Item* callee = largest_callee(e.text)) n += of(*callee);
        return n;
    }

    double of(const Item& fn) {
        auto [it, fresh] = sizes_.try_emplace(&fn, 0); // 0 while in progress: recursion is reported elsewhere
        if (!fresh) return it->second;
        const double n = fn.body ? of(*fn.body) : 1;
        sizes_[&fn] = n;
        return n;
    }

    // The function a call names (by its last component: the import's alias aside), the largest if
    // several files define one of that name; null for a parameter or a builtin.
    const Item* largest_callee(const std::string& callee) {
        const std::size_t dot = callee.rfind('.');
        const auto found = functions_.find(dot == std::string::npos ? callee : callee.substr(dot + 1));
        if (found == functions_.end()) return nullptr;
        const Item* best = nullptr;
        double best_size = 0;
        for (const Item* f : found->second)
            if (const double n = of(*f); !best || n > best_size) best = f, best_size = n;
        return best;
    }

    // The call in `e` whose callee is the largest, and that size (its callee's).
    std::pair<const Expr*, double> largest_call(const Expr& e) {
        std::pair<const Expr*, double> best{nullptr, 0};
        const auto consider = [&](const Expr* k) {
            if (!k) return;
            const auto c = largest_call(*k);
            if (c.first && c.second > best.second) best = c;
        };
        if (e.kind == ExprKind::call)
            if (const Item* callee = largest_callee(e.text)) best = {&e, of(*callee)};
        for (const ExprPtr& k : e.kids) consider(k.get());
        for (const Arg& a : e.args) consider(a.value.get());
        for (const Binding& b : e.bindings) consider(b.value.get());
        return best;
    }

private:
    std::unordered_map<std::string, std::vector<const Item*>> functions_;
    std::unordered_map<const Item*, double> sizes_;
};

std::string size_text(double n) {
    return n < 1e9 ? fmt::format("{:.0f}", n) : fmt::format("about {:.3g}", n);
}

constexpr int max_chain_notes = 12;

} // namespace

void check_inline_size(const Program& program, const Limits& limits, Diagnostics& diags) {
    const auto limit = static_cast<double>(limits.max_inline_nodes);
    InlineSize size(program);
    for (const Item& it : program.items) {
        if (it.kind == ItemKind::fn || it.kind == ItemKind::import || it.kind == ItemKind::automaton)
            continue;
        std::vector<const Expr*> roots;
        if (it.body) roots.push_back(it.body.get());
        for (const Expect& x : it.expects)
            if (x.expr) roots.push_back(x.expr.get());
        for (const Expr* root : roots) {
            const double n = size.of(*root);
            if (n <= limit) continue;
            diags.error(it.loc, fmt::format("'{}' inlined has {} expression nodes, more than the limit of "
                                            "{}{}: functions calling the previous one several times "
                                            "multiply at each level",
                                            it.name, size_text(n), limits.max_inline_nodes,
                                            raised_by("FRAC_MAX_INLINE_NODES")));
            // The chain: from the definition, each time the call of the largest function.
            const Expr* at = root;
            for (int step = 0; step < max_chain_notes; ++step) {
                const auto [call, callee_size] = size.largest_call(*at);
                if (!call) break;
                const Item* callee = size.largest_callee(call->text);
                diags.note(call->loc, fmt::format("this call of '{}' inlines {} nodes", call->text,
                                                  size_text(callee_size)));
                if (!callee->body) break;
                at = callee->body.get();
            }
        }
    }
}

} // namespace frac::front
