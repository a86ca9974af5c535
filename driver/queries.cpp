#include "driver/queries.hpp"

#include "runtime/automata/dimension.hpp"
#include "runtime/automata/tabulate.hpp"
#include "runtime/dimension.hpp"
#include "runtime/rss.hpp"

#include <fmt/format.h>
#include <stdexcept>

namespace frac::driver {

ir::Interval automaton_dimension(const front::AutomatonInfo& a) {
    const rt::SimilarityDimension d = a.fif_points.empty() ? rt::similarity_dimension(a.automaton)
                                                           : rt::fif_box_dimension(a.automaton, a.fif_points);
    if (!d.defined)
        throw RunError(fmt::format(
            "dimension of '{}': {} ({}frac dimension FILE {} counts boxes of its cover)", a.name, d.reason,
            a.fif_points.empty() ? "its similarity dimension needs similitudes; " : "", a.name));
    return d.bracket;
}

std::vector<ir::Interval> answer_queries(const front::Module& m, const ir::Tape& tape,
                                         const EngineOptions& options, QueryAnswers& answers) {
    answers.resize(m.queries.size());
    std::vector<ir::Interval> inputs(m.queries.size(), ir::Interval(0.0));
    for (std::size_t k = 0; k < tape.input_slots.size(); ++k) {
        if (tape.input_slots[k] == ir::no_slot) continue;
        if (!answers[k]) {
            const front::Query& q = m.queries[k];
            if (q.kind == front::Query::Kind::automaton_dimension) {
                answers[k] = automaton_dimension(m.automata.at(q.shape));
                inputs[k] = *answers[k];
                continue;
            }
            if (q.kind == front::Query::Kind::automaton_point) {
                // A point value (the tabulated double, p compositions), not an enclosure.
                const auto& a = m.automata.at(q.shape);
                try {
                    answers[k] = ir::Interval(rt::address_point(a.automaton, q.address).at(q.component));
                } catch (const std::invalid_argument& e) {
                    throw RunError(fmt::format("tabulate of '{}': {}", a.name, e.what()));
                }
                inputs[k] = *answers[k];
                continue;
            }
            const front::ShapeInfo& s = m.shapes[q.shape];
            auto eval = make_evaluator(m, s.root, s.dimension, options);
            if (q.kind == front::Query::Kind::enclose) {
                answers[k] = eval->eval_box(q.box.data());
            } else {
                rt::RssOptions ro;
                ro.depth = q.to;
                ro.split = q.split;
                ro.keep_cells = false;
                ro.threads = options.threads;
                try {
                    const rt::RssResult r = rt::subdivide(*eval, q.box, ro);
                    answers[k] = ir::Interval(rt::box_counting(r, q.from, q.to).dimension);
                } catch (const std::invalid_argument& e) {
                    throw RunError(fmt::format("dimension of '{}': {}", s.name, e.what()));
                }
            }
        }
        inputs[k] = *answers[k];
    }
    return inputs;
}

ClosedValue evaluate_closed(const front::Module& m, ir::NodeId node, const EngineOptions& engine,
                            QueryAnswers& answers, bool with_point) {
    const int inputs = static_cast<int>(m.queries.size());
    const ir::Tape tape = ir::build_tape(m.graph, node, inputs);
    const std::vector<ir::Interval> in = answer_queries(m, tape, engine, answers);
    auto eval = make_evaluator(m, node, inputs, engine);
    ClosedValue v;
    bool reads_enclosure = false;
    for (std::size_t k = 0; k < tape.input_slots.size(); ++k)
        reads_enclosure |=
            tape.input_slots[k] != ir::no_slot && m.queries[k].kind == front::Query::Kind::enclose;
    if (with_point && !reads_enclosure) {
        std::vector<double> p;
        for (const ir::Interval& x : in) p.push_back(num::midpoint(x));
        v.point = eval->eval_point(p.data());
    }
    v.enclosure = eval->eval_box(in.data());
    return v;
}

} // namespace frac::driver
