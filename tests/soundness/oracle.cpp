// MPFI soundness oracle; see oracle.hpp.
#include "tests/soundness/oracle.hpp"

#include <mpfi.h>
#include <mpfr.h>

#include <algorithm>
#include <cfenv>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>

namespace frac::oracle {
namespace {

// ---- Random drawing ----

using Rng = std::mt19937_64;

int pick(Rng& rng, int lo, int hi) {
    return std::uniform_int_distribution<int>(lo, hi)(rng);
}
double uniform(Rng& rng, double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
}
bool chance(Rng& rng, double p) {
    return std::bernoulli_distribution(p)(rng);
}
double sign(Rng& rng) {
    return chance(rng, 0.5) ? 1.0 : -1.0;
}

constexpr double half_pi = 1.5707963267948966; // RN(pi/2)

Expr constant(double v) {
    return Expr{Op::Const, 0, v, 0, {}};
}
Expr node(Op op, std::vector<Expr> args) {
    return Expr{op, 0, 0.0, 0, std::move(args)};
}

double random_constant(Rng& rng) {
    switch (pick(rng, 0, 7)) {
    case 0: return pick(rng, -3, 5);
    case 1: return pick(rng, -8, 8) / 4.0;
    case 2: return uniform(rng, -10, 10);
    case 3: return sign(rng) * std::ldexp(uniform(rng, 1, 2), pick(rng, -30, 30));
    case 4: return pick(rng, -8, 8) * half_pi;
    case 5: return pick(rng, -5, 5) + sign(rng) * std::ldexp(1.0, -pick(rng, 20, 52));
    case 6: return 0.0;
    default: {
        static constexpr double decimals[] = {0.1, 0.2, 0.3, 0.7, 1e-3, 2.5e-7, 3.14159, 1e10};
        return sign(rng) * decimals[pick(rng, 0, 7)];
    }
    }
}

// Exponents for Pow: thin integers (the powi path) and proper reals.
double random_exponent(Rng& rng) {
    static constexpr double reals[] = {0.5, 1.5, 2.5, -0.5, -1.25, 1.0 / 3.0, 0.7, 3.3};
    return chance(rng, 0.4) ? pick(rng, -3, 5) : reals[pick(rng, 0, 7)];
}

Expr leaf(Rng& rng, int num_vars) {
    if (chance(rng, 0.65)) return Expr{Op::Var, pick(rng, 0, num_vars - 1), 0.0, 0, {}};
    return constant(random_constant(rng));
}

// Often keeps an argument in the domain of sqrt/log/pow so that points are defined.
Expr nonnegative(Rng& rng, Expr e) {
    return chance(rng, 0.5) ? node(Op::Abs, {std::move(e)}) : e;
}

// ---- Boxes and points ----

double random_centre(Rng& rng) {
    const double tiny = std::ldexp(1.0, -pick(rng, 1, 50));
    switch (pick(rng, 0, 7)) {
    case 0: return uniform(rng, -10, 10);
    case 1: return pick(rng, -20, 20);
    case 2: return pick(rng, -20, 20) + sign(rng) * tiny;
    case 3: return pick(rng, -20, 20) + 0.5 + (chance(rng, 0.5) ? 0.0 : sign(rng) * tiny);
    case 4: {
        // Near multiples of pi/2, sometimes far out to exercise argument reduction.
        const double k = chance(rng, 0.8) ? pick(rng, -12, 12) : pick(rng, -1000000, 1000000);
        const double c = k * half_pi;
        return chance(rng, 0.3) ? c
                                : c + sign(rng) * std::ldexp(std::max(1.0, std::abs(c)), -pick(rng, 20, 52));
    }
    case 5: return chance(rng, 0.2) ? 0.0 : sign(rng) * std::ldexp(1.0, -pick(rng, 1, 60));
    case 6: return sign(rng) * std::ldexp(uniform(rng, 1, 2), pick(rng, 10, 60));
    default: return uniform(rng, -1000, -1);
    }
}

double random_width(Rng& rng, double centre) {
    switch (pick(rng, 0, 5)) {
    case 0: return 0.0;
    case 1:
        return chance(rng, 0.5) ? std::abs(centre) * std::ldexp(1.0, -pick(rng, 40, 52))
                                : std::ldexp(1.0, -pick(rng, 30, 60));
    case 2: return std::ldexp(uniform(rng, 1, 2), -pick(rng, 1, 20));
    case 3: return uniform(rng, 0.1, 3);
    case 4: return uniform(rng, 3, 100);
    default: return std::ldexp(uniform(rng, 1, 2), pick(rng, 10, 40));
    }
}

num::Interval random_interval(Rng& rng) {
    const double c = random_centre(rng);
    const double w = random_width(rng, c);
    const double u = chance(rng, 0.5) ? 0.5 : uniform(rng, 0, 1);
    num::Interval b{c - w * u, c + w * (1 - u)};
    if (chance(rng, 0.02)) (chance(rng, 0.5) ? b.lo : b.hi) = chance(rng, 0.5) ? -num::inf : num::inf;
    if (b.lo > b.hi) std::swap(b.lo, b.hi);
    return b;
}

// Sample points come from the bounded part of a coordinate interval (centres are below 2^61).
num::Interval bounded(num::Interval b) {
    return {std::max(b.lo, -1e30), std::min(b.hi, 1e30)};
}

double sample(Rng& rng, num::Interval b, int kind) {
    b = bounded(b);
    switch (kind) {
    case 0: return b.lo;
    case 1: return b.hi;
    case 2: return num::midpoint(b);
    default: {
        const int k = pick(rng, 0, 3);
        if (k < 2) return k == 0 ? b.lo : b.hi;
        return std::clamp(b.lo + uniform(rng, 0, 1) * (b.hi - b.lo), b.lo, b.hi);
    }
    }
}

// ---- MPFI evaluation ----

// Temporaries for the recursion, reused across calls (MPFI allocation dominates otherwise).
class Pool {
public:
    explicit Pool(int bits) : bits_(bits) {}
    Pool(const Pool&) = delete;
    Pool& operator=(const Pool&) = delete;
    ~Pool() {
        for (auto& v : values_) mpfi_clear(v->x);
    }
    int bits() const { return bits_; }

    // Stack discipline: a Slot returns its temporary on destruction.
    class Slot {
    public:
        explicit Slot(Pool& pool) : pool_(pool), x_(pool.take()) {}
        ~Slot() { --pool_.top_; }
        Slot(const Slot&) = delete;
        Slot& operator=(const Slot&) = delete;
        mpfi_ptr get() const { return x_; }

    private:
        Pool& pool_;
        mpfi_ptr x_;
    };

private:
    struct Value {
        mpfi_t x;
    };
    mpfi_ptr take() {
        if (top_ == values_.size()) {
            values_.push_back(std::make_unique<Value>());
            mpfi_init2(values_.back()->x, bits_);
        }
        return values_[top_++]->x;
    }
    int bits_;
    std::size_t top_ = 0;
    std::vector<std::unique_ptr<Value>> values_;
};

bool has_zero(mpfi_srcptr x) {
    return mpfr_sgn(&x->left) <= 0 && mpfr_sgn(&x->right) >= 0;
}
bool is_zero(mpfi_srcptr x) {
    return mpfr_zero_p(&x->left) && mpfr_zero_p(&x->right);
}
// Within the double range (with margin). MPFI's trigonometric functions take time proportional to
// the exponent of their argument, huge (sin(exp(exp(x)))) or tiny (sin(exp(-2^52))): minutes.
bool moderate(mpfi_srcptr x) {
    for (mpfr_srcptr v : {&x->left, &x->right})
        if (!mpfr_number_p(v) || (!mpfr_zero_p(v) && std::abs(mpfr_get_exp(v)) > 1100)) return false;
    return true;
}

class MpfiEvaluator {
public:
    MpfiEvaluator(Pool& pool, const double* point) : pool_(pool), point_(point) {}

    // out = an enclosure of e at the point; false when undefined or undecidable.
    bool eval(const Expr& e, mpfi_ptr out) {
        switch (e.op) {
        case Op::Const: mpfi_set_d(out, e.value); return true;
        case Op::Var: mpfi_set_d(out, point_[e.var]); return true;
        case Op::Add:
            return binary(e, out, [](mpfi_ptr r, mpfi_srcptr a, mpfi_srcptr b) {
                mpfi_add(r, a, b);
                return true;
            });
        case Op::Sub:
            return binary(e, out, [](mpfi_ptr r, mpfi_srcptr a, mpfi_srcptr b) {
                mpfi_sub(r, a, b);
                return true;
            });
        case Op::Mul:
            return binary(e, out, [](mpfi_ptr r, mpfi_srcptr a, mpfi_srcptr b) {
                mpfi_mul(r, a, b);
                return true;
            });
        case Op::Div:
            return binary(e, out, [](mpfi_ptr r, mpfi_srcptr a, mpfi_srcptr b) {
                if (has_zero(b)) return false;
                mpfi_div(r, a, b);
                return true;
            });
        case Op::Min:
        case Op::Max:
            return binary(e, out, [max = e.op == Op::Max](mpfi_ptr r, mpfi_srcptr a, mpfi_srcptr b) {
                auto f = max ? mpfr_max : mpfr_min;
                f(&r->left, &a->left, &b->left, MPFR_RNDD);
                f(&r->right, &a->right, &b->right, MPFR_RNDU);
                return true;
            });
        case Op::Atan2:
            return binary(e, out, [](mpfi_ptr r, mpfi_srcptr y, mpfi_srcptr x) {
                if (mpfr_sgn(&x->left) <= 0 && has_zero(y)) {
                    // On the negative x axis the angle is pi; the origin and "which side of the cut" are
                    // undecidable.
                    if (!is_zero(y) || mpfr_sgn(&x->right) >= 0) return false;
                    mpfi_const_pi(r);
                    return true;
                }
                mpfi_atan2(r, y, x);
                return true;
            });
        case Op::Pow: return pow(e, out);
        default: break;
        }
        if (!eval(e.args.at(0), out)) return false;
        switch (e.op) {
        case Op::Neg: mpfi_neg(out, out); return true;
        case Op::Sqr: mpfi_sqr(out, out); return true;
        case Op::Abs: mpfi_abs(out, out); return true;
        case Op::PowInt: return power(out, e.n);
        case Op::Sqrt:
            if (mpfr_sgn(&out->left) < 0) return false;
            mpfi_sqrt(out, out);
            return true;
        case Op::Log:
            if (mpfr_sgn(&out->left) <= 0) return false;
            mpfi_log(out, out);
            return true;
        case Op::Exp: mpfi_exp(out, out); return true;
        case Op::Sin:
            if (!moderate(out)) return false;
            mpfi_sin(out, out);
            return true;
        case Op::Cos:
            if (!moderate(out)) return false;
            mpfi_cos(out, out);
            return true;
        case Op::Tan:
            if (!moderate(out)) return false;
            mpfi_tan(out, out);
            return mpfr_number_p(&out->left) && mpfr_number_p(&out->right); // a pole may be inside
        case Op::Floor: return integer_part(out, mpfr_floor, false);
        case Op::Ceil: return integer_part(out, mpfr_ceil, false);
        case Op::Mod1: return integer_part(out, mpfr_floor, true);
        case Op::Dz: return dz(out);
        default: throw std::logic_error("eval_mpfi: unhandled op");
        }
    }

private:
    template <class F>
    bool binary(const Expr& e, mpfi_ptr out, F f) {
        Pool::Slot a(pool_), b(pool_);
        return eval(e.args.at(0), a.get()) && eval(e.args.at(1), b.get()) && f(out, a.get(), b.get());
    }

    // x^n; 0^0 = 1, negative powers need x != 0. Endpoint-wise on the monotone x^|n| (of |x| for even
    // n): mpfr_pow_ui is correctly rounded and exact where the power is representable.
    bool power(mpfi_ptr x, std::int64_t n) {
        if (n == 0) {
            mpfi_set_ui(x, 1);
            return true;
        }
        if (n < 0 && has_zero(x)) return false;
        const std::uint64_t m = n < 0 ? 0 - static_cast<std::uint64_t>(n) : n;
        if (m % 2 == 0) mpfi_abs(x, x);
        mpfr_pow_ui(&x->left, &x->left, m, MPFR_RNDD);
        mpfr_pow_ui(&x->right, &x->right, m, MPFR_RNDU);
        if (n < 0) mpfi_ui_div(x, 1, x);
        return true;
    }

    // num::pow semantics: an integer exponent gives an integer power, also of negative bases (which
    // every evaluator must see only when the exponent is a constant, so that its enclosure is thin);
    // otherwise x^y for x > 0, and 0^y = 0 for y > 0.
    bool pow(const Expr& e, mpfi_ptr out) {
        Pool::Slot y(pool_);
        if (!eval(e.args.at(0), out) || !eval(e.args.at(1), y.get())) return false;
        mpfr_srcptr y_lo = &y.get()->left;
        const bool integer = mpfr_equal_p(y_lo, &y.get()->right) && mpfr_integer_p(y_lo);
        if (integer && (e.args[1].op == Op::Const || mpfr_sgn(&out->left) > 0)) {
            if (mpfr_cmpabs_ui(y_lo, 1UL << 62) < 0) return power(out, mpfr_get_si(y_lo, MPFR_RNDN));
            mpfi_abs(out, out); // a double this large is an even integer
        }
        if (is_zero(out)) return mpfr_sgn(y_lo) > 0; // out stays [0, 0]
        if (mpfr_sgn(&out->left) <= 0) return false;
        // x^y is monotone in each argument, so its range over the box is spanned by the corners;
        // mpfr_pow is correctly rounded and exact where the power is representable (4^0.5 = 2).
        Pool::Slot lo(pool_), hi(pool_), t(pool_);
        mpfr_ptr l = &lo.get()->left, h = &hi.get()->left, c = &t.get()->left;
        mpfr_set_inf(l, 1);
        mpfr_set_inf(h, -1);
        for (mpfr_srcptr xv : {&out->left, &out->right})
            for (mpfr_srcptr yv : {y_lo, static_cast<mpfr_srcptr>(&y.get()->right)}) {
                mpfr_pow(c, xv, yv, MPFR_RNDD);
                mpfr_min(l, l, c, MPFR_RNDD);
                mpfr_pow(c, xv, yv, MPFR_RNDU);
                mpfr_max(h, h, c, MPFR_RNDU);
            }
        mpfr_swap(&out->left, l);
        mpfr_swap(&out->right, h);
        return true;
    }

    // floor/ceil (mod = false) or x - floor(x) (mod = true); undecidable across a discontinuity.
    bool integer_part(mpfi_ptr x, int (*round)(mpfr_ptr, mpfr_srcptr), bool mod) {
        Pool::Slot t(pool_);
        mpfr_ptr lo = &t.get()->left, hi = &t.get()->right;
        round(lo, &x->left); // exact: an integer part has no more bits than its argument
        round(hi, &x->right);
        if (!mpfr_equal_p(lo, hi)) return false;
        if (mod) {
            mpfr_sub(&x->left, &x->left, lo, MPFR_RNDD);
            mpfr_sub(&x->right, &x->right, lo, MPFR_RNDU);
        } else {
            mpfr_set(&x->left, lo, MPFR_RNDD);
            mpfr_set(&x->right, lo, MPFR_RNDU);
        }
        return true;
    }

    // Distance to the integers: hull of the endpoint values, plus 0 or 1/2 when an integer or a
    // half-integer lies inside. All steps are exact at the pool's precision for moderate magnitudes.
    bool dz(mpfi_ptr x) {
        const int bits = pool_.bits();
        for (mpfr_srcptr v : {&x->left, &x->right})
            if (!mpfr_number_p(v) || (!mpfr_zero_p(v) && mpfr_get_exp(v) > bits - 8)) return false;
        Pool::Slot s(pool_), t(pool_);
        mpfr_ptr a = &s.get()->left, b = &s.get()->right, c = &t.get()->left, d = &t.get()->right;
        auto distance = [&](mpfr_ptr r, mpfr_srcptr v) {
            mpfr_floor(c, v);
            mpfr_sub(c, v, c, MPFR_RNDN);
            mpfr_ceil(d, v);
            mpfr_sub(d, d, v, MPFR_RNDN);
            mpfr_min(r, c, d, MPFR_RNDN);
        };
        distance(a, &x->left);
        distance(b, &x->right);
        if (mpfr_greater_p(a, b)) mpfr_swap(a, b);
        mpfr_ceil(c, &x->left);
        if (mpfr_lessequal_p(c, &x->right)) mpfr_set_zero(a, 1);
        // Smallest odd integer >= 2 * left, compared with 2 * right.
        mpfr_mul_2ui(c, &x->left, 1, MPFR_RNDN);
        mpfr_ceil(c, c);
        mpfr_div_2ui(d, c, 1, MPFR_RNDN);
        if (mpfr_integer_p(d)) mpfr_add_ui(c, c, 1, MPFR_RNDN);
        mpfr_mul_2ui(d, &x->right, 1, MPFR_RNDN);
        if (mpfr_lessequal_p(c, d)) mpfr_set_d(b, 0.5, MPFR_RNDN);
        mpfr_set(&x->left, a, MPFR_RNDD);
        mpfr_set(&x->right, b, MPFR_RNDU);
        return true;
    }

    Pool& pool_;
    const double* point_;
};

// ---- Reporting ----

std::string fmt_double(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%a (%.17g)", v, v);
    return buf;
}

std::string fmt_interval(num::Interval a) {
    return "[" + fmt_double(a.lo) + ", " + fmt_double(a.hi) + "]";
}

void count_ops(const Expr& e, std::array<std::uint64_t, kNumOps>& counts) {
    ++counts[static_cast<int>(e.op)];
    for (const Expr& a : e.args) count_ops(a, counts);
}

} // namespace

const char* op_name(Op op) {
    switch (op) {
    case Op::Const: return "const";
    case Op::Var: return "var";
    case Op::Add: return "add";
    case Op::Sub: return "sub";
    case Op::Mul: return "mul";
    case Op::Div: return "div";
    case Op::Neg: return "neg";
    case Op::Sqr: return "sqr";
    case Op::PowInt: return "powi";
    case Op::Pow: return "pow";
    case Op::Sqrt: return "sqrt";
    case Op::Abs: return "abs";
    case Op::Min: return "min";
    case Op::Max: return "max";
    case Op::Floor: return "floor";
    case Op::Ceil: return "ceil";
    case Op::Mod1: return "mod1";
    case Op::Dz: return "dz";
    case Op::Sin: return "sin";
    case Op::Cos: return "cos";
    case Op::Tan: return "tan";
    case Op::Exp: return "exp";
    case Op::Log: return "log";
    case Op::Atan2: return "atan2";
    }
    return "?";
}

int arity(Op op) {
    switch (op) {
    case Op::Const:
    case Op::Var: return 0;
    case Op::Add:
    case Op::Sub:
    case Op::Mul:
    case Op::Div:
    case Op::Min:
    case Op::Max:
    case Op::Pow:
    case Op::Atan2: return 2;
    default: return 1;
    }
}

std::string to_string(const Expr& e) {
    switch (e.op) {
    case Op::Const: {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%a", e.value);
        return buf;
    }
    case Op::Var: return "x" + std::to_string(e.var);
    default: break;
    }
    std::string s = std::string(op_name(e.op)) + "(";
    for (std::size_t i = 0; i < e.args.size(); ++i) s += (i ? ", " : "") + to_string(e.args[i]);
    if (e.op == Op::PowInt) s += ", " + std::to_string(e.n);
    return s + ")";
}

std::size_t size(const Expr& e) {
    std::size_t n = 1;
    for (const Expr& a : e.args) n += size(a);
    return n;
}

Expr random_expr(std::mt19937_64& rng, int max_depth, int num_vars) {
    if (num_vars < 1) throw std::invalid_argument("random_expr: num_vars must be >= 1");
    if (max_depth <= 0 || chance(rng, 0.2)) return leaf(rng, num_vars);
    const auto op = static_cast<Op>(pick(rng, static_cast<int>(Op::Add), kNumOps - 1));
    auto sub = [&] { return random_expr(rng, max_depth - 1, num_vars); };
    switch (op) {
    case Op::PowInt: {
        Expr e = node(op, {sub()});
        e.n = pick(rng, -3, 5);
        return e;
    }
    case Op::Pow: {
        Expr base = nonnegative(rng, sub());
        return node(op, {std::move(base), chance(rng, 0.7) ? constant(random_exponent(rng)) : sub()});
    }
    case Op::Sqrt: return node(op, {nonnegative(rng, sub())});
    case Op::Log: {
        Expr arg = nonnegative(rng, sub());
        if (chance(rng, 0.3))
            arg = node(Op::Add, {std::move(arg), constant(std::ldexp(1.0, -pick(rng, 0, 30)))});
        return node(op, {std::move(arg)});
    }
    case Op::Div: {
        Expr num = sub();
        Expr den = sub();
        // Sometimes a denominator bounded away from zero, so that the quotient is defined everywhere.
        if (chance(rng, 0.3))
            den = node(Op::Add, {node(Op::Sqr, {std::move(den)}), constant(uniform(rng, 0.01, 2))});
        return node(op, {std::move(num), std::move(den)});
    }
    default: break;
    }
    std::vector<Expr> args;
    for (int i = 0; i < arity(op); ++i) args.push_back(sub());
    return node(op, std::move(args));
}

std::vector<num::Interval> random_box(std::mt19937_64& rng, int num_vars) {
    std::vector<num::Interval> box;
    for (int i = 0; i < num_vars; ++i) box.push_back(random_interval(rng));
    return box;
}

bool PointValue::precise() const {
    return outer.hi <= std::nextafter(outer.lo, num::inf);
}

std::optional<PointValue> eval_mpfi(const Expr& e, const double* point, int bits) {
    if (bits < 53) throw std::invalid_argument("eval_mpfi: need at least 53 bits");
    thread_local std::unique_ptr<Pool> pool;
    if (!pool || pool->bits() != bits) pool = std::make_unique<Pool>(bits);
    Pool::Slot result(*pool);
    mpfi_ptr r = result.get();
    if (!MpfiEvaluator(*pool, point).eval(e, r) || mpfi_nan_p(r)) return std::nullopt;
    PointValue v;
    v.outer = {mpfr_get_d(&r->left, MPFR_RNDD), mpfr_get_d(&r->right, MPFR_RNDU)};
    v.left_up = mpfr_get_d(&r->left, MPFR_RNDU);
    v.right_down = mpfr_get_d(&r->right, MPFR_RNDD);
    if (v.outer.lo == num::inf || v.outer.hi == -num::inf) return std::nullopt; // overflowed to one infinity
    return v;
}

num::Interval eval_reference(const Expr& e, const num::Interval* box) {
    auto arg = [&](int i) { return eval_reference(e.args[i], box); };
    switch (e.op) {
    case Op::Const: return e.value;
    case Op::Var: return box[e.var];
    case Op::Add: return num::add(arg(0), arg(1));
    case Op::Sub: return num::sub(arg(0), arg(1));
    case Op::Mul: return num::mul(arg(0), arg(1));
    case Op::Div: return num::div(arg(0), arg(1));
    case Op::Neg: return num::neg(arg(0));
    case Op::Sqr: return num::sqr(arg(0));
    case Op::PowInt: return num::powi(arg(0), e.n);
    case Op::Pow: return num::pow(arg(0), arg(1));
    case Op::Sqrt: return num::sqrt(arg(0));
    case Op::Abs: return num::abs(arg(0));
    case Op::Min: return num::min(arg(0), arg(1));
    case Op::Max: return num::max(arg(0), arg(1));
    case Op::Floor: return num::floor(arg(0));
    case Op::Ceil: return num::ceil(arg(0));
    case Op::Mod1: return num::mod1(arg(0));
    case Op::Dz: return num::dz(arg(0));
    case Op::Sin: return num::sin(arg(0));
    case Op::Cos: return num::cos(arg(0));
    case Op::Tan: return num::tan(arg(0));
    case Op::Exp: return num::exp(arg(0));
    case Op::Log: return num::log(arg(0));
    case Op::Atan2: return num::atan2(arg(0), arg(1));
    }
    throw std::logic_error("eval_reference: unhandled op");
}

bool Report::covered() const {
    for (int i = 0; i < kNumOps; ++i)
        if (op_checked[i] == 0) return false;
    return points_checked > pairs;
}

std::string Report::summary() const {
    std::string s = "pairs " + std::to_string(pairs) + ", points checked " + std::to_string(points_checked) +
                    ", skipped " + std::to_string(undefined_skipped) + " undefined, imprecise " +
                    std::to_string(imprecise) + ", violations " + std::to_string(violations) +
                    " (bad enclosures " + std::to_string(bad_enclosures) + ")\n";
    char buf[96];
    s += "per op (nodes drawn / in checked pairs):";
    for (int i = 0; i < kNumOps; ++i) {
        std::snprintf(buf, sizeof buf, "%s %s %llu/%llu", i % 6 == 0 ? "\n " : ",",
                      op_name(static_cast<Op>(i)), static_cast<unsigned long long>(op_nodes[i]),
                      static_cast<unsigned long long>(op_checked[i]));
        s += buf;
    }
    s += "\n";
    if (!first_violation.empty()) s += "first violation:\n" + first_violation;
    return s;
}

Report check_soundness(std::uint64_t n_pairs, std::uint64_t seed, int num_vars, const Enclosure& enclosure,
                       const Options& options) {
    Rng rng(seed);
    Report report;
    std::vector<double> point(num_vars);
    auto record = [&](std::uint64_t pair, const Expr& e, const std::vector<num::Interval>& box,
                      const char* what, num::Interval enc, const std::optional<PointValue>& exact) {
        ++report.violations;
        if (!report.first_violation.empty()) return;
        std::string s =
            "pair " + std::to_string(pair) + ": " + what + "\n  expr " + to_string(e) + "\n  box ";
        for (const num::Interval& b : box) s += fmt_interval(b) + " ";
        if (exact) {
            s += "\n  point ";
            for (double x : point) s += fmt_double(x) + " ";
            s += "\n  mpfi      " + fmt_interval(exact->outer) + (exact->precise() ? "" : " (imprecise)");
        }
        report.first_violation = s + "\n  enclosure " + fmt_interval(enc) + "\n";
    };

    const std::uint64_t boxes_per_expr = static_cast<std::uint64_t>(std::max(1, options.boxes_per_expr));
    const std::uint64_t exprs_per_block = static_cast<std::uint64_t>(std::max(1, options.exprs_per_block));
    std::vector<Expr> block;
    std::uint64_t next_in_block = 0;
    for (std::uint64_t pair = 0; pair < n_pairs; ++pair) {
        if (pair % boxes_per_expr == 0 && next_in_block == block.size()) {
            const std::uint64_t remaining = (n_pairs - pair + boxes_per_expr - 1) / boxes_per_expr;
            block.clear();
            for (std::uint64_t k = 0; k < std::min(exprs_per_block, remaining); ++k)
                block.push_back(random_expr(rng, options.max_depth, num_vars));
            next_in_block = 0;
            if (options.prepare) options.prepare(block);
        }
        const Expr& e = block[next_in_block];
        if (pair % boxes_per_expr == boxes_per_expr - 1) ++next_in_block;
        const std::vector<num::Interval> box = random_box(rng, num_vars);
        std::array<std::uint64_t, kNumOps> counts{};
        count_ops(e, counts);
        ++report.pairs;

        const int mode = std::fegetround();
        const num::Interval enc = enclosure(e, box.data());
        if (std::fegetround() != mode) {
            std::fesetround(mode);
            ++report.bad_enclosures;
            record(pair, e, box, "the evaluator did not restore the rounding mode", enc, std::nullopt);
        }
        if (std::isnan(enc.lo) || std::isnan(enc.hi)) {
            ++report.bad_enclosures;
            record(pair, e, box, "NaN bound", enc, std::nullopt);
        }

        bool checked = false;
        for (int k = 0; k < options.points_per_pair; ++k) {
            for (int i = 0; i < num_vars; ++i) point[i] = sample(rng, box[i], k);
            const std::optional<PointValue> exact = eval_mpfi(e, point.data(), options.bits);
            if (!exact) {
                ++report.undefined_skipped;
                continue;
            }
            ++report.points_checked;
            checked = true;
            if (!exact->precise()) ++report.imprecise;
            if (!exact->admits(enc)) record(pair, e, box, "enclosure misses the exact value", enc, exact);
        }
        for (int i = 0; i < kNumOps; ++i) {
            report.op_nodes[i] += counts[i];
            if (checked) report.op_checked[i] += counts[i];
        }
    }
    return report;
}

} // namespace frac::oracle
