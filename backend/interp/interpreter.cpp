#include "backend/interp/interpreter.hpp"

#include "backend/interp/flat_interpreter.hpp"

#include "ir/semantics.hpp"
#include "ir/series_tail.hpp"

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

namespace frac::interp {

using ir::Instr;
using ir::Interval;
using ir::Op;
using ir::Tape;
using ir::TapeSeries;

namespace {

class Interpreter final : public ir::Evaluator {
public:
    Interpreter(Tape tape, const ir::EvalOptions& options)
        : tape_(std::move(tape)), options_(options), has_choices_(ir::has_choices(tape_)),
          cost_(ir::tape_cost(tape_)), boxes_(tape_.num_slots) {
        if (options_.max_terms < 1 || options_.max_terms > ir::max_terms_limit)
            throw std::invalid_argument("max_terms out of range");
        for (const ir::TapeConst& c : tape_.constants) boxes_[c.slot] = c.value;
    }

    int dimension() const override { return tape_.inputs; }
    std::string engine() const override { return "interp"; }
    std::unique_ptr<ir::Evaluator> clone() const override {
        return std::make_unique<Interpreter>(tape_, options_);
    }
    std::size_t instruction_count() const override { return tape_.instruction_count(); }

    // The interpreter records choices in its own register file: after eval_box it holds every
    // block-0 value of the box.
    std::vector<ir::Choice> record(const Interval* box) {
        const ir::EvalStats saved = stats;
        eval_box(box);
        stats = saved; // a recording is not an evaluation of the shape
        return ir::record_choices(tape_, boxes_.data());
    }

    bool may_specialize() const override { return options_.prune && has_choices_; }
    bool specializes_independently() const override { return true; } // a tape push, no cache
    std::shared_ptr<ir::Evaluator> specialize(const Interval* box, double expected_evaluations) override {
        return push(box, expected_evaluations, false);
    }
    // The register file holds the values of the last box evaluated: no second evaluation.
    std::size_t kept_evaluations() const override { return 1; }
    std::shared_ptr<ir::Evaluator> specialize_after_eval(std::size_t k, const Interval* box,
                                                         double expected_evaluations) override {
        return push(box, expected_evaluations, k == 0 && evaluated_boxes_ == 1);
    }

    // A tape push: the pruned tape of the box, made for this cell's descendants alone (no cache: a
    // tape copy costs about what looking it up would). It prunes its own sub-boxes in turn, so tapes
    // shrink down the tree. `evaluated`: the register file holds the box's values already.
    std::shared_ptr<ir::Evaluator> push(const Interval* box, double expected_evaluations, bool evaluated) {
        if (!options_.prune || !has_choices_ || expected_evaluations <= interp_min_expected_evaluations)
            return nullptr;
        const auto t0 = std::chrono::steady_clock::now();
        const std::vector<ir::Choice> choices =
            evaluated ? ir::record_choices(tape_, boxes_.data()) : record(box);
        const auto t1 = std::chrono::steady_clock::now();
        specialize_stats.record_ms += std::chrono::duration<double, std::milli>(t1 - t0).count();
        ++specialize_stats.requests;
        if (!ir::any_decided(choices)) {
            ++specialize_stats.unpruned;
            return nullptr;
        }
        ir::Tape pruned = ir::specialize(tape_, choices, ir::push_max_cost(cost_, expected_evaluations));
        std::shared_ptr<ir::Evaluator> result;
        if (!pruned.blocks.empty()) {
            result = std::make_shared<Interpreter>(std::move(pruned), options_);
            ++specialize_stats.pushes;
        } else {
            ++specialize_stats.too_little;
        }
        specialize_stats.prune_ms +=
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count();
        return result;
    }

    double eval_point(const double* coords) override {
        if (points_.empty() && tape_.num_slots > 0) { // made on first use: pruned tapes serve boxes only
            points_.resize(tape_.num_slots);
            for (const ir::TapeConst& c : tape_.constants) points_[c.slot] = c.point;
        }
        ++stats.calls;
        load(points_, coords);
        run_points(0);
        return points_[tape_.result];
    }

    Interval eval_box(const Interval* box) override {
        ++stats.calls;
        evaluated_boxes_ = 1;
        num::UpwardRounding up;
        load(boxes_, box);
        run_boxes(0);
        return boxes_[tape_.result];
    }

    void eval_boxes(const Interval* boxes, std::size_t n, Interval* out) override {
        num::UpwardRounding up; // once per batch
        const auto d = static_cast<std::size_t>(tape_.inputs);
        evaluated_boxes_ = n;
        for (std::size_t i = 0; i < n; ++i) {
            ++stats.calls;
            load(boxes_, boxes + i * d);
            run_boxes(0);
            out[i] = boxes_[tape_.result];
        }
    }

private:
    template <class V>
    void load(std::vector<V>& regs, const V* inputs) {
        for (std::size_t k = 0; k < tape_.input_slots.size(); ++k)
            if (tape_.input_slots[k] != ir::no_slot) regs[tape_.input_slots[k]] = inputs[k];
    }

    // The implementation of external function k; a tape with an unbound one is a driver bug.
    const ir::ExternalFunction& external(std::int64_t k) const {
        const auto i = static_cast<std::size_t>(k);
        if (i >= tape_.externals.size() || !tape_.externals[i])
            throw std::logic_error("interpreter: external function #" + std::to_string(k) + " is not bound");
        return *tape_.externals[i];
    }

    void run_boxes(std::uint32_t block) {
        Interval args[3];
        for (const Instr& ins : tape_.blocks[block]) {
            if (ir::is_series(ins.op)) {
                boxes_[ins.out] = series_box(tape_.series[ins.series]);
                continue;
            }
            for (int i = 0; i < ir::arity(ins.op); ++i) args[i] = boxes_[ins.in[static_cast<std::size_t>(i)]];
            boxes_[ins.out] = ins.op == Op::External ? external(ins.imm).eval_box(args)
                                                     : ir::apply_interval(ins.op, args, ins.imm);
        }
    }

    void run_points(std::uint32_t block) {
        double args[3];
        for (const Instr& ins : tape_.blocks[block]) {
            if (ir::is_series(ins.op)) {
                points_[ins.out] = series_point(tape_.series[ins.series]);
                continue;
            }
            for (int i = 0; i < ir::arity(ins.op); ++i)
                args[i] = points_[ins.in[static_cast<std::size_t>(i)]];
            points_[ins.out] = ins.op == Op::External ? external(ins.imm).eval_point(args)
                                                      : ir::apply_point(ins.op, args, ins.imm);
        }
    }

    // p <- M(p) for all components at once: a map's component may be another state slot (a swap).
    template <class V>
    static void advance_orbit(std::vector<V>& regs, const TapeSeries& s) {
        V next[ir::max_state_components];
        for (std::size_t c = 0; c < s.state_slots.size(); ++c) next[c] = regs[s.update_slots[c]];
        for (std::size_t c = 0; c < s.state_slots.size(); ++c) regs[s.state_slots[c]] = next[c];
    }

    static bool one_sided(Op kind, Interval tail) {
        return (kind == Op::SeriesMin && std::isinf(tail.hi)) ||
               (kind == Op::SeriesMax && std::isinf(tail.lo));
    }
    static bool tail_cannot_improve(Op kind, Interval acc, Interval term, Interval tail) {
        if (kind == Op::SeriesMin) return tail.lo >= acc.lo && term.hi >= acc.hi;
        return tail.hi <= acc.hi && term.lo <= acc.lo;
    }

    std::int64_t last_index(const TapeSeries& s) const {
        return s.data.end == ir::infinite_end ? s.data.start + options_.max_terms - 1 : s.data.end;
    }

    // Sums terms while they resolve something the tail bound does not, then encloses the rest.
    Interval series_box(const TapeSeries& s) {
        const bool infinite = s.data.end == ir::infinite_end;
        const bool has_b = s.tail_b != ir::no_slot;
        const Interval a = infinite ? boxes_[s.tail_a] : Interval(0.0);
        const Interval b = has_b ? boxes_[s.tail_b] : Interval(0.0);
        const std::int64_t last = last_index(s);
        Interval gamma_i = infinite ? num::powi(s.data.gamma, s.data.start) : Interval(1.0);
        Interval acc;
        std::int64_t i = s.data.start;
        bool resolved = !infinite;
        for (std::size_t c = 0; c < s.state_slots.size(); ++c)
            boxes_[s.state_slots[c]] = boxes_[s.init_slots[c]];
        // A proven Lipschitz bound: run the orbit from the centre of the initial box, widen at the end.
        const double h = infinite && s.data.escape.lipschitz > 0 ? centre_orbit(s) : 0.0;
        const bool escape = infinite && s.data.escape.present;
        double escape_prev = s.kind == Op::SeriesMax ? num::inf : -num::inf;
        for (;; ++i) {
            boxes_[s.index_slot] = Interval(static_cast<double>(i));
            run_boxes(s.block);
            const Interval term = boxes_[s.body_slot];
            advance_orbit(boxes_, s);
            acc = i == s.data.start ? term : ir::series_combine(s.kind, acc, term);
            ++stats.series_terms;
            if (i == last) break;
            if (infinite) {
                // Stop when this term told little more than its static bound: the box is too wide
                // for later terms to resolve anything. (The factor absorbs the rounding of gamma^i.)
                const Interval bound = ir::series_term_bound(a, b, has_b, gamma_i, i);
                if (options_.adaptive_terms && num::width(term) >= ir::term_resolution * num::width(bound)) {
                    resolved = true;
                    break;
                }
                Interval tail = ir::series_tail(s.kind, a, b, has_b, s.data.gamma, i);
                double escape_now = 0.0;
                if (escape) {
                    Interval state[ir::max_state_components];
                    const int dims = load_state(s, state);
                    escape_now = ir::escape_bound(s.kind, s.data.escape, state, dims, i + 1);
                    tail = ir::escape_tighten(s.kind, tail, escape_now);
                }
                if (num::width(tail) <= ir::box_stop_ratio * num::magnitude(acc) || num::width(tail) == 0) {
                    resolved = true;
                    break;
                }
                // A one-sided tail (terms bounded on one side only): stop once the tail cannot move
                // the bound it knows and this term did not improve the other one.
                if (one_sided(s.kind, tail) && tail_cannot_improve(s.kind, acc, term, tail)) {
                    resolved = true;
                    break;
                }
                if (escape && ir::escape_stalls(s.kind, escape_now, escape_prev, acc)) {
                    resolved = true;
                    break;
                }
                escape_prev = escape_now;
                gamma_i = num::mul(gamma_i, s.data.gamma);
            }
        }
        if (!infinite) return acc;
        if (!resolved) ++stats.series_capped;
        const Interval tail = ir::series_tail(s.kind, a, b, has_b, s.data.gamma, i);
        if (!s.data.escape.present) return ir::series_combine(s.kind, acc, tail);
        Interval state[ir::max_state_components];
        const int dims = load_state(s, state);
        return ir::lipschitz_finish(s.kind, s.data.escape, acc, tail,
                                    ir::escape_bound_around(s.kind, s.data.escape, state, dims, i + 1, h), i,
                                    h);
    }

    int load_state(const TapeSeries& s, Interval* state) const {
        for (std::size_t c = 0; c < s.state_slots.size(); ++c) state[c] = boxes_[s.state_slots[c]];
        return static_cast<int>(s.state_slots.size());
    }
    double centre_orbit(const TapeSeries& s) {
        Interval state[ir::max_state_components];
        const int dims = load_state(s, state);
        const double h = ir::lipschitz_centre(state, dims);
        for (int c = 0; c < dims; ++c) boxes_[s.state_slots[static_cast<std::size_t>(c)]] = state[c];
        return h;
    }

    double series_point(const TapeSeries& s) {
        const bool infinite = s.data.end == ir::infinite_end;
        const bool has_b = s.tail_b != ir::no_slot;
        if (s.point_block != ir::no_block) run_points(s.point_block);
        // Bounds of A and B at this point (not their point values: those are no bounds).
        auto bound = [&](std::size_t k) {
            return s.point_tail[k] == ir::no_slot ? std::nan("") : points_[s.point_tail[k]];
        };
        const double a = infinite ? ir::point_magnitude(bound(0), bound(1)) : 0.0;
        const double b = has_b ? ir::point_magnitude(bound(2), bound(3)) : 0.0;
        const double gamma = s.data.gamma.hi;
        const std::int64_t last = last_index(s);
        double gamma_next = infinite ? std::pow(gamma, static_cast<double>(s.data.start + 1)) : 0.0;
        double acc = 0.0, comp = 0.0;
        std::int64_t i = s.data.start;
        bool resolved = !infinite;
        for (std::size_t c = 0; c < s.state_slots.size(); ++c)
            points_[s.state_slots[c]] = points_[s.init_slots[c]];
        for (;; ++i) {
            points_[s.index_slot] = static_cast<double>(i);
            run_points(s.block);
            const double term = points_[s.body_slot];
            advance_orbit(points_, s);
            if (i == s.data.start)
                acc = term;
            else if (s.kind == Op::SeriesSum)
                ir::compensated_add(acc, comp, term);
            else
                acc = ir::series_combine_point(s.kind, acc, term);
            ++stats.series_terms;
            if (i == last) break;
            if (infinite && s.data.escape.present) {
                // The escape certificate bounds every later term from the orbit point q_{i+1}.
                double state[ir::max_state_components];
                for (std::size_t c = 0; c < s.state_slots.size(); ++c) state[c] = points_[s.state_slots[c]];
                if (ir::escape_point_done(s.kind, s.data.escape, acc, state,
                                          static_cast<int>(s.state_slots.size()), i + 1)) {
                    resolved = true;
                    break;
                }
            } else if (infinite && !s.data.one_sided) {
                // A bound of the tail's size: stop once it is below half an ulp of the sum.
                const double n1 = static_cast<double>(i + 1);
                const double tail = (a + b * n1) * gamma_next * (n1 + 1.0) / ((1.0 - gamma) * (1.0 - gamma));
                if (tail <= ir::point_stop_ratio * std::fabs(acc) || tail == 0.0) {
                    resolved = true;
                    break;
                }
                gamma_next *= gamma;
            }
        }
        if (!infinite) return acc + comp;
        if (!resolved) ++stats.series_capped;
        // No tail estimate from a one-sided bound (min and max series: comp is 0).
        if (s.data.escape.present || s.data.one_sided) return acc + comp;
        return ir::series_point_end(s.kind, acc, comp, bound(0), bound(1), bound(2), bound(3), has_b,
                                    s.data.gamma, i);
    }

    Tape tape_;
    ir::EvalOptions options_;
    bool has_choices_; // block 0 has something to prune
    double cost_;      // ir::tape_cost of the tape
    std::vector<Interval> boxes_;
    std::vector<double> points_;
    std::size_t evaluated_boxes_ = 0; // boxes of the last box evaluation (boxes_ holds the last one's)
};

} // namespace

std::unique_ptr<ir::Evaluator> make_interpreter(ir::Tape tape, const ir::EvalOptions& options) {
    if (runs_flat(tape)) return make_flat_interpreter(tape, options);
    return make_tape_interpreter(std::move(tape), options);
}

double eval_ns_per_cost(const ir::Tape& tape) {
    return runs_flat(tape) ? flat_eval_ns_per_cost : tape_eval_ns_per_cost;
}

double cover_eval_ns(const ir::Tape& tape) {
    return cover_eval_ns_fixed + eval_ns_per_cost(tape) * ir::tape_cost(tape);
}

std::unique_ptr<ir::Evaluator> make_tape_interpreter(ir::Tape tape, const ir::EvalOptions& options) {
    return std::make_unique<Interpreter>(std::move(tape), options);
}

ChoiceRecorder::ChoiceRecorder(const ir::Tape& tape, const ir::EvalOptions& options)
    : interp_(std::make_unique<Interpreter>(tape, options)) {}
ChoiceRecorder::~ChoiceRecorder() = default;

std::vector<ir::Choice> ChoiceRecorder::record(const Interval* box) {
    return static_cast<Interpreter&>(*interp_).record(box);
}

} // namespace frac::interp
