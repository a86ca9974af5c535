// The flat interpreter (backend/interp/flat_interpreter.hpp) against the tape interpreter it replaces
// on flat tapes: the same bits on boxes, batches and points, and tape pushes that compute what
// ir::specialize's tapes compute, from the values of any box of a batch.
#include "backend/interp/flat_interpreter.hpp"
#include "backend/interp/interpreter.hpp"
#include "engines.hpp"

#include <catch2/catch.hpp>

using namespace frac;
using namespace frac::test;

namespace {

// A random sub-box of `box` (thin in some coordinates now and then).
std::vector<Interval> sub_box_of(BoxMaker& r, const std::vector<Interval>& box) {
    std::vector<Interval> s;
    for (const Interval& x : box) {
        const double lo = std::isfinite(x.lo) ? x.lo : -4, hi = std::isfinite(x.hi) ? x.hi : 4;
        double a = r.uniform(lo, hi), b = r.uniform(lo, hi);
        if (a > b) std::swap(a, b);
        if (r.pick(6) == 0) b = a;
        s.push_back({std::max(a, x.lo), std::min(b, x.hi)});
    }
    return s;
}

// A graph whose choices decide on many boxes: min/max/select over random subexpressions.
ir::NodeId choice_tree(ir::Graph& g, BoxMaker& mk, int depth) {
    if (depth == 0) return random_node(g, mk, 3, true);
    static const ir::Op ops[] = {ir::Op::Min, ir::Op::Max, ir::Op::Add, ir::Op::Select};
    const ir::Op op = ops[mk.pick(4)];
    const ir::NodeId a = choice_tree(g, mk, depth - 1), b = choice_tree(g, mk, depth - 1);
    if (op == ir::Op::Select)
        return g.op(op, g.op(ir::Op::Lt, g.var(0), g.constant(mk.uniform(-1, 1))), a, b);
    return g.op(op, a, b);
}

std::string mismatch(const char* what, std::size_t k, Interval flat, Interval ref) {
    return std::string(what) + " " + std::to_string(k) + ": flat " + hex(flat) + ", reference " + hex(ref);
}

// Restores the default (vector kernels where the CPU has them) when a test ends.
struct VectorLanes {
    explicit VectorLanes(bool wanted) { interp::use_vector_lanes(wanted); }
    ~VectorLanes() { interp::use_vector_lanes(true); }
};

} // namespace

TEST_CASE("four boxes side by side: the vector kernels give the scalar kernels' bits on special bounds",
          "[interp][flat]") {
    if (!interp::use_vector_lanes(true)) {
        WARN("this CPU has no AVX2: the vector kernels are not used");
        return;
    }
    // Every interval over these bounds, and the empty one.
    const double bounds[] = {-num::inf, -1e300, -3.0, -1.0, -0.5, -1e-310, -0.0,    0.0,
                             1e-310,    0.5,    1.0,  2.75, 3.0,  1e300,   num::inf};
    std::vector<Interval> intervals = {Interval::empty()};
    for (double lo : bounds)
        for (double hi : bounds)
            if (lo <= hi && !(lo == num::inf || hi == -num::inf)) intervals.push_back({lo, hi});
    using ir::Op;
    for (const Op op : {Op::Add, Op::Sub, Op::Mul, Op::Neg, Op::Sqr, Op::Sqrt, Op::Abs, Op::Min, Op::Max}) {
        ir::Graph g;
        const ir::NodeId x = g.var(0), y = g.var(1);
        const ir::Tape t = ir::build_tape(g, ir::arity(op) == 1 ? g.op(op, x) : g.op(op, x, y), 2);
        REQUIRE(interp::runs_flat(t));
        auto flat = interp::make_interpreter(t);
        std::vector<Interval> boxes;
        for (const Interval& a : intervals)
            for (const Interval& b : intervals) boxes.insert(boxes.end(), {a, b});
        const std::size_t count = boxes.size() / 2;
        std::vector<Interval> out(count);
        flat->eval_boxes(boxes.data(), count, out.data()); // four at a time
        for (std::size_t k = 0; k < count; ++k) {
            const Interval one = flat->eval_box(&boxes[2 * k]); // scalar kernels
            INFO(ir::op_name(op) << " of " << hex(boxes[2 * k]) << ", " << hex(boxes[2 * k + 1]) << ": "
                                 << mismatch("box", k, out[k], one));
            REQUIRE(same(out[k], one));
        }
    }
}

TEST_CASE("the flat interpreter agrees with the tape interpreter bit for bit", "[interp][flat]") {
    // Both kernels for boxes side by side.
    const bool vector = GENERATE(true, false);
    const VectorLanes lanes(vector);
    BoxMaker mk(8080);
    int flat_tapes = 0;
    for (int n = 0; n < 300; ++n) {
        ir::Graph g;
        const ir::NodeId root = random_node(g, mk, 5, n % 2 == 1);
        const ir::Tape t = ir::build_tape(g, root, 2);
        if (!interp::runs_flat(t)) continue;
        ++flat_tapes;
        INFO("graph " << n << ":\n" << ir::print_tape(t));
        auto flat = interp::make_interpreter(t);
        auto ref = interp::make_tape_interpreter(t);
        std::vector<Interval> boxes;
        for (int k = 0; k < 23; ++k) {
            const std::vector<Interval> b = {mk.coordinate({-2, 2}), mk.coordinate({-2, 2})};
            boxes.insert(boxes.end(), b.begin(), b.end());
        }
        const std::size_t count = boxes.size() / 2;
        std::vector<Interval> ref_out(count);
        ref->eval_boxes(boxes.data(), count, ref_out.data());
        for (std::size_t k = 0; k < count; ++k) {
            const Interval one = flat->eval_box(&boxes[2 * k]);
            INFO(mismatch("box", k, one, ref_out[k]));
            REQUIRE(same(one, ref_out[k]));
        }
        // Batches of every size around the lane count.
        for (std::size_t size = 1; size <= count; size += 1 + size / 3) {
            std::vector<Interval> out(count);
            for (std::size_t k = 0; k < count; k += size)
                flat->eval_boxes(&boxes[2 * k], std::min(size, count - k), &out[k]);
            for (std::size_t k = 0; k < count; ++k) {
                INFO("batches of " << size << ": " << mismatch("box", k, out[k], ref_out[k]));
                REQUIRE(same(out[k], ref_out[k]));
            }
        }
        for (int k = 0; k < 20; ++k) {
            const double p[2] = {mk.position({-2, 2}), mk.position({-2, 2})};
            const double a = flat->eval_point(p), b = ref->eval_point(p);
            INFO("point (" << hex(p[0]) << ", " << hex(p[1]) << "): flat " << hex(a) << ", reference "
                           << hex(b));
            REQUIRE(same(a, b));
        }
    }
    CHECK(flat_tapes > 200);
}

TEST_CASE("flat tape pushes compute what ir::specialize's tapes compute, from any box of a batch",
          "[interp][flat][prune]") {
    BoxMaker mk(9090);
    const std::vector<Interval> root_box = {{-2, 2}, {-2, 2}};
    int pushed = 0, nested = 0, too_little = 0;
    for (int n = 0; n < 120; ++n) {
        ir::Graph g;
        const ir::NodeId root = choice_tree(g, mk, 3);
        const ir::Tape t = ir::build_tape(g, root, 2);
        REQUIRE(interp::runs_flat(t));
        INFO("graph " << n << ":\n" << ir::print_tape(t));
        auto flat = interp::make_interpreter(t);
        auto other = interp::make_interpreter(t); // evaluates in between on the same thread
        interp::ChoiceRecorder recorder(t, {});
        REQUIRE(flat->kept_evaluations() >= 1);
        for (int trial = 0; trial < 6; ++trial) {
            // A batch of up to kept_evaluations() boxes (a cover's sibling cells), then every box's push.
            const std::size_t m =
                1 + static_cast<std::size_t>(mk.pick(static_cast<int>(flat->kept_evaluations())));
            std::vector<std::vector<Interval>> boxes;
            std::vector<Interval> flat_boxes;
            for (std::size_t k = 0; k < m; ++k) {
                boxes.push_back(sub_box_of(mk, root_box));
                flat_boxes.insert(flat_boxes.end(), boxes.back().begin(), boxes.back().end());
            }
            std::vector<Interval> out(m);
            flat->eval_boxes(flat_boxes.data(), m, out.data());
            if (trial % 3 == 2) other->eval_box(flat_boxes.data()); // the thread's registers change
            for (std::size_t k = 0; k < m; ++k) {
                const std::vector<Interval>& box = boxes[k];
                // Boxes of one batch push for different expected evaluations now and then (the most a
                // pruned tape may cost differs; the batch's analysis must follow).
                const double evaluations[] = {1e12, 40, 20};
                const double expected_evaluations = evaluations[(k + static_cast<std::size_t>(trial)) % 3];
                auto push = flat->specialize_after_eval(k, box.data(), expected_evaluations);
                const std::vector<ir::Choice> choices = recorder.record(box.data());
                const ir::Tape expected = ir::specialize(t, choices);
                const double max_cost =
                    ir::push_max_cost(static_cast<double>(t.instruction_count()), expected_evaluations);
                const bool prunes =
                    ir::any_decided(choices) && static_cast<double>(expected.instruction_count()) <= max_cost;
                too_little += ir::any_decided(choices) && !prunes;
                INFO("trial " << trial << ", box " << k << " of " << m << ": " << hex_box(box.data(), 2));
                REQUIRE(bool(push) == prunes);
                if (!push) continue;
                ++pushed;
                CHECK(push->instruction_count() == expected.instruction_count());
                auto ref = interp::make_tape_interpreter(expected);
                // The pushed tape on sub-boxes and points of the box, and its own pushes.
                for (int s = 0; s < 8; ++s) {
                    const std::vector<Interval> sub = sub_box_of(mk, box);
                    const Interval a = push->eval_box(sub.data()), b = ref->eval_box(sub.data());
                    INFO(mismatch("sub-box", static_cast<std::size_t>(s), a, b));
                    REQUIRE(same(a, b));
                    const double p[2] = {sub[0].lo, sub[1].hi};
                    REQUIRE(same(push->eval_point(p), ref->eval_point(p)));
                    // (Not compared with the whole tape: pow's domain depends on whether its exponent is
                    // thin, so enclosures are not inclusion isotone, and a pruned tape may differ.)
                    if (auto again = push->specialize_after_eval(0, sub.data(), 1e12)) {
                        ++nested;
                        const ir::Tape expected_again =
                            ir::specialize(expected, interp::ChoiceRecorder(expected, {}).record(sub.data()));
                        CHECK(again->instruction_count() == expected_again.instruction_count());
                        const std::vector<Interval> leaf = sub_box_of(mk, sub);
                        REQUIRE(same(again->eval_box(leaf.data()),
                                     interp::make_tape_interpreter(expected_again)->eval_box(leaf.data())));
                    }
                }
            }
        }
    }
    CHECK(pushed > 150);
    CHECK(nested > 50);
    CHECK(too_little > 20);
}
