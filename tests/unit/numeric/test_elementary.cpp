// floor/ceil/mod1/dz and the elementary functions sin, cos, tan, exp, log, atan2.
#include "helpers.hpp"

#include <limits>

namespace {

constexpr long double sin1 = 0.841470984807896506652502321630298999622563L;
constexpr long double cos1 = 0.540302305868139717400936607442976603732310L;
constexpr long double sin2 = 0.909297426825681695396019865911744842702254L;
constexpr long double cos2 = -0.416146836547142386997568229500762189766000L;
constexpr long double tan1 = 1.557407724654902230506974807458360173087250L;
constexpr long double e1 = 2.718281828459045235360287471352662497757247L;
constexpr long double ln2 = 0.693147180559945309417232121458176568075500L;
constexpr long double pi_ld = 3.141592653589793238462643383279502884197169L;

// Reference values of a long double function, evaluated in round-to-nearest.
long double ref(long double (*f)(long double), double x) {
    return f(static_cast<long double>(x));
}
long double sinl_(long double x) {
    return std::sin(x);
}
long double cosl_(long double x) {
    return std::cos(x);
}
long double tanl_(long double x) {
    return std::tan(x);
}
long double atan2l_(long double y, long double x) {
    return std::atan2(y, x);
}

bool within_pi(Interval a) {
    return num::pi().hi >= a.hi && -num::pi().hi <= a.lo;
}
} // namespace

TEST_CASE("floor and ceil are exact", "[numeric][integer]") {
    UpwardRounding upward;
    CHECK(num::floor({-1.5, 2.5}) == Interval(-2, 2));
    CHECK(num::ceil({-1.5, 2.5}) == Interval(-1, 3));
    CHECK(num::floor(3.0) == Interval(3));
    CHECK(num::floor(R) == R);
    CHECK(num::ceil({-inf, 0.5}) == Interval(-inf, 1));
}

TEST_CASE("mod1 across integer boundaries", "[numeric][integer]") {
    UpwardRounding upward;
    CHECK(num::mod1({2.25, 2.75}) == Interval(0.25, 0.75));
    CHECK(num::mod1({-0.75, -0.25}) == Interval(0.25, 0.75));
    CHECK(num::mod1(3.0) == Interval(0, 0));
    CHECK(num::mod1({0.5, 1.5}) == Interval(0, 1));
    CHECK(num::mod1({2.5, 3.0}) == Interval(0, 1));
    CHECK(num::mod1(R) == Interval(0, 1));
    // 1 - 2^-60 is not a double: the bounds must be rounded outward.
    CHECK(num::mod1(-0x1p-60) == Interval(down(1.0), 1.0));
    CHECK(num::point::mod1(-0.25) == 0.75);
    CHECK(num::point::mod1(2.5) == 0.5);
}

TEST_CASE("dz: within one period, across integers and half-integers", "[numeric][integer]") {
    UpwardRounding upward;
    CHECK(num::dz({0.1, 0.2}) == Interval(0.1, 0.2));
    const Interval falling = num::dz({0.7, 0.9});
    CHECK(encloses(falling, 1 - static_cast<long double>(0.9)));
    CHECK(encloses(falling, 1 - static_cast<long double>(0.7)));
    CHECK(falling.lo > 0.09);
    CHECK(falling.hi < 0.31);
    const Interval across_integer = num::dz({0.9, 1.1});
    CHECK(across_integer.lo == 0);
    CHECK(encloses(across_integer, static_cast<long double>(1.1) - 1));
    CHECK(across_integer.hi < 0.11);
    const Interval across_half = num::dz({0.4, 0.6});
    CHECK(across_half.hi == 0.5);
    CHECK(across_half.lo <= 0.4);
    CHECK(across_half.lo > 0.39);
    CHECK(num::dz({0.25, 0.75}) == Interval(0.25, 0.5));
    CHECK(num::dz({-0.3, 0.2}) == Interval(0, 0.3));
    CHECK(num::dz(3.0) == Interval(0, 0));
    CHECK(num::dz(3.5) == Interval(0.5, 0.5));
    CHECK(num::dz(-2.75) == Interval(0.25, 0.25));
    CHECK(num::dz(-0x1p-60) == Interval(0x1p-60, 0x1p-60));
    CHECK(num::dz({0.5, 1.5}) == Interval(0, 0.5));
    CHECK(num::dz({0.25, 1.3}) == Interval(0, 0.5));
    CHECK(num::dz(R) == Interval(0, 0.5));
    CHECK(num::dz(1e17) == Interval(0, 0));
    CHECK(num::dz({0x1p52 - 0.5, 0x1p52}) == Interval(0, 0.5));
    CHECK(num::dz({-0x1p52, -0x1p52 + 0.5}) == Interval(0, 0.5));
    CHECK(num::point::dz(0.25) == 0.25);
    CHECK(num::point::dz(0.75) == 0.25);
    CHECK(num::point::dz(-0.25) == 0.25);
}

TEST_CASE("sin: correctly rounded points, extrema inclusion", "[numeric][trig]") {
    const long double s01 = ref(sinl_, 0.1), s02 = ref(sinl_, 0.2), s4 = ref(sinl_, 4.0);
    UpwardRounding upward;
    CHECK(num::sin(0.0) == Interval(0, 0));
    CHECK(tight(num::sin(1.0), sin1, 1));
    CHECK(tight(num::sin(-1.0), -sin1, 1));
    // Monotone piece: no extremum inside.
    const Interval inc = num::sin({0.1, 0.2});
    CHECK((encloses(inc, s01) && encloses(inc, s02)));
    CHECK((inc.lo > 0.09 && inc.hi < 0.2));
    // [1, 2] contains pi/2.
    const Interval top = num::sin({1, 2});
    CHECK(top.hi == 1);
    CHECK((encloses(top, sin1) && top.lo > 0.84));
    // [4, 5] contains 3 pi/2.
    const Interval bottom = num::sin({4, 5});
    CHECK(bottom.lo == -1);
    CHECK((encloses(bottom, s4) && bottom.hi < -0.75));
    // The doubles around pi/2: RN(pi/2) < pi/2 < its successor.
    const double half_pi = 1.5707963267948966;
    CHECK(num::sin({half_pi, up(half_pi)}).hi == 1);
    // num::sin(RN(pi)) = 1.22e-16 > 0.
    const Interval near_pi = num::sin(3.141592653589793);
    CHECK((near_pi.lo > 0 && near_pi.hi < 1.3e-16));
    CHECK(num::sin({0, 7}) == Interval(-1, 1));
    CHECK(num::sin({-inf, 0}) == Interval(-1, 1));
    CHECK(num::sin(1e300) == Interval(-1, 1));
}

TEST_CASE("cos: correctly rounded points, extrema inclusion", "[numeric][trig]") {
    const long double c3 = ref(cosl_, 3.0), c32 = ref(cosl_, 3.2);
    UpwardRounding upward;
    CHECK(num::cos(0.0) == Interval(1, 1));
    CHECK(tight(num::cos(1.0), cos1, 2));
    CHECK(tight(num::cos(-1.0), cos1, 2));
    CHECK(tight(num::cos(2.0), cos2, 2));
    const Interval dec = num::cos({1, 2});
    CHECK((encloses(dec, cos1) && encloses(dec, cos2)));
    CHECK((dec.lo > -0.42 && dec.hi < 0.55));
    CHECK(num::cos({-0.1, 0.1}).hi == 1);
    const Interval bottom = num::cos({3, 3.2});
    CHECK(bottom.lo == -1);
    CHECK((encloses(bottom, c3) && encloses(bottom, c32) && bottom.hi < -0.98));
    CHECK(num::cos({-1, 7}) == Interval(-1, 1));
    CHECK(num::cos(R) == Interval(-1, 1));
}

TEST_CASE("tan: monotone between poles, entire across a pole", "[numeric][trig]") {
    const long double t3 = ref(tanl_, 3.0), t32 = ref(tanl_, 3.2);
    UpwardRounding upward;
    CHECK(num::tan(0.0) == Interval(0, 0));
    CHECK(tight(num::tan(1.0), tan1, 1));
    const Interval sym = num::tan({-1, 1});
    CHECK((encloses(sym, -tan1) && encloses(sym, tan1) && sym.hi < 1.56));
    CHECK(num::tan({1.5, 1.6}) == R);
    CHECK(num::tan({-1.6, -1.5}) == R);
    CHECK(num::tan({4.7, 4.8}) == R);
    // Around pi (a zero, not a pole) tan stays finite.
    const Interval around_pi = num::tan({3, 3.2});
    CHECK((encloses(around_pi, t3) && encloses(around_pi, t32) && around_pi.hi < 0.06));
    // num::tan(RN(pi/2)) = 1.633e16: the point lies just below the pole.
    CHECK(encloses(num::tan(1.5707963267948966), 1.633123935319537e16L));
    CHECK(num::tan(R) == R);
}

TEST_CASE("exp and log: exact points, limits, domain", "[numeric][explog]") {
    UpwardRounding upward;
    CHECK(num::exp(0.0) == Interval(1, 1));
    CHECK(tight(num::exp(1.0), e1, 2));
    CHECK(num::exp({-inf, 0}) == Interval(0, 1));
    CHECK(num::exp(1000.0) == Interval(dmax, inf));
    CHECK(num::exp(-1000.0) == Interval(0, 0x1p-1074));
    const Interval e12 = num::exp({1, 2});
    CHECK((encloses(e12, e1) && encloses(e12, e1 * e1)));
    CHECK(num::log(1.0) == Interval(0, 0));
    CHECK(tight(num::log(2.0), ln2, 2));
    CHECK(encloses(num::log(num::e()), 1.0L));
    CHECK(num::log({0, 1}) == Interval(-inf, 0));
    CHECK(num::log({-1, 1}) == Interval(-inf, 0));
    CHECK(num::log({-2, -1}).is_empty());
    CHECK(num::log(0.0).is_empty());
    CHECK(num::log({1, inf}) == Interval(0, inf));
}

TEST_CASE("atan2 across quadrants, the branch cut and the origin", "[numeric][trig]") {
    const long double q2_lo = atan2l_(2, -1), q2_hi = atan2l_(1, -2);
    UpwardRounding upward;
    const Interval full{-num::pi().hi, num::pi().hi};
    const Interval diag = num::atan2(1.0, 1.0);
    CHECK(tight(diag, pi_ld / 4, 8));
    // Quadrant II: angles between num::atan2(2, -1) and num::atan2(1, -2).
    const Interval q2 = num::atan2({1, 2}, {-2, -1});
    CHECK((encloses(q2, q2_lo) && encloses(q2, q2_hi)));
    CHECK((q2.lo > 2.03 && q2.hi < 2.68));
    const Interval q3 = num::atan2({-2, -1}, {-2, -1});
    CHECK((encloses(q3, -q2_lo) && encloses(q3, -q2_hi)));
    CHECK((q3.lo > -2.68 && q3.hi < -2.03));
    const Interval q4 = num::atan2({-2, -1}, {1, 2});
    CHECK((q4.lo > -1.11 && q4.hi < -0.46));
    CHECK(encloses(num::atan2(1.0, 0.0), pi_ld / 2));
    const Interval upper = num::atan2({1, 2}, {-1, 1});
    CHECK((encloses(upper, pi_ld / 4) && encloses(upper, 3 * pi_ld / 4)));
    // Straddling the positive x axis is fine; the negative one is the branch cut.
    const Interval right = num::atan2({-1, 1}, {1, 2});
    CHECK((encloses(right, -pi_ld / 4) && encloses(right, pi_ld / 4) && right.hi < 0.79));
    CHECK(num::atan2({-1, 1}, {-2, -1}) == full);
    // A box touching the cut from above (y >= 0) sees only angles up to pi: atan2(0, x < 0) = pi.
    const Interval touching = num::atan2({0, 1}, {-2, -1});
    CHECK((encloses(touching, pi_ld) && encloses(touching, 3 * pi_ld / 4) && touching.lo > 2.3));
    const Interval on_cut = num::atan2(0.0, -1.0);
    CHECK((encloses(on_cut, pi_ld) && on_cut.lo > 3.14));
    CHECK(num::atan2(-0.0, -1.0) == on_cut); // the real number 0 has no sign
    // From below, y = 0 with x < 0 has angle pi while the rest is near -pi: every angle.
    CHECK(num::atan2({-1, 0}, {-2, -1}) == full);
    CHECK(encloses(full, pi_ld));
    // Boxes containing the origin.
    CHECK(num::atan2({-1, 1}, {-1, 1}) == full);
    CHECK(num::atan2({-1, 0}, {-1, 1}) == full);
    const Interval upper_origin = num::atan2({0, 1}, {-1, 1});
    CHECK((upper_origin.lo == 0 && encloses(upper_origin, pi_ld)));
    CHECK(num::atan2(0.0, {0, 1}).lo == 0);
    const Interval unbounded = num::atan2({1, inf}, {1, inf});
    CHECK((unbounded.lo <= 1e-300 && encloses(unbounded, pi_ld / 2)));
    for (Interval a : {diag, q2, q3, q4, upper, right, unbounded}) CHECK(within_pi(a));
}
