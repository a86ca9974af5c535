// Compiled -O2 -march=native -ffp-contract=off -frounding-math (bench/CMakeLists.txt): the host's
// instructions as the JIT uses them, and no contraction into fma, which would change the bits.
#include "bench/carpet_handwritten.hpp"

#include "ir/graph.hpp"
#include "ir/series_tail.hpp"
#include "numeric/interval_kernels.hpp"

#include <cmath>
#include <stdexcept>
#include <vector>

namespace frac::bench {
namespace {

using num::Interval;

// The numeric core's rounded-down operations (-RU(-x op y)), as the core and the interpreters use them.
using num::kernels::add_down;
using num::kernels::div_down;
using num::kernels::mul_down;
using num::kernels::sub_down;

inline double mn(double a, double b) {
    return b < a ? b : a;
}
inline double mx(double a, double b) {
    return a < b ? b : a;
}

// x * p with p > 0 and finite (a table entry 3^i): the four corners of interval.cpp's product,
// zero factors giving 0, in the same order.
inline Interval mul_pos(Interval x, Interval p) {
    const bool zl = x.lo == 0, zh = x.hi == 0;
    const double d0 = zl ? 0.0 : mul_down(x.lo, p.lo), d1 = zl ? 0.0 : mul_down(x.lo, p.hi);
    const double d2 = zh ? 0.0 : mul_down(x.hi, p.lo), d3 = zh ? 0.0 : mul_down(x.hi, p.hi);
    const double u0 = zl ? 0.0 : x.lo * p.lo, u1 = zl ? 0.0 : x.lo * p.hi;
    const double u2 = zh ? 0.0 : x.hi * p.lo, u3 = zh ? 0.0 : x.hi * p.hi;
    return {mn(mn(mn(d0, d1), d2), d3), mx(mx(mx(u0, u1), u2), u3)};
}
inline double dz_down(double x) {
    return mn(sub_down(x, std::floor(x)), sub_down(std::ceil(x), x));
}
inline double dz_up(double x) {
    return mn(x - std::floor(x), std::ceil(x) - x);
}
inline Interval dz_box(Interval a) {
    if (!(a.hi - a.lo < 1)) return {0.0, 0.5};
    double lo = mn(dz_down(a.lo), dz_down(a.hi));
    double hi = mx(dz_up(a.lo), dz_up(a.hi));
    if (std::ceil(a.lo) <= a.hi) lo = 0.0;
    double half = std::floor(a.lo) + 0.5;
    if (half < a.lo) half += 1.0;
    if (half <= a.hi) hi = 0.5;
    return {lo, hi};
}
// a / p with p > 0: the sign cases of interval.cpp's division.
inline Interval div_pos(Interval a, Interval p) {
    double lo, hi;
    if (a.lo >= 0) {
        lo = div_down(a.lo, p.hi);
        hi = a.hi / p.lo;
    } else if (a.hi <= 0) {
        lo = div_down(a.lo, p.lo);
        hi = a.hi / p.hi;
    } else {
        lo = div_down(a.lo, p.lo);
        hi = a.hi / p.lo;
    }
    return {std::isnan(lo) ? -num::inf : lo, std::isnan(hi) ? num::inf : hi};
}

class Carpet final : public ir::Evaluator {
public:
    explicit Carpet(int max_terms) : max_terms_(max_terms) {
        if (max_terms < 1 || max_terms > ir::max_terms_limit)
            throw std::invalid_argument("max_terms out of range");
        // The constants of the carpet's tape: 1/3 and the tail coefficient A = 1/3 - [0, 1/2] over the
        // same enclosures; gamma = 1/3.
        num::UpwardRounding up;
        third_ = num::div(Interval(1.0), Interval(3.0));
        const Interval a = num::sub(third_, Interval(0.0, 0.5));
        const Interval gamma = third_;
        Interval gi = Interval(1.0);
        for (int i = 0; i < max_terms; ++i) {
            pow3_.push_back(num::powi(Interval(3.0), i));
            threshold_.push_back(0.75 * num::width(ir::series_term_bound(a, {}, false, gi, i)));
            tail_.push_back(ir::series_tail(ir::Op::SeriesMin, a, {}, false, gamma, i));
            tail_width_.push_back(num::width(tail_.back()));
            gi = num::mul(gi, gamma);
        }
    }

    int dimension() const override { return 2; }
    std::string engine() const override { return "handwritten"; }
    std::unique_ptr<Evaluator> clone() const override { return std::make_unique<Carpet>(max_terms_); }
    double eval_point(const double*) override { throw std::logic_error("handwritten carpet: boxes only"); }
    Interval eval_box(const Interval* box) override {
        Interval r;
        eval_boxes(box, 1, &r);
        return r;
    }

    void eval_boxes(const Interval* boxes, std::size_t n, Interval* out) override {
        num::UpwardRounding up; // once per batch
        std::uint64_t terms = 0;
        for (std::size_t k = 0; k < n; ++k) {
            const Interval x = boxes[2 * k], y = boxes[2 * k + 1];
            Interval acc;
            int i = 0;
            for (;; ++i) {
                const Interval p = pow3_[static_cast<std::size_t>(i)];
                const Interval dx = dz_box(mul_pos(x, p)), dy = dz_box(mul_pos(y, p));
                const Interval m{mn(dx.lo, dy.lo), mn(dx.hi, dy.hi)};
                const Interval d{sub_down(third_.lo, m.hi), third_.hi - m.lo}; // 1/3 - m
                const Interval term = div_pos(d, p);
                acc = i == 0 ? term : Interval{mn(acc.lo, term.lo), mn(acc.hi, term.hi)};
                ++terms;
                if (i == max_terms_ - 1) break;
                if (term.hi - term.lo >= threshold_[static_cast<std::size_t>(i)]) break;
                const double tw = tail_width_[static_cast<std::size_t>(i)];
                if (tw <= 0x1p-52 * mx(std::fabs(acc.lo), std::fabs(acc.hi)) || tw == 0) break;
            }
            const Interval t = tail_[static_cast<std::size_t>(i)];
            out[k] = {mn(acc.lo, t.lo), mn(acc.hi, t.hi)};
        }
        stats.calls += n;
        stats.series_terms += terms;
    }

private:
    int max_terms_;
    Interval third_;
    std::vector<Interval> pow3_, tail_;
    std::vector<double> threshold_, tail_width_;
};

} // namespace

std::unique_ptr<ir::Evaluator> make_carpet_handwritten(int max_terms) {
    return std::make_unique<Carpet>(max_terms);
}

} // namespace frac::bench
