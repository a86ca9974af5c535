#include "ir/specialize.hpp"

#include "ir/semantics.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace frac::ir {

bool has_choices(const Tape& tape) {
    if (tape.blocks.empty()) return false;
    for (const Instr& ins : tape.blocks[0])
        if (is_choice(ins.op)) return true;
    return false;
}

namespace {

// What the emptiness analysis knows of a slot on every sub-box of the recorded box (and every term).
struct SlotFacts {
    bool may_empty = false; // its enclosure can be empty on some sub-box
    bool nonneg = false;    // lo >= 0 always
    bool positive = false;  // lo >= 0 and hi > 0 always: never [0, 0]
};

bool contains_zero(Interval v) {
    return v.lo <= 0 && 0 <= v.hi;
}

// Forward analysis of the tape: which slots can become empty on a sub-box. Block-0 values are
// known (the recorded enclosures, which bound the sub-boxes' ones); values computed per series term
// are not, so there only the operations that produce them count.
class EmptinessAnalysis {
public:
    EmptinessAnalysis(const Tape& t, const Interval* slots) : t_(t), v_(slots), f_(scratch()) {
        f_.assign(t.num_slots, SlotFacts{});
        for (const TapeConst& c : t.constants)
            f_[c.slot] = {false, c.value.lo >= 0, c.value.lo >= 0 && c.value.hi > 0};
        for (Slot s : t.input_slots)
            if (s != no_slot) known_fact(s);
        block(0, true);
    }

    bool may_empty(Slot s) const { return f_[s].may_empty; }

private:
    void known_fact(Slot s) {
        const Interval v = v_[s];
        f_[s] = {v.is_empty(), !v.is_empty() && v.lo >= 0, !v.is_empty() && v.lo > 0};
    }

    // Whether `op` is defined on every sub-box, from what is known of its operands: their recorded
    // enclosures in block 0, the facts of their operations per series term.
    bool defined(const Instr& ins, bool known) const {
        if (known)
            return defined_over_box(ins.op, v_[ins.in[0]], arity(ins.op) > 1 ? v_[ins.in[1]] : Interval(),
                                    ins.imm);
        const SlotFacts& a = f_[ins.in[0]];
        switch (ins.op) {
        case Op::Div: return f_[ins.in[1]].positive;
        case Op::Sqrt: return a.nonneg;
        case Op::Log:
        case Op::Pow: return a.positive;
        case Op::PowI: return ins.imm >= 0 || a.positive;
        default: return true;
        }
    }

    // Facts of an operation's result computed per term (unknown value).
    SlotFacts static_facts(const Instr& ins) const {
        const auto fact = [&](int i) { return f_[ins.in[static_cast<std::size_t>(i)]]; };
        SlotFacts r;
        switch (ins.op) {
        case Op::Exp: r.nonneg = r.positive = true; break;
        case Op::Pow:
        case Op::PowI: r.nonneg = r.positive = fact(0).positive; break;
        case Op::Sqrt: r.nonneg = true, r.positive = fact(0).positive; break;
        case Op::Mul:
        case Op::Add:
        case Op::Div:
            r.nonneg = fact(0).nonneg && fact(1).nonneg;
            r.positive = fact(0).positive && fact(1).positive;
            break;
        case Op::Sqr:
        case Op::Abs:
        case Op::Dz:
        case Op::Mod1: r.nonneg = true; break;
        default: break;
        }
        return r;
    }

    void block(std::uint32_t b, bool known) {
        for (const Instr& ins : t_.blocks[b]) {
            if (is_series(ins.op)) {
                series(t_.series[ins.series], ins.out, known);
                continue;
            }
            bool operand_empty = false;
            for (int i = 0; i < arity(ins.op); ++i)
                operand_empty |= f_[ins.in[static_cast<std::size_t>(i)]].may_empty;
            const bool may_empty = operand_empty || !defined(ins, known);
            if (known) {
                known_fact(ins.out);
                f_[ins.out].may_empty = may_empty;
            } else {
                f_[ins.out] = static_facts(ins);
                f_[ins.out].may_empty = may_empty;
            }
        }
    }

    void series(const TapeSeries& s, Slot out, bool known) {
        f_[s.index_slot] = {false, s.data.start >= 0, s.data.start >= 1};
        bool empty = false;
        for (std::size_t c = 0; c < s.state_slots.size(); ++c) {
            f_[s.state_slots[c]] = {f_[s.init_slots[c]].may_empty, false, false};
            empty |= f_[s.init_slots[c]].may_empty;
        }
        block(s.block, false);
        for (const Instr& ins : t_.blocks[s.block]) empty |= f_[ins.out].may_empty;
        for (Slot u : s.update_slots) empty |= f_[u].may_empty;
        empty |= f_[s.body_slot].may_empty;
        if (s.tail_a != no_slot) empty |= f_[s.tail_a].may_empty;
        if (s.tail_b != no_slot) empty |= f_[s.tail_b].may_empty;
        f_[out] = {empty, false, false};
        if (known && v_[out].is_empty()) f_[out].may_empty = true;
    }

    // Reused by the thread's analyses (one per tape push: allocations would cost as much as the work).
    static std::vector<SlotFacts>& scratch() {
        thread_local std::vector<SlotFacts> facts;
        return facts;
    }

    const Tape& t_;
    const Interval* v_;
    std::vector<SlotFacts>& f_;
};

} // namespace

bool defined_over_box(Op op, Interval a, Interval b, std::int64_t imm) {
    switch (op) {
    case Op::Div: return !contains_zero(b);
    case Op::Sqrt: return a.lo >= 0;
    case Op::Log:
    case Op::Pow: return a.lo > 0;
    case Op::PowI: return imm >= 0 || !contains_zero(a);
    default: return true;
    }
}

std::vector<Choice> record_choices(const Tape& tape, const Interval* slots) {
    const std::vector<Instr>& main = tape.blocks.at(0);
    std::vector<Choice> choices(main.size(), Choice::both);
    if (!has_choices(tape)) return choices;
    const EmptinessAnalysis facts(tape, slots);
    for (std::size_t k = 0; k < main.size(); ++k) {
        const Instr& ins = main[k];
        if (!is_choice(ins.op)) continue;
        choices[k] = decide_choice(ins.op, slots[ins.in[0]], slots[ins.in[1]], facts.may_empty(ins.in[0]),
                                   facts.may_empty(ins.in[1]));
    }
    return choices;
}

bool any_decided(const std::vector<Choice>& choices) {
    for (Choice c : choices)
        if (c != Choice::both) return true;
    return false;
}

namespace {

// The cost (tape_cost) of the instructions of block b, and of the series blocks it runs, that `keep`.
template <class Keep>
double cost_of(const Tape& t, std::uint32_t b, const Keep& keep) {
    double c = 0;
    for (const Instr& ins : t.blocks[b]) {
        if (!keep(ins)) continue;
        c += 1;
        // An external function (a branch and bound over an automaton) costs far more than an operation:
        // pruning it away is worth a compilation sooner.
        if (ins.op == Op::External) c += 100;
        if (is_series(ins.op)) c += series_terms_estimate * cost_of(t, t.series[ins.series].block, keep);
    }
    return c;
}

// Builds the pruned tape: slot aliases for the decided choices, liveness from the result, then a
// copy of the live code with slots numbered in program order.
class Pruner {
public:
    Pruner(const Tape& t, const std::vector<Choice>& choices)
        : t_(t), alias_(scratch().alias), def_(scratch().def), used_(scratch().used),
          renumber_(scratch().renumber) {
        alias_.resize(t.num_slots);
        def_.assign(t.num_slots, nullptr);
        used_.assign(t.num_slots, 0);
        for (Slot s = 0; s < t.num_slots; ++s) alias_[s] = s;
        for (std::size_t k = 0; k < t.blocks[0].size(); ++k) {
            const Instr& ins = t.blocks[0][k];
            if (choices[k] == Choice::both || !is_choice(ins.op)) continue;
            const std::size_t pick = (ins.op == Op::Select ? 1 : 0) + (choices[k] == Choice::second ? 1 : 0);
            alias_[ins.out] = alias_[ins.in[pick]]; // operands precede: their aliases are final
        }
        for (const auto& blk : t.blocks)
            for (const Instr& ins : blk) def_[ins.out] = &ins;
    }

    Tape run(double max_cost) {
        mark(map(t_.result));
        if (max_cost < std::numeric_limits<double>::infinity() && cost_of(t_, 0, [this](const Instr& ins) {
                                                                      return live_slot(ins.out) &&
                                                                             alias_[ins.out] == ins.out;
                                                                  }) > max_cost)
            return {};
        Tape out;
        out.inputs = t_.inputs;
        out.externals = t_.externals;
        renumber_.assign(t_.num_slots, no_slot);
        for (const TapeConst& c : t_.constants)
            if (live_slot(c.slot)) out.constants.push_back({fresh(c.slot, out), c.value, c.point});
        out.input_slots.assign(t_.input_slots.size(), no_slot);
        for (std::size_t k = 0; k < t_.input_slots.size(); ++k)
            if (t_.input_slots[k] != no_slot && live_slot(t_.input_slots[k]))
                out.input_slots[k] = fresh(t_.input_slots[k], out);
        out.blocks.emplace_back();
        copy_block(0, 0, out);
        out.result = renumber_[map(t_.result)];
        return out;
    }

private:
    Slot map(Slot s) const { return s == no_slot ? no_slot : alias_[s]; }

    bool live_slot(Slot s) const { return used_[s] != 0; }

    // Marks `s` needed, and with it the code computing it (an explicit stack: tapes can be deep).
    void mark(Slot root) {
        std::vector<Slot> todo{root};
        while (!todo.empty()) {
            const Slot s = todo.back();
            todo.pop_back();
            if (s == no_slot || used_[s]) continue;
            used_[s] = 1;
            const Instr* ins = def_[s];
            if (!ins) continue; // a constant, an input, a series index or orbit state
            if (!is_series(ins->op)) {
                for (int i = 0; i < arity(ins->op); ++i)
                    todo.push_back(map(ins->in[static_cast<std::size_t>(i)]));
                continue;
            }
            const TapeSeries& ser = t_.series[ins->series];
            todo.push_back(map(ser.body_slot));
            todo.push_back(map(ser.tail_a));
            todo.push_back(map(ser.tail_b));
            for (Slot u : ser.update_slots) todo.push_back(map(u));
            for (Slot i : ser.init_slots) todo.push_back(map(i));
        }
    }

    Slot fresh(Slot old, Tape& out) {
        renumber_[old] = out.num_slots;
        return out.num_slots++;
    }
    Slot get(Slot old) const {
        if (old == no_slot) return no_slot;
        const Slot s = renumber_[map(old)];
        if (s == no_slot) throw std::logic_error("specialize: a live slot read before it is written");
        return s;
    }

    void copy_block(std::uint32_t from, std::uint32_t to, Tape& out) {
        for (const Instr& ins : t_.blocks[from]) {
            if (!live_slot(ins.out) || alias_[ins.out] != ins.out) continue;
            Instr n = ins;
            if (is_series(ins.op)) {
                n.series = copy_series(t_.series[ins.series], out);
            } else {
                for (int i = 0; i < arity(ins.op); ++i)
                    n.in[static_cast<std::size_t>(i)] = get(ins.in[static_cast<std::size_t>(i)]);
            }
            n.out = fresh(ins.out, out);
            out.blocks[to].push_back(n);
        }
    }

    std::uint32_t copy_series(const TapeSeries& s, Tape& out) {
        TapeSeries n;
        n.kind = s.kind;
        n.data = s.data;
        n.block = static_cast<std::uint32_t>(out.blocks.size());
        out.blocks.emplace_back();
        n.index_slot = fresh(s.index_slot, out);
        for (Slot st : s.state_slots) n.state_slots.push_back(fresh(st, out));
        for (Slot i : s.init_slots) n.init_slots.push_back(get(i));
        copy_block(s.block, n.block, out);
        n.body_slot = get(s.body_slot);
        for (Slot u : s.update_slots) n.update_slots.push_back(get(u));
        n.tail_a = get(s.tail_a);
        n.tail_b = get(s.tail_b);
        // A specialised tape serves boxes: the point bounds of the tail (point-only code) are dropped.
        out.series.push_back(n);
        return static_cast<std::uint32_t>(out.series.size() - 1);
    }

    // Reused by the thread's pruners (one per tape push: allocations would cost as much as the work).
    struct Scratch {
        std::vector<Slot> alias;
        std::vector<const Instr*> def;
        std::vector<char> used;
        std::vector<Slot> renumber;
    };
    static Scratch& scratch() {
        thread_local Scratch s;
        return s;
    }

    const Tape& t_;
    std::vector<Slot>& alias_;
    std::vector<const Instr*>& def_;
    std::vector<char>& used_; // by slot: needed for the result
    std::vector<Slot>& renumber_;
};

} // namespace

Tape specialize(const Tape& tape, const std::vector<Choice>& choices, double max_cost) {
    if (tape.blocks.empty() || choices.size() != tape.blocks[0].size())
        throw std::invalid_argument("specialize: one choice per instruction of block 0 is needed");
    return Pruner(tape, choices).run(max_cost);
}

namespace {

template <class T>
void put(std::string& s, const T& v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    s.append(b, sizeof(T));
}

void put_interval(std::string& s, Interval v) {
    put(s, v.lo);
    put(s, v.hi);
}

} // namespace

std::string tape_key(const Tape& t) {
    std::string s;
    put(s, t.inputs);
    put(s, t.num_slots);
    put(s, t.result);
    for (const TapeConst& c : t.constants) {
        put(s, c.slot);
        put_interval(s, c.value);
        put(s, c.point);
    }
    for (Slot i : t.input_slots) put(s, i);
    for (const auto& f : t.externals)
        put(s, reinterpret_cast<std::uintptr_t>(f.get())); // bound implementations
    for (const auto& b : t.blocks) {
        put(s, b.size());
        for (const Instr& ins : b) {
            put(s, ins.op);
            put(s, ins.out);
            put(s, ins.in);
            put(s, ins.imm);
            put(s, ins.series);
        }
    }
    for (const TapeSeries& ser : t.series) {
        put(s, ser.kind);
        put(s, ser.data.level);
        put(s, ser.data.start);
        put(s, ser.data.end);
        put_interval(s, ser.data.gamma);
        put(s, ser.data.state_count);
        put(s, ser.block);
        put(s, ser.index_slot);
        put(s, ser.body_slot);
        put(s, ser.tail_a);
        put(s, ser.tail_b);
        put(s, ser.point_block);
        for (Slot x : ser.point_tail) put(s, x);
        for (const auto* v : {&ser.state_slots, &ser.init_slots, &ser.update_slots}) {
            put(s, v->size());
            for (Slot x : *v) put(s, x);
        }
    }
    return s;
}

double tape_cost(const Tape& tape) {
    return tape.blocks.empty() ? 0 : cost_of(tape, 0, [](const Instr&) { return true; });
}

double push_max_cost(double cost_current, double expected_evaluations) {
    return std::nextafter(cost_current, 0.0) -
           push_build_evaluations * cost_current / std::max(expected_evaluations, 1e-300);
}

std::size_t SpecializationCache::size() const {
    std::lock_guard<std::mutex> lock(mu_);
    return compiled_count_;
}

bool SpecializationCache::may_pay(double cost_current, double expected_evaluations, double record_ns) const {
    const double own = eval_ns(costs_, cost_current);
    double best = expected_evaluations * costs_.eval_ns_per_cost * cost_current - costs_.compile_ns_fixed;
    if (fallback_ && fallback_eval_ns_)
        best = std::max(best, expected_evaluations * (own - fallback_ns_fixed_));
    std::lock_guard<std::mutex> lock(mu_);
    if (compiled_count_ > 0)
        best = std::max(best, expected_evaluations * costs_.eval_ns_per_cost * cost_current);
    return best > record_ns;
}

std::shared_ptr<Evaluator> SpecializationCache::get(const Tape& current, const std::vector<Choice>& choices,
                                                    double expected_evaluations, SpecializeStats& stats) {
    if (!any_decided(choices)) {
        ++stats.unpruned;
        return nullptr;
    }
    const auto t0 = std::chrono::steady_clock::now();
    Tape pruned = specialize(current, choices);
    const double before = tape_cost(current), after = tape_cost(pruned);
    std::string key = after > max_cost_ratio * before ? std::string() : tape_key(pruned);
    stats.prune_ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (key.empty()) {
        ++stats.too_little;
        return nullptr;
    }
    std::lock_guard<std::mutex> lock(mu_);
    auto found = entries_.find(key);
    if (found == entries_.end()) {
        if (entries_.size() >= max_specializations) {
            ++stats.declined;
            return nullptr;
        }
        found = entries_.emplace(std::move(key), Entry{}).first;
    }
    Entry& entry = found->second;
    if (entry.compiled) {
        ++stats.hits;
        return entry.compiled;
    }
    entry.demand += expected_evaluations;
    const double saved_ns = entry.demand * costs_.eval_ns_per_cost * (before - after);
    const double compile_ns = costs_.compile_ns_fixed + costs_.compile_ns_per_instruction *
                                                            static_cast<double>(pruned.instruction_count());
    if (saved_ns >= compile_ns) {
        const auto t1 = std::chrono::steady_clock::now();
        entry.compiled = compile_(pruned);
        stats.compile_ms +=
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count();
        ++stats.compiled;
        ++compiled_count_;
        entry.fallback.reset();
        return entry.compiled;
    }
    if (fallback_ && fallback_eval_ns_ && fallback_eval_ns_(pruned) < eval_ns(costs_, before)) {
        if (entry.fallback) {
            ++stats.hits;
        } else {
            entry.fallback = fallback_(pruned);
            ++stats.fallbacks;
        }
        return entry.fallback;
    }
    ++stats.declined;
    return nullptr;
}

} // namespace frac::ir
