#include "backend/llvm/tables.hpp"

#include "ir/semantics.hpp"
#include "ir/series_tail.hpp"

#include <cfenv>
#include <cmath>
#include <functional>
#include <stdexcept>

namespace frac::jit {

using ir::Instr;
using ir::Op;
using ir::Slot;
using ir::Tape;
using ir::TapeSeries;

Facts facts_of(const Interval* v, std::size_t n) {
    Facts f;
    f.maybe_empty = false;
    f.lo_positive = f.hi_negative = f.lo_nonzero = f.hi_nonzero = f.thin = f.finite = true;
    for (std::size_t k = 0; k < n; ++k) {
        const Interval& x = v[k];
        if (x.is_empty()) f.maybe_empty = true;
        if (!(std::isfinite(x.lo) && std::isfinite(x.hi))) f.finite = false;
        if (!(x.lo == x.hi)) f.thin = false;
        if (!(x.lo > 0)) f.lo_positive = false;
        if (!(x.hi < 0)) f.hi_negative = false;
        if (x.lo == 0) f.lo_nonzero = false;
        if (x.hi == 0) f.hi_nonzero = false;
    }
    if (f.maybe_empty) f.lo_positive = f.hi_negative = f.thin = f.finite = false;
    return f;
}

namespace {

// Round to nearest for the point tables, whatever mode the caller left.
class NearestRounding {
public:
    NearestRounding() : saved_(std::fegetround()) { std::fesetround(FE_TONEAREST); }
    ~NearestRounding() { std::fesetround(saved_); }
    NearestRounding(const NearestRounding&) = delete;
    NearestRounding& operator=(const NearestRounding&) = delete;

private:
    int saved_;
};

std::int64_t last_index(const TapeSeries& s, const ir::EvalOptions& o) {
    return s.data.end == ir::infinite_end ? s.data.start + o.max_terms - 1 : s.data.end;
}

void series_tables(const Tape& t, const TapeSeries& s, const ir::EvalOptions& o,
                   const std::vector<bool>& is_const, const std::vector<Interval>& const_box,
                   SeriesTables& out) {
    out.infinite = s.data.end == ir::infinite_end;
    out.first = s.data.start;
    out.last = last_index(s, o);
    if (!out.infinite) return;
    const bool has_b = s.tail_b != ir::no_slot;
    const Interval gamma = s.data.gamma;
    const auto n_entries = static_cast<std::size_t>(out.last - out.first + 1);
    out.const_tail = is_const[s.tail_a] && (!has_b || is_const[s.tail_b]);
    {
        NearestRounding nearest;
        // The interpreter: pow(gamma, start + 1), then *= gamma; denominator (1 - gamma) * (1 - gamma).
        const double g = gamma.hi;
        out.point_gamma_next = std::pow(g, static_cast<double>(s.data.start + 1));
        out.point_denominator = (1.0 - g) * (1.0 - g);
    }
    num::UpwardRounding up;
    Interval gamma_i = num::powi(gamma, s.data.start);
    if (out.const_tail) {
        const Interval a = const_box[s.tail_a];
        const Interval b = has_b ? const_box[s.tail_b] : Interval(0.0);
        out.threshold.resize(n_entries);
        out.tail.resize(n_entries);
        out.tail_width.resize(n_entries);
        for (std::size_t k = 0; k < n_entries; ++k) {
            const std::int64_t i = out.first + static_cast<std::int64_t>(k);
            const Interval bound = ir::series_term_bound(a, b, has_b, gamma_i, i);
            out.threshold[k] = ir::term_resolution * num::width(bound);
            out.tail[k] = ir::series_tail(s.kind, a, b, has_b, gamma, i);
            out.tail_width[k] = num::width(out.tail[k]);
            gamma_i = num::mul(gamma_i, gamma);
        }
        return;
    }
    out.gamma_n.resize(n_entries);
    for (std::size_t k = 0; k < n_entries; ++k) {
        out.gamma_n[k] = gamma_i;
        gamma_i = num::mul(gamma_i, gamma);
    }
}

// Which slots hold finite intervals wherever they are written: a greatest fixed point (every written
// slot starts finite and loses it at any write that does not prove it), an inductive invariant over
// the evaluation order. Inputs (boxes may be unbounded), series results, states and indices: not
// finite; constants and index tables: their exact facts. Provably finite: dz and mod1 of a non-empty
// interval (within [0, 1]), floor, ceil, neg and abs of a finite one, min and max of two.
void finite_facts(const Tape& t, Tables& out) {
    std::vector<Facts>& f = out.slot_facts;
    std::vector<bool> fixed(t.num_slots, false); // facts set outright: constants, index tables
    for (const ir::TapeConst& c : t.constants) fixed[c.slot] = true;
    for (const IndexTable& tab : out.index_tables) fixed[tab.slot] = true;
    std::vector<bool> written(t.num_slots, false);
    std::function<void(std::uint32_t)> mark = [&](std::uint32_t block) {
        for (const Instr& ins : t.blocks[block]) {
            if (ir::is_series(ins.op)) mark(t.series[ins.series].block);
            if (!fixed[ins.out]) written[ins.out] = true;
        }
    };
    mark(0);
    for (Slot s = 0; s < t.num_slots; ++s)
        if (!fixed[s]) f[s].finite = written[s];
    for (const TapeSeries& s : t.series) {
        for (Slot c : s.state_slots) f[c].finite = false;
        f[s.index_slot].finite = false;
    }
    bool changed = true;
    auto proves = [&](const Instr& ins) {
        auto in = [&](int k) { return f[ins.in[static_cast<std::size_t>(k)]]; };
        switch (ins.op) {
        case Op::Dz:
        case Op::Mod1: return !in(0).maybe_empty;
        case Op::Floor:
        case Op::Ceil:
        case Op::Neg:
        case Op::Abs: return in(0).finite;
        case Op::Min:
        case Op::Max: return in(0).finite && in(1).finite;
        default: return false;
        }
    };
    std::function<void(std::uint32_t)> walk = [&](std::uint32_t block) {
        for (const Instr& ins : t.blocks[block]) {
            if (ir::is_series(ins.op)) walk(t.series[ins.series].block);
            if (fixed[ins.out] || !f[ins.out].finite) continue;
            if (ir::is_series(ins.op) || !proves(ins)) {
                f[ins.out].finite = false;
                changed = true;
            }
        }
    };
    while (changed) {
        changed = false;
        walk(0);
    }
}

// Fixed point of maybe_empty over the tape (orbit states feed back, so one pass is not enough).
void analyse(const Tape& t, Tables& out) {
    std::vector<Facts>& f = out.slot_facts;
    bool changed = true;
    auto set = [&](Slot s, bool me) {
        if (me && !f[s].maybe_empty) {
            f[s].maybe_empty = true;
            changed = true;
        }
    };
    // Walks a block; slots not yet seen stay "not empty" until an iteration proves otherwise.
    std::function<void(std::uint32_t)> walk = [&](std::uint32_t block) {
        for (const Instr& ins : t.blocks[block]) {
            if (ir::is_series(ins.op)) {
                const TapeSeries& s = t.series[ins.series];
                for (std::size_t c = 0; c < s.state_slots.size(); ++c)
                    set(s.state_slots[c], f[s.init_slots[c]].maybe_empty || f[s.update_slots[c]].maybe_empty);
                walk(s.block);
                set(ins.out, true); // the tail may be one-sided or empty: not worth proving
                continue;
            }
            if (out.slot_table[ins.out] >= 0) continue; // an index table: its facts are exact
            bool in[3] = {false, false, false};
            for (int k = 0; k < ir::arity(ins.op); ++k)
                in[k] = f[ins.in[static_cast<std::size_t>(k)]].maybe_empty;
            const Facts divisor = ins.op == Op::Div ? f[ins.in[1]] : Facts{};
            set(ins.out, may_be_empty(ins.op, in, ins.imm, divisor));
        }
    };
    while (changed) {
        changed = false;
        walk(0);
    }
    finite_facts(t, out);
}

} // namespace

bool may_be_empty(Op op, const bool* in, std::int64_t imm, const Facts& divisor) {
    switch (op) {
    // Non-empty operands give a non-empty result (interval.cpp).
    case Op::Add:
    case Op::Sub:
    case Op::Mul:
    case Op::Min:
    case Op::Max:
    case Op::Atan2:
    case Op::Lt:
    case Op::Le:
    case Op::Gt:
    case Op::Ge:
    case Op::Eq:
    case Op::Ne:
    case Op::And:
    case Op::Or: return in[0] || in[1];
    case Op::Neg:
    case Op::Sqr:
    case Op::Abs:
    case Op::Floor:
    case Op::Ceil:
    case Op::Mod1:
    case Op::Dz:
    case Op::Sin:
    case Op::Cos:
    case Op::Tan:
    case Op::Exp:
    case Op::Not: return in[0];
    case Op::Select:
    case Op::External: return in[0] || in[1] || in[2]; // AttractorDistanceFunction: empty on empty only
    case Op::PowI:
        return imm < 0 || in[0]; // 1 / 0^n is empty
    // A divisor of known sign cannot be [0, 0].
    case Op::Div: return in[0] || !(divisor.lo_positive || divisor.hi_negative);
    // Outside the domain: empty.
    case Op::Pow:
    case Op::Sqrt:
    case Op::Log: return true;
#include "ir/non_operation_cases.def"
        break;
    }
    return true;
}

Tables build_tables(const Tape& t, const ir::EvalOptions& o) {
    Tables out;
    out.slot_table.assign(t.num_slots, -1);
    std::vector<bool> is_const(t.num_slots, false);
    std::vector<Interval> const_box(t.num_slots);
    std::vector<double> const_point(t.num_slots, 0.0);
    for (const ir::TapeConst& c : t.constants) {
        is_const[c.slot] = true;
        const_box[c.slot] = c.value;
        const_point[c.slot] = c.point;
    }
    out.series.resize(t.series.size());
    for (std::size_t si = 0; si < t.series.size(); ++si) {
        const TapeSeries& s = t.series[si];
        series_tables(t, s, o, is_const, const_box, out.series[si]);

        // Index tables: instructions of this block that read only constants, the index and each other.
        const std::int64_t first = s.data.start, last = last_index(s, o);
        if (last < first || last - first + 1 > max_index_table) continue;
        const auto n_entries = static_cast<std::size_t>(last - first + 1);
        std::vector<bool> index_only(t.num_slots, false);
        std::vector<const Instr*> chosen;
        for (const Instr& ins : t.blocks[s.block]) {
            if (ir::is_series(ins.op)) continue;
            bool ok = ins.op != Op::External; // computed by the runtime: never tabulated at compile time
            for (int k = 0; k < ir::arity(ins.op); ++k) {
                const Slot in = ins.in[static_cast<std::size_t>(k)];
                if (!(is_const[in] || in == s.index_slot || index_only[in])) ok = false;
            }
            if (!ok) continue;
            index_only[ins.out] = true;
            chosen.push_back(&ins);
        }
        if (chosen.empty()) continue;
        // Evaluate the chosen instructions for every index, in tape order.
        std::vector<Interval> box(const_box);
        std::vector<double> point(const_point);
        const std::size_t base = out.index_tables.size();
        for (const Instr* ins : chosen) {
            out.slot_table[ins->out] = static_cast<int>(out.index_tables.size());
            IndexTable tab;
            tab.slot = ins->out;
            tab.series = static_cast<std::uint32_t>(si);
            tab.box.resize(n_entries);
            tab.point.resize(n_entries);
            out.index_tables.push_back(std::move(tab));
        }
        {
            num::UpwardRounding up;
            for (std::size_t k = 0; k < n_entries; ++k) {
                box[s.index_slot] = Interval(static_cast<double>(first + static_cast<std::int64_t>(k)));
                for (std::size_t c = 0; c < chosen.size(); ++c) {
                    const Instr& ins = *chosen[c];
                    Interval args[3];
                    for (int a = 0; a < ir::arity(ins.op); ++a)
                        args[a] = box[ins.in[static_cast<std::size_t>(a)]];
                    box[ins.out] = ir::apply_interval(ins.op, args, ins.imm);
                    out.index_tables[base + c].box[k] = box[ins.out];
                }
            }
        }
        {
            NearestRounding nearest;
            for (std::size_t k = 0; k < n_entries; ++k) {
                point[s.index_slot] = static_cast<double>(first + static_cast<std::int64_t>(k));
                for (std::size_t c = 0; c < chosen.size(); ++c) {
                    const Instr& ins = *chosen[c];
                    double args[3];
                    for (int a = 0; a < ir::arity(ins.op); ++a)
                        args[a] = point[ins.in[static_cast<std::size_t>(a)]];
                    point[ins.out] = ir::apply_point(ins.op, args, ins.imm);
                    out.index_tables[base + c].point[k] = point[ins.out];
                }
            }
        }
        for (std::size_t c = 0; c < chosen.size(); ++c) {
            IndexTable& tab = out.index_tables[base + c];
            tab.facts = facts_of(tab.box.data(), tab.box.size());
        }
    }
    // Facts of every slot: constants and index tables exactly, inputs and indices not empty, the rest
    // from the fixed point.
    out.slot_facts.assign(t.num_slots, Facts{});
    for (Facts& f : out.slot_facts) f.maybe_empty = false;
    for (const ir::TapeConst& c : t.constants) out.slot_facts[c.slot] = facts_of(&c.value, 1);
    for (const IndexTable& tab : out.index_tables) out.slot_facts[tab.slot] = tab.facts;
    analyse(t, out);
    return out;
}

} // namespace frac::jit
