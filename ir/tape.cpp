#include "ir/tape.hpp"
#include "ir/series_tail.hpp"
#include "support/flat_map.hpp"

#include <bit>
#include <fmt/format.h>
#include <stdexcept>

namespace frac::ir {

namespace {

int highest_level(std::uint64_t mask) {
    return mask == 0 ? 0 : 63 - std::countl_zero(mask);
}

// The slot of each node emitted in a context (a large model's tape has a hundred thousand).
using SlotMemo = support::FlatMap<NodeId, Slot, no_node>;

class Scheduler {
public:
    Scheduler(const Graph& g, Tape& t) : g_(g), t_(t) {}

    Slot run(NodeId root) {
        t_.blocks.emplace_back();
        contexts_.push_back({0, 0, {}});
        return emit(root);
    }

private:
    struct Context {
        int level;
        std::uint32_t block;
        SlotMemo memo;
    };

    Slot fresh() { return t_.num_slots++; }

    Context& context_for(int level) {
        for (auto it = contexts_.rbegin(); it != contexts_.rend(); ++it)
            if (it->level == level) return *it;
        throw std::logic_error(fmt::format("tape: index of level {} used outside its series", level));
    }

    Slot emit(NodeId id) {
        const Node& n = g_[id];
        if (n.op == Op::Const) {
            if (const Slot* known = const_slots_.find(id)) return *known;
            const Slot s = const_slots_[id] = fresh();
            t_.constants.push_back({s, n.value, n.point});
            return s;
        }
        if (n.op == Op::Var) {
            if (n.imm < 0 || n.imm >= t_.inputs)
                throw std::logic_error(fmt::format("tape: input {} out of range", n.imm));
            Slot& s = t_.input_slots[static_cast<std::size_t>(n.imm)];
            if (s == no_slot) s = fresh();
            return s;
        }
        Context& ctx = context_for(highest_level(n.index_mask));
        if (const Slot* known = ctx.memo.find(id)) return *known;
        if (capture_) return emit_captured(id);
        if (n.op == Op::Index) {
            // The index slot is allocated by the series that owns this context.
            throw std::logic_error("tape: series index without its series");
        }
        Slot out = is_series(n.op) ? emit_series(id, ctx) : emit_op(id, ctx);
        // emit_* may have grown contexts_ (invalidating ctx); look the context up again.
        context_for(highest_level(n.index_mask)).memo[id] = out;
        return out;
    }

    Slot emit_op(NodeId id, Context& ctx) {
        const Node& n = g_[id];
        const std::uint32_t block = ctx.block;
        Instr ins;
        ins.op = n.op;
        ins.imm = n.imm;
        for (int i = 0; i < arity(n.op); ++i)
            ins.in[static_cast<std::size_t>(i)] = emit(n.args[static_cast<std::size_t>(i)]);
        ins.out = fresh();
        t_.blocks[block].push_back(ins);
        return ins.out;
    }

    Slot emit_series(NodeId id, Context& ctx) {
        const Node& n = g_[id];
        const std::uint32_t outer_block = ctx.block;
        TapeSeries s;
        s.kind = n.op;
        s.data = n.series;
        s.block = static_cast<std::uint32_t>(t_.blocks.size());
        t_.blocks.emplace_back();
        s.index_slot = fresh();
        contexts_.push_back({n.series.level, s.block, {}});
        bind_leaf(find_leaf(Op::Index, n.series.level), s.index_slot);
        const auto states = static_cast<std::size_t>(n.series.state_count);
        for (std::size_t c = 0; c < states; ++c) {
            s.state_slots.push_back(fresh());
            bind_leaf(find_leaf(Op::State, state_imm(n.series.level, static_cast<int>(c))),
                      s.state_slots.back());
        }
        s.body_slot = emit(n.args[0]);
        for (std::size_t c = 0; c < states; ++c) s.update_slots.push_back(emit(n.orbit[states + c]));
        contexts_.pop_back();
        for (std::size_t c = 0; c < states; ++c) s.init_slots.push_back(emit(n.orbit[c]));
        if (n.args[1] != no_node) s.tail_a = emit(n.args[1]);
        if (n.args[2] != no_node) s.tail_b = emit(n.args[2]);
        if (n.args[1] != no_node) emit_point_bounds(n, s);
        Instr ins;
        ins.op = n.op;
        ins.series = static_cast<std::uint32_t>(t_.series.size());
        ins.out = fresh();
        t_.series.push_back(s);
        t_.blocks[outer_block].push_back(ins);
        return ins.out;
    }

    // Point-only code of a series (TapeSeries::point_block): nodes not computed by the enclosing
    // blocks go to the capture block, so box evaluation never runs them.
    Slot emit_captured(NodeId id) {
        if (const Slot* known = capture_->memo.find(id)) return *known;
        if (is_series(g_[id].op) || g_[id].op == Op::Index || g_[id].op == Op::State)
            throw std::logic_error("tape: a point bound reads a value its series has not computed");
        const Slot out = emit_op(id, *capture_);
        capture_->memo[id] = out;
        return out;
    }

    void emit_point_bounds(const Node& n, TapeSeries& s) {
        bool needed = false;
        for (std::size_t k = 0; k < 4; ++k) needed |= n.point_tail[k] != n.args[1 + k / 2];
        if (!needed) {
            for (std::size_t k = 0; k < 4; ++k) s.point_tail[k] = k < 2 ? s.tail_a : s.tail_b;
            return;
        }
        s.point_block = static_cast<std::uint32_t>(t_.blocks.size());
        t_.blocks.emplace_back();
        Context capture{-1, s.point_block, {}};
        capture_ = &capture;
        for (std::size_t k = 0; k < 4; ++k)
            if (n.point_tail[k] != no_node) s.point_tail[k] = emit(n.point_tail[k]);
        capture_ = nullptr;
        if (t_.blocks.back().empty()) { // bounds that are constants or already computed
            t_.blocks.pop_back();
            s.point_block = no_block;
        }
    }

    // The series' own index or state (a leaf of the graph, absent when its body does not read it) has
    // the slot the series sets.
    void bind_leaf(NodeId leaf, Slot slot) {
        if (leaf != no_node) contexts_.back().memo[leaf] = slot;
    }

    NodeId find_leaf(Op op, std::int64_t imm) {
        // Index and state nodes are few; a linear scan once per series keeps Graph free of a reverse map.
        for (NodeId i = 0; i < g_.size(); ++i)
            if (g_[i].op == op && g_[i].imm == imm) return i;
        return no_node;
    }

    const Graph& g_;
    Tape& t_;
    std::vector<Context> contexts_;
    Context* capture_ = nullptr;
    SlotMemo const_slots_;
};

} // namespace

std::size_t Tape::instruction_count() const {
    std::size_t n = 0;
    for (const auto& b : blocks) n += b.size();
    return n;
}

Tape build_tape(const Graph& g, NodeId root, int inputs) {
    Tape t;
    t.inputs = inputs;
    t.externals = g.externals;
    t.input_slots.assign(static_cast<std::size_t>(inputs), no_slot);
    t.result = Scheduler(g, t).run(root);
    return t;
}

namespace {

std::string slot_name(Slot s) {
    return s == no_slot ? "-" : fmt::format("%{}", s);
}

std::string interval_text(Interval v) {
    return v.is_thin() ? fmt::format("{}", v.lo) : fmt::format("[{}, {}]", v.lo, v.hi);
}

void print_block(const Tape& t, std::uint32_t b, int indent, std::string& out) {
    const std::string pad(static_cast<std::size_t>(indent), ' ');
    for (const Instr& ins : t.blocks[b]) {
        if (is_series(ins.op)) {
            const TapeSeries& s = t.series[ins.series];
            const std::string end = s.data.end == infinite_end ? "inf" : fmt::format("{}", s.data.end);
            out += fmt::format("{}{} = {} {} in {}..{} {{\n", pad, slot_name(ins.out), op_name(ins.op),
                               slot_name(s.index_slot), s.data.start, end);
            print_block(t, s.block, indent + 2, out);
            out += fmt::format("{}}} term {}", pad, slot_name(s.body_slot));
            for (std::size_t c = 0; c < s.state_slots.size(); ++c)
                out += fmt::format("{} {} = {} then {}", c ? "," : " orbit", slot_name(s.state_slots[c]),
                                   slot_name(s.init_slots[c]), slot_name(s.update_slots[c]));
            if (s.data.end == infinite_end)
                out += fmt::format(" tail ({} + {} i) * {}^i", slot_name(s.tail_a), slot_name(s.tail_b),
                                   interval_text(s.data.gamma));
            for (std::size_t k = 0; k < 2; ++k) {
                const Slot lo = s.point_tail[2 * k], hi = s.point_tail[2 * k + 1];
                if (lo != (k ? s.tail_b : s.tail_a) || hi != lo)
                    out += fmt::format(" point {} in [{}, {}]", k ? "B" : "A", slot_name(lo), slot_name(hi));
            }
            if (s.data.escape.present) out += escape_text(s.data.escape);
            out += "\n";
            if (s.point_block != no_block) {
                out += fmt::format("{}point bounds {{\n", pad);
                print_block(t, s.point_block, indent + 2, out);
                out += fmt::format("{}}}\n", pad);
            }
            continue;
        }
        out += fmt::format("{}{} = {}", pad, slot_name(ins.out), op_name(ins.op));
        for (int i = 0; i < arity(ins.op); ++i)
            out += fmt::format("{} {}", i ? "," : "", slot_name(ins.in[static_cast<std::size_t>(i)]));
        if (ins.op == Op::PowI) out += fmt::format(", {}", ins.imm);
        if (ins.op == Op::External) out += external_text(ins.imm, t.externals);
        out += "\n";
    }
}

} // namespace

std::string print_tape(const Tape& t) {
    std::string out = fmt::format("tape: {} inputs, {} slots, {} instructions\n", t.inputs, t.num_slots,
                                  t.instruction_count());
    for (std::size_t k = 0; k < t.input_slots.size(); ++k)
        if (t.input_slots[k] != no_slot)
            out += fmt::format("{} = input {}\n", slot_name(t.input_slots[k]), k);
    for (const TapeConst& c : t.constants)
        out += fmt::format("{} = const {}\n", slot_name(c.slot), interval_text(c.value));
    print_block(t, 0, 0, out);
    out += fmt::format("result {}\n", slot_name(t.result));
    return out;
}

namespace {

std::string verify_block(const Tape& t, std::uint32_t b, std::vector<bool>& written) {
    for (const Instr& ins : t.blocks[b]) {
        const int k = is_series(ins.op) ? 0 : arity(ins.op);
        for (int i = 0; i < k; ++i) {
            const Slot s = ins.in[static_cast<std::size_t>(i)];
            if (s >= t.num_slots || !written[s])
                return fmt::format("block {}: {} reads {} before it is written", b, op_name(ins.op),
                                   slot_name(s));
        }
        if (ins.op == Op::External &&
            (ins.imm < 0 || static_cast<std::size_t>(ins.imm) >= t.externals.size()))
            return fmt::format("block {}: external #{} out of range", b, ins.imm);
        if (is_series(ins.op)) {
            if (ins.series >= t.series.size()) return fmt::format("block {}: bad series index", b);
            const TapeSeries& s = t.series[ins.series];
            if (s.block <= b || s.block >= t.blocks.size())
                return fmt::format("series block {} out of order", s.block);
            if (s.index_slot >= t.num_slots) return "series index slot out of range";
            written[s.index_slot] = true;
            if (s.init_slots.size() != s.state_slots.size() || s.update_slots.size() != s.state_slots.size())
                return "orbit slots of different sizes";
            for (Slot i : s.init_slots)
                if (i >= t.num_slots || !written[i]) return "orbit initial point not written";
            for (Slot st : s.state_slots) {
                if (st >= t.num_slots || written[st]) return "orbit state slot written twice";
                written[st] = true;
            }
            if (auto e = verify_block(t, s.block, written); !e.empty()) return e;
            for (Slot u : s.update_slots)
                if (u >= t.num_slots || !written[u]) return "orbit map not written";
            if (s.body_slot >= t.num_slots || !written[s.body_slot]) return "series term slot not written";
            if (s.data.end == infinite_end) {
                if (s.tail_a == no_slot || !written[s.tail_a])
                    return "infinite series without tail coefficient";
                if (s.tail_b != no_slot && !written[s.tail_b]) return "series tail coefficient not written";
                if (s.point_block != no_block) {
                    if (s.point_block <= s.block || s.point_block >= t.blocks.size())
                        return fmt::format("series point block {} out of order", s.point_block);
                    if (auto e = verify_block(t, s.point_block, written); !e.empty()) return e;
                }
                for (const Slot p : s.point_tail)
                    if (p != no_slot && (p >= t.num_slots || !written[p]))
                        return "series point bound of the tail not written";
                if (!(s.data.gamma.lo > 0 && s.data.gamma.hi < 1))
                    return "infinite series without decay in (0, 1)";
            }
        }
        if (ins.out >= t.num_slots || written[ins.out])
            return fmt::format("block {}: slot {} written twice or out of range", b, slot_name(ins.out));
        written[ins.out] = true;
    }
    return {};
}

} // namespace

std::string verify_tape(const Tape& t) {
    if (t.blocks.empty()) return "tape without main block";
    std::vector<bool> written(t.num_slots, false);
    for (const TapeConst& c : t.constants) {
        if (c.slot >= t.num_slots) return "constant slot out of range";
        written[c.slot] = true;
    }
    for (Slot s : t.input_slots)
        if (s != no_slot) written[s] = true;
    if (auto e = verify_block(t, 0, written); !e.empty()) return e;
    if (t.result >= t.num_slots || !written[t.result]) return "result slot not written";
    return {};
}

} // namespace frac::ir
