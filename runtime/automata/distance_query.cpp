// The queries of AttractorDistance and its serialization: the part compiled models link
// (libfrac_aot_automata.a), so nothing here may use the IR's automaton, fmt or other run-time code.
#include "runtime/automata/distance.hpp"

#include "runtime/automata/distance_bounds.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace frac::rt {

namespace {

// x * 2^-p rounded down (dir = -inf) or up (dir = +inf): exact unless the result is subnormal.
double scale_down(double x, int p, double dir) {
    const double y = std::ldexp(x, -p);
    return std::ldexp(y, p) == x ? y : std::nextafter(y, dir);
}

// The Euclidean norm of the vectors in the d intervals v (under upward rounding). Components
// past 2^500 are scaled down by a power of two first, so that no square overflows (a point 1e160
// away had the distance [1.3e154, inf]); the scaling is exact for every component that stays a
// normal double, and the others are rounded outward.
Interval euclidean_norm(const Interval* v, std::size_t d) {
    double largest = 0;
    for (std::size_t i = 0; i < d; ++i) largest = std::max({largest, std::fabs(v[i].lo), std::fabs(v[i].hi)});
    Interval sum(0.0);
    if (!(largest > 0x1p500)) {
        for (std::size_t i = 0; i < d; ++i) sum = num::add(sum, num::sqr(v[i]));
        return num::sqrt(sum);
    }
    const int p = std::isinf(largest) ? 1023 : std::ilogb(largest);
    for (std::size_t i = 0; i < d; ++i)
        sum = num::add(
            sum, num::sqr(Interval(scale_down(v[i].lo, p, -num::inf), scale_down(v[i].hi, p, num::inf))));
    const Interval r = num::sqrt(sum);
    // Back to scale: exact, or past the largest double (an upper bound of infinity, a lower one of
    // the largest double).
    return Interval(std::min(std::ldexp(r.lo, p), std::numeric_limits<double>::max()), std::ldexp(r.hi, p));
}

using bounds::down_sub;
using bounds::frobenius_upper;
using bounds::up_add;
using bounds::up_mul;

// Plain values appended as their bytes, with vectors as a length then their elements.
class Writer {
public:
    template <class T>
    void value(const T& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
        bytes.insert(bytes.end(), p, p + sizeof(T));
    }
    template <class T>
    void vector(const std::vector<T>& v) {
        value(static_cast<std::uint64_t>(v.size()));
        for (const T& x : v) value(x);
    }
    std::vector<std::uint8_t> bytes;
};

class Reader {
public:
    Reader(const std::uint8_t* data, std::size_t size) : data_(data), left_(size) {}
    template <class T>
    T value() {
        static_assert(std::is_trivially_copyable_v<T>);
        if (left_ < sizeof(T)) fail();
        T v;
        std::memcpy(&v, data_, sizeof(T));
        data_ += sizeof(T), left_ -= sizeof(T);
        return v;
    }
    // A count of elements of `element_size` bytes each that must still be there.
    std::size_t count(std::size_t element_size) {
        const auto n = value<std::uint64_t>();
        if (element_size != 0 && n > left_ / element_size) fail();
        return static_cast<std::size_t>(n);
    }
    template <class T>
    std::vector<T> vector() {
        std::vector<T> v(count(sizeof(T)));
        for (T& x : v) x = value<T>();
        return v;
    }
    bool at_end() const { return left_ == 0; }
    [[noreturn]] static void fail() { throw std::invalid_argument("malformed attractor distance data"); }

private:
    const std::uint8_t* data_;
    std::size_t left_;
};

constexpr std::uint64_t format_tag = 0x3144'5453'4944'4346; // "FCDISTD1" read as little-endian

} // namespace

std::vector<std::uint8_t> AttractorDistance::serialize() const {
    Writer w;
    w.value(format_tag);
    w.value(static_cast<std::int64_t>(dim_));
    w.value(options_);
    w.value(static_cast<std::uint64_t>(initial_));
    w.value(root_lip_);
    w.vector(root_);
    w.value(static_cast<std::uint64_t>(balls_.size()));
    for (const StateBall& b : balls_) {
        w.vector(b.centre);
        w.value(b.radius);
        w.vector(b.witness);
        w.value(b.witness_radius);
    }
    w.value(static_cast<std::uint64_t>(states_.size()));
    for (const StateData& s : states_) {
        w.value(static_cast<std::uint64_t>(s.coords));
        w.value(static_cast<std::uint8_t>(s.bary));
        w.vector(s.arcs);
    }
    w.value(static_cast<std::uint64_t>(arcs_.size()));
    for (const ArcData& a : arcs_) {
        w.value(static_cast<std::uint64_t>(a.to));
        w.vector(a.op);
        w.value(a.lip);
        w.vector(a.nearest);
    }
    return std::move(w.bytes);
}

AttractorDistance AttractorDistance::deserialize(const std::uint8_t* data, std::size_t size) {
    Reader r(data, size);
    if (r.value<std::uint64_t>() != format_tag) Reader::fail();
    AttractorDistance d;
    const auto dim = r.value<std::int64_t>();
    if (dim < 1 || dim > 3) Reader::fail();
    d.dim_ = static_cast<int>(dim);
    d.options_ = r.value<DistanceOptions>();
    d.initial_ = static_cast<std::size_t>(r.value<std::uint64_t>());
    d.root_lip_ = r.value<double>();
    d.root_ = r.vector<Interval>();
    d.balls_.resize(r.count(1));
    for (StateBall& b : d.balls_) {
        b.centre = r.vector<double>();
        b.radius = r.value<double>();
        b.witness = r.vector<Interval>();
        b.witness_radius = r.value<double>();
    }
    d.states_.resize(r.count(1));
    for (StateData& s : d.states_) {
        s.coords = static_cast<std::size_t>(r.value<std::uint64_t>());
        s.bary = r.value<std::uint8_t>() != 0;
        s.arcs = r.vector<std::size_t>();
    }
    d.arcs_.resize(r.count(1));
    for (ArcData& a : d.arcs_) {
        a.to = static_cast<std::size_t>(r.value<std::uint64_t>());
        a.op = r.vector<Interval>();
        a.lip = r.value<double>();
        a.nearest = r.vector<double>();
    }
    if (!r.at_end()) Reader::fail();
    // The sizes the queries index by: every index in range, every matrix and ball of its state's size.
    const std::size_t n = d.states_.size(), dd = static_cast<std::size_t>(d.dim_);
    bool ok = d.initial_ < n && d.balls_.size() == n && d.root_.size() == dd * d.states_[d.initial_].coords;
    for (std::size_t s = 0; ok && s < n; ++s) {
        const StateData& st = d.states_[s];
        ok = st.coords >= 1 && st.coords <= 64 &&
             (d.balls_[s].radius < 0 ||
              (d.balls_[s].centre.size() == st.coords && d.balls_[s].witness.size() == st.coords));
        for (std::size_t ai : st.arcs) {
            if (!ok || ai >= d.arcs_.size()) {
                ok = false;
                break;
            }
            const ArcData& a = d.arcs_[ai];
            ok = a.to < n && a.op.size() == st.coords * d.states_[a.to].coords &&
                 a.nearest.size() == a.op.size();
        }
    }
    if (!ok || d.balls_[d.initial_].radius < 0) Reader::fail();
    return d;
}

std::vector<Interval> AttractorDistance::bounding_box() const {
    const std::size_t d = static_cast<std::size_t>(dim_), n = states_[initial_].coords;
    const StateBall& b = balls_[initial_];
    num::UpwardRounding up;
    const double r = up_mul(root_lip_, b.radius);
    std::vector<Interval> box(d);
    for (std::size_t i = 0; i < d; ++i) {
        Interval c(0.0);
        for (std::size_t j = 0; j < n; ++j)
            c = num::add(c, num::mul(root_[i * n + j], Interval(b.centre[j])));
        box[i] = {num::sub(Interval(c.lo), Interval(r)).lo, num::add(Interval(c.hi), Interval(r)).hi};
    }
    return box;
}

Interval AttractorDistance::eval_point(const double* p) const {
    std::vector<Interval> box(static_cast<std::size_t>(dim_));
    for (int i = 0; i < dim_; ++i) box[static_cast<std::size_t>(i)] = Interval(p[i]);
    return query(box.data()).distance;
}

Interval AttractorDistance::eval_box(const Interval* box) const {
    return query(box).distance;
}

DistanceResult AttractorDistance::query(const Interval* box) const {
    const std::size_t d = static_cast<std::size_t>(dim_);
    DistanceResult result;
    bool point = true;
    for (std::size_t i = 0; i < d; ++i) {
        // NaN says nothing about the point: any distance. An empty box has no distances.
        if (std::isnan(box[i].lo) || std::isnan(box[i].hi)) return {Interval(0.0, num::inf), 0, 0, false};
        if (box[i].is_empty()) return {Interval::empty(), 0, 0, true};
        if (!std::isfinite(box[i].lo) || !std::isfinite(box[i].hi))
            return {Interval(0.0, num::inf), 0, 0, false};
        if (box[i].lo != box[i].hi) point = false;
    }
    num::UpwardRounding up;
    double eps = options_.epsilon;
    if (!point) {
        Interval diag2(0.0);
        for (std::size_t i = 0; i < d; ++i)
            diag2 = num::add(diag2, num::sqr(num::sub(Interval(box[i].hi), Interval(box[i].lo))));
        eps = std::max(eps, options_.box_tolerance * num::sqrt(diag2).lo);
    }

    // Composite matrices (d x coords of the node's state) live in a pool of fixed-size slots,
    // recycled once a node is expanded.
    std::size_t stride = 0;
    for (const StateData& s : states_) stride = std::max(stride, d * s.coords);
    std::vector<Interval> pool;
    std::vector<std::uint32_t> free_slots;
    auto alloc = [&]() -> std::uint32_t {
        if (!free_slots.empty()) {
            const std::uint32_t s = free_slots.back();
            free_slots.pop_back();
            return s;
        }
        pool.resize(pool.size() + stride);
        return static_cast<std::uint32_t>(pool.size() / stride - 1);
    };
    struct Node {
        double lower;
        double lip;
        std::size_t state;
        std::uint32_t slot;
    };

    double best_min = num::inf; // upper bound of the minimum over the box of d(p, A)
    double best_max = num::inf; // upper bound of the maximum over the box of d(p, A)

    // The node's lower bound; updates the upper bounds with its witness.
    std::vector<Interval> parts(3 * d); // its vectors to the ball's centre and witness, and outside the box
    auto evaluate = [&](const Node& node) {
        const StateBall& ball = balls_[node.state];
        const std::size_t n = states_[node.state].coords;
        const Interval* m = &pool[node.slot * stride];
        Interval* const to_centre = parts.data();
        Interval* const to_witness = to_centre + d;
        Interval* const outside = to_witness + d;
        for (std::size_t i = 0; i < d; ++i) {
            Interval ci(0.0), wi(0.0);
            for (std::size_t j = 0; j < n; ++j) {
                ci = num::add(ci, num::mul(m[i * n + j], Interval(ball.centre[j])));
                wi = num::add(wi, num::mul(m[i * n + j], ball.witness[j]));
            }
            to_centre[i] = num::sub(box[i], ci);
            to_witness[i] = num::sub(box[i], wi);
            // The most any point of the witness's box can lie outside the box along this axis.
            outside[i] = Interval(std::max({0.0, num::sub(Interval(wi.hi), Interval(box[i].hi)).hi,
                                            num::sub(Interval(box[i].lo), Interval(wi.lo)).hi}));
        }
        const double slack = up_mul(node.lip, ball.witness_radius);
        best_min = std::min(best_min, up_add(euclidean_norm(outside, d).hi, slack));
        best_max = std::min(best_max, up_add(euclidean_norm(to_witness, d).hi, slack));
        return down_sub(euclidean_norm(to_centre, d).lo, up_mul(node.lip, ball.radius));
    };
    // The child of `node` along `arc`: its composite M T and Lipschitz bound (not yet evaluated).
    std::vector<Interval> lin;
    auto make_child = [&](const Node& node, const ArcData& arc) {
        const std::size_t n = states_[node.state].coords, k = states_[arc.to].coords;
        Node c{0, 0, arc.to, alloc()};
        const Interval* m = &pool[node.slot * stride];
        Interval* cm = &pool[c.slot * stride];
        for (std::size_t i = 0; i < d; ++i)
            for (std::size_t j = 0; j < k; ++j) {
                Interval s(0.0);
                for (std::size_t l = 0; l < n; ++l)
                    s = num::add(s, num::mul(m[i * n + l], arc.op[l * k + j]));
                cm[i * k + j] = s;
            }
        // The product of the factors' bounds, or the composite's own Frobenius bound when smaller
        // (a product of per-map norms can stay above 1 where the composite contracts).
        const bool bary = states_[arc.to].bary;
        lin.clear();
        for (std::size_t i = 0; i < d; ++i) {
            Interval mean(0.0);
            if (bary) {
                for (std::size_t j = 0; j < k; ++j) mean = num::add(mean, cm[i * k + j]);
                mean = num::div(mean, Interval(static_cast<double>(k)));
            }
            for (std::size_t j = 0; j < (bary ? k : k - 1); ++j)
                lin.push_back(bary ? num::sub(cm[i * k + j], mean) : cm[i * k + j]);
        }
        c.lip = std::min(up_mul(node.lip, arc.lip), frobenius_upper(lin));
        return c;
    };
    auto radius = [&](const Node& node) { return up_mul(node.lip, balls_[node.state].radius); };

    Node root{0, root_lip_, initial_, alloc()};
    std::copy(root_.begin(), root_.end(), pool.begin() + static_cast<std::ptrdiff_t>(root.slot * stride));
    root.lower = evaluate(root);

    // Greedy dive (the paper's greedy upper bound): follow the child with the least lower bound
    // down to a ball of radius epsilon / 2, for an early bound to prune with.
    {
        Node at = root;
        at.slot = alloc();
        std::copy_n(&pool[root.slot * stride], stride, &pool[at.slot * stride]);
        while (radius(at) > eps / 2 && result.nodes < options_.max_nodes) {
            ++result.nodes;
            Node best{num::inf, 0, 0, 0};
            bool have = false;
            for (std::size_t ai : states_[at.state].arcs) {
                Node c = make_child(at, arcs_[ai]);
                c.lower = evaluate(c);
                if (!have || c.lower < best.lower) {
                    if (have) free_slots.push_back(best.slot);
                    best = c, have = true;
                } else {
                    free_slots.push_back(c.slot);
                }
            }
            free_slots.push_back(at.slot);
            if (!have) break;
            at = best;
        }
        free_slots.push_back(at.slot);
    }

    // Best first: a min-heap on the lower bounds.
    std::vector<Node> heap{root};
    auto later = [](const Node& a, const Node& b) { return a.lower > b.lower; };
    double pruned_min = num::inf; // least lower bound of a pruned node
    // Epsilon, or a few units in the last place of the distance where that is coarser: far from the
    // attractor (1e10 and beyond, for the default 1e-6) no bound can come closer than the rounding,
    // and each query ran to the node budget (a point 1e200 away took 1.2 s).
    const auto tolerance = [&] { return best_min < num::inf ? std::max(eps, best_min * 0x1p-50) : eps; };
    while (!heap.empty()) {
        if (heap.front().lower >= best_min - tolerance()) {
            result.converged = true;
            break;
        }
        if (result.nodes >= options_.max_nodes) break;
        std::pop_heap(heap.begin(), heap.end(), later);
        const Node node = heap.back();
        heap.pop_back();
        ++result.nodes;
        for (std::size_t ai : states_[node.state].arcs) {
            Node c = make_child(node, arcs_[ai]);
            c.lower = evaluate(c);
            // Nodes within epsilon of the best bound cannot narrow the result below epsilon.
            if (c.lower >= best_min - tolerance()) {
                pruned_min = std::min(pruned_min, c.lower);
                ++result.pruned;
                free_slots.push_back(c.slot);
                continue;
            }
            heap.push_back(c);
            std::push_heap(heap.begin(), heap.end(), later);
        }
        free_slots.push_back(node.slot);
    }
    if (heap.empty()) result.converged = true;
    double lower = pruned_min;
    for (const Node& n : heap) lower = std::min(lower, n.lower);
    lower = std::min(lower, best_min); // every node pruned: the minimum is at most best_min anyway
    const double upper = point ? std::min(best_min, best_max) : best_max;
    result.distance = Interval(std::max(0.0, lower), upper);
    return result;
}

BruteForceResult AttractorDistance::brute_force(const double* p, int level) const {
    if (level < 0 || level > 40) throw std::invalid_argument("brute force level must be in 0..40");
    const std::size_t d = static_cast<std::size_t>(dim_), depth_count = static_cast<std::size_t>(level) + 1;
    BruteForceResult out;
    out.estimate = num::inf;
    // Depth-first over the paths, one composite per depth (no allocation per node).
    std::size_t stride = 0;
    for (const StateData& s : states_) stride = std::max(stride, d * s.coords);
    std::vector<double> mats(depth_count * stride), lips(depth_count);
    std::vector<std::size_t> state(depth_count), next(depth_count, 0);
    for (std::size_t i = 0; i < root_.size(); ++i) mats[i] = num::midpoint(root_[i]);
    state[0] = initial_, lips[0] = root_lip_;
    for (std::ptrdiff_t depth = 0; depth >= 0;) {
        const std::size_t k = static_cast<std::size_t>(depth);
        const std::size_t n = states_[state[k]].coords;
        const double* m = &mats[k * stride];
        if (k + 1 == depth_count) {
            const StateBall& b = balls_[state[k]];
            double s = 0;
            for (std::size_t i = 0; i < d; ++i) {
                double x = 0;
                for (std::size_t j = 0; j < n; ++j) x += m[i * n + j] * b.centre[j];
                s += (p[i] - x) * (p[i] - x);
            }
            out.estimate = std::min(out.estimate, std::sqrt(s));
            out.error = std::max(out.error, lips[k] * b.radius);
            ++out.leaves;
            --depth;
            continue;
        }
        if (next[k] >= states_[state[k]].arcs.size()) {
            next[k] = 0;
            --depth;
            continue;
        }
        const ArcData& arc = arcs_[states_[state[k]].arcs[next[k]++]];
        const std::size_t c = states_[arc.to].coords;
        double* child = &mats[(k + 1) * stride];
        for (std::size_t i = 0; i < d; ++i)
            for (std::size_t j = 0; j < c; ++j) {
                double v = 0;
                for (std::size_t l = 0; l < n; ++l) v += m[i * n + l] * arc.nearest[l * c + j];
                child[i * c + j] = v;
            }
        state[k + 1] = arc.to, lips[k + 1] = lips[k] * arc.lip, next[k + 1] = 0;
        ++depth;
    }
    return out;
}

int AttractorDistance::brute_force_level(double epsilon) const {
    double rho = 0, r = 0;
    for (const ArcData& a : arcs_) rho = std::max(rho, a.lip);
    for (const StateBall& b : balls_) r = std::max(r, b.radius);
    r *= root_lip_;
    if (r <= epsilon) return 0;
    if (!(rho < 1)) return -1;
    return static_cast<int>(std::ceil(std::log(epsilon / r) / std::log(rho)));
}

} // namespace frac::rt
