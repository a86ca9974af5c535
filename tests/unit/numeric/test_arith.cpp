// Rounding mode, arithmetic, powers, set operations, constants and decimal literals.
#include "helpers.hpp"

#include <cfenv>
#include <limits>
#include <stdexcept>
#include <vector>

TEST_CASE("UpwardRounding sets upward rounding and restores the previous mode", "[numeric][rounding]") {
    REQUIRE(std::fegetround() == FE_TONEAREST);
    REQUIRE_FALSE(num::rounding_is_upward());
    {
        UpwardRounding upward;
        CHECK(num::rounding_is_upward());
        {
            UpwardRounding nested;
            CHECK(num::rounding_is_upward());
        }
        CHECK(num::rounding_is_upward());
    }
    CHECK(std::fegetround() == FE_TONEAREST);
    std::fesetround(FE_DOWNWARD);
    {
        UpwardRounding upward;
        CHECK(num::rounding_is_upward());
    }
    CHECK(std::fegetround() == FE_DOWNWARD);
    std::fesetround(FE_TONEAREST);
}

TEST_CASE("add and sub round outward and keep exact results thin", "[numeric][arith]") {
    UpwardRounding upward;
    CHECK(num::add({1, 2}, {3, 4}) == Interval(4, 6));
    CHECK(num::add(0.5, 0.25) == Interval(0.75));
    CHECK(num::sub({1, 2}, {3, 5}) == Interval(-4, -1));
    CHECK(num::sub(0.75, 0.25) == Interval(0.5));

    // 0.1 + 0.2 is not a double: the result must be the two neighbours of the exact sum.
    const long double sum = static_cast<long double>(0.1) + static_cast<long double>(0.2); // exact
    const Interval s = num::add(0.1, 0.2);
    CHECK(tight(s, sum, 1));
    const Interval d = num::sub(0.1, -0.2);
    CHECK(d == s);
    CHECK(num::sub(1.0, 0x1p-60) == Interval(down(1.0), 1.0));
    CHECK(num::add(-1.0, -0x1p-60) == Interval(down(-1.0), -1.0));

    CHECK(num::add({1, inf}, {-inf, 2}) == R);
    CHECK(num::add({dmax, dmax}, {dmax, dmax}) == Interval(dmax, inf));
    CHECK(num::sub({-dmax, -dmax}, {dmax, dmax}) == Interval(-inf, -dmax));
}

TEST_CASE("mul: corners, signs, 0 * inf = 0", "[numeric][arith]") {
    UpwardRounding upward;
    CHECK(num::mul({-1, 2}, {3, 4}) == Interval(-4, 8));
    CHECK(num::mul({-3, -2}, {-5, 4}) == Interval(-12, 15));
    CHECK(num::mul({2, 3}, {4, 5}) == Interval(8, 15));
    CHECK(num::mul(0.0, R) == Interval(0, 0));
    CHECK(num::mul({0, 1}, R) == R);
    CHECK(num::mul({0, 1}, {0, inf}) == Interval(0, inf));
    CHECK(num::mul({1, 2}, {-inf, -1}) == Interval(-inf, -1));
    CHECK(tight(num::mul(0.1, 0.1), static_cast<long double>(0.1) * static_cast<long double>(0.1), 1));
    CHECK(tight(num::mul(-0.1, 0.3), -static_cast<long double>(0.1) * static_cast<long double>(0.3), 1));
    CHECK(num::mul({dmax, dmax}, 2.0) == Interval(dmax, inf));
    CHECK(num::mul(0x1p-1074, 0.5) == Interval(0, 0x1p-1074));
}

TEST_CASE("div: exact, inexact, and divisors containing zero", "[numeric][arith]") {
    UpwardRounding upward;
    CHECK(num::div({1, 2}, {4, 8}) == Interval(0.125, 0.5));
    CHECK(num::div({-1, 2}, {-4, -2}) == Interval(-1, 0.5));
    CHECK(tight(num::div(1.0, 3.0), 1.0L / 3.0L, 1));
    CHECK(tight(num::div(-1.0, 3.0), -1.0L / 3.0L, 1));
    CHECK(num::div({1, 2}, {0, 1}) == Interval(1, inf));
    CHECK(num::div({1, 2}, {-1, 0}) == Interval(-inf, -1));
    CHECK(num::div({-2, -1}, {0, 1}) == Interval(-inf, -1));
    CHECK(num::div({-2, -1}, {-4, 0}) == Interval(0.25, inf));
    CHECK(num::div({1, 2}, {-1, 1}) == R);
    CHECK(num::div({-1, 1}, {0, 1}) == R);
    CHECK(num::div({0, 1}, {0, 1}) == Interval(0, inf));
    CHECK(num::div(0.0, {-1, 1}) == Interval(0, 0));
    CHECK(num::div({1, 2}, 0.0).is_empty());
    CHECK(num::div(0.0, 0.0).is_empty());
    CHECK(num::div({1, 2}, {1, inf}) == Interval(0, 2));
    CHECK(num::div({1, inf}, {1, inf}) == Interval(0, inf));
}

TEST_CASE("neg, abs, min, max, hull, intersect", "[numeric][arith]") {
    UpwardRounding upward;
    CHECK(num::neg({1, 2}) == Interval(-2, -1));
    CHECK(num::neg(E).is_empty());
    CHECK(num::abs({-3, 2}) == Interval(0, 3));
    CHECK(num::abs({-3, -2}) == Interval(2, 3));
    CHECK(num::abs({1, 2}) == Interval(1, 2));
    CHECK(num::min({1, 4}, {2, 3}) == Interval(1, 3));
    CHECK(num::max({1, 4}, {2, 3}) == Interval(2, 4));
    CHECK(num::hull({1, 2}, {4, 5}) == Interval(1, 5));
    CHECK(num::hull(E, {4, 5}) == Interval(4, 5));
    CHECK(num::hull({4, 5}, E) == Interval(4, 5));
    CHECK(num::intersect({1, 3}, {2, 5}) == Interval(2, 3));
    CHECK(num::intersect({1, 2}, {3, 4}).is_empty());
    CHECK(num::intersect({1, 2}, {2, 4}) == Interval(2, 2));
}

TEST_CASE("width, midpoint, magnitude", "[numeric][arith]") {
    for (const bool upward : {false, true}) {
        std::fesetround(upward ? FE_UPWARD : FE_TONEAREST);
        // 1 - 2^-60 is not a double: the width must be rounded up in either mode.
        CHECK(num::width({-0x1p-60, 1.0}) == up(1.0));
        CHECK(num::width({1, 3}) == 2);
        CHECK(num::width(E) == 0);
        CHECK(num::width({0, inf}) == inf);
    }
    std::fesetround(FE_TONEAREST);
    CHECK(num::midpoint({1, 3}) == 2);
    CHECK(num::midpoint({dmax, dmax}) == dmax);
    CHECK(num::midpoint({-dmax, dmax}) == 0);
    CHECK(num::midpoint(R) == 0);
    CHECK(num::midpoint({0, inf}) == dmax);
    CHECK(num::midpoint({-inf, 0}) == -dmax);
    CHECK(num::midpoint({0x1p-1074, 0x1p-1074}) == 0x1p-1074);
    CHECK(std::isnan(num::midpoint(E)));
    CHECK(num::magnitude({-3, 2}) == 3);
    CHECK(num::magnitude({-inf, 2}) == inf);
    CHECK(num::magnitude(E) == 0);
}

TEST_CASE("sqr and powi are tight and handle signs", "[numeric][pow]") {
    UpwardRounding upward;
    CHECK(num::sqr({-1, 2}) == Interval(0, 4));
    CHECK(num::sqr({-3, -2}) == Interval(4, 9));
    CHECK(num::sqr({2, 3}) == Interval(4, 9));
    CHECK(tight(num::sqr(0.1), static_cast<long double>(0.1) * static_cast<long double>(0.1), 1));
    CHECK(num::powi({-2, 3}, 2) == Interval(0, 9));
    CHECK(num::powi({-2, 3}, 3) == Interval(-8, 27));
    CHECK(num::powi({-3, -2}, 3) == Interval(-27, -8));
    CHECK(num::powi({-3, -2}, 4) == Interval(16, 81));
    CHECK(num::powi({-1, 1}, 0) == Interval(1, 1));
    CHECK(num::powi(0.0, 0) == Interval(1, 1));
    CHECK(num::powi({2, 4}, -1) == Interval(0.25, 0.5));
    CHECK(num::powi({-4, -2}, -2) == Interval(0.0625, 0.25));
    CHECK(num::powi({-1, 1}, -2) == Interval(1, inf));
    CHECK(num::powi({-1, 1}, -1) == R);
    CHECK(num::powi({0, 2}, -1) == Interval(0.5, inf));
    const long double x = static_cast<long double>(1.1);
    CHECK(encloses(num::powi(1.1, 5), x * x * x * x * x));
    CHECK(encloses(num::powi(-1.1, 5), -x * x * x * x * x));
    CHECK(num::powi({2, 2}, 1100) == Interval(dmax, inf));
    const Interval tiny = num::powi({2, 2}, -1100);
    CHECK(tiny.lo == 0);
    CHECK((tiny.hi > 0 && tiny.hi < 1e-300));
    CHECK(num::powi({-1, 1}, std::numeric_limits<std::int64_t>::min()) == Interval(1, inf));
    CHECK(num::powi(E, 3).is_empty());
}

TEST_CASE("pow: integer exponents, domain of real exponents, 0^b", "[numeric][pow]") {
    UpwardRounding upward;
    CHECK(num::pow({-8, -8}, 3.0) == Interval(-512, -512));
    CHECK(num::pow({-2, 3}, 2.0) == Interval(0, 9));
    CHECK(encloses(num::pow(4.0, 0.5), 2.0L));
    CHECK(num::width(num::pow(4.0, 0.5)) < 1e-14);
    CHECK(encloses(num::pow(2.0, 0.5), 1.41421356237309504880L));
    CHECK(num::pow({-2, -1}, 0.5).is_empty());
    CHECK(num::pow(0.0, 2.5) == Interval(0, 0));
    CHECK(num::pow(0.0, -2.5).is_empty());
    const Interval p = num::pow({-1, 4}, 0.5);
    CHECK(p.lo <= 0);
    CHECK(encloses(p, 2.0L));
    CHECK(num::pow({0, 1}, -0.5).hi == inf);
    CHECK(encloses(num::pow({2, 2}, {1, 3}), 8.0L));
    CHECK(encloses(num::pow({2, 2}, {1, 3}), 2.0L));
    // Huge thin exponents are even integers: the sign of the base does not matter.
    CHECK(num::pow({-1, -1}, 1e300).contains(1.0));
}

TEST_CASE("sqrt: exact squares stay exact, domain is restricted", "[numeric][pow]") {
    UpwardRounding upward;
    CHECK(num::sqrt(4.0) == Interval(2, 2));
    CHECK(num::sqrt({4, 9}) == Interval(2, 3));
    CHECK(num::sqrt(0.0) == Interval(0, 0));
    CHECK(num::sqrt({-1, 4}) == Interval(0, 2));
    CHECK(num::sqrt({-2, -1}).is_empty());
    CHECK(num::sqrt({0, inf}) == Interval(0, inf));
    CHECK(tight(num::sqrt(2.0), 1.41421356237309504880L, 1));
    CHECK(tight(num::sqrt(0.1), std::sqrt(static_cast<long double>(0.1)), 1));
}

TEST_CASE("empty propagates and NaN never appears", "[numeric][special]") {
    UpwardRounding upward;
    using Unary = Interval (*)(Interval);
    using Binary = Interval (*)(Interval, Interval);
    const std::vector<Unary> unary = {num::neg,  num::sqr,  num::sqrt, num::abs, num::floor,
                                      num::ceil, num::mod1, num::dz,   num::sin, num::cos,
                                      num::tan,  num::exp,  num::log};
    const std::vector<Binary> binary = {num::add, num::sub, num::mul, num::div,
                                        num::pow, num::min, num::max, num::atan2};
    const std::vector<Interval> specials = {R,           {-inf, 0},   {0, inf},     {-inf, -1},
                                            {1, inf},    {0, 0},      {-1, 1},      {-dmax, dmax},
                                            {-0.0, 0.0}, {dmax, inf}, {-inf, -dmax}};
    for (Unary f : unary) {
        CHECK(f(E).is_empty());
        for (Interval a : specials) {
            const Interval r = f(a);
            CHECK_FALSE((std::isnan(r.lo) || std::isnan(r.hi)));
        }
    }
    for (Binary f : binary) {
        CHECK(f(E, {1, 2}).is_empty());
        CHECK(f({1, 2}, E).is_empty());
        for (Interval a : specials)
            for (Interval b : specials) {
                const Interval r = f(a, b);
                CHECK_FALSE((std::isnan(r.lo) || std::isnan(r.hi)));
            }
    }
    for (std::int64_t n = -3; n <= 5; ++n)
        for (Interval a : specials) {
            const Interval r = num::powi(a, n);
            CHECK_FALSE((std::isnan(r.lo) || std::isnan(r.hi)));
        }
}

TEST_CASE("pi and e are outward enclosures", "[numeric][constants]") {
    CHECK(tight(num::pi(), 3.14159265358979323846264338327950288L, 1));
    CHECK(tight(num::e(), 2.71828182845904523536028747135266250L, 1));
}

TEST_CASE("from_decimal encloses decimal literals and restores the rounding mode", "[numeric][decimal]") {
    const Interval tenth = num::from_decimal("0.1");
    CHECK(tenth.lo < tenth.hi);
    CHECK(tenth.hi == 0.1); // RN(0.1) lies above 0.1
    CHECK(tenth.lo == down(0.1));
    CHECK(std::fegetround() == FE_TONEAREST);
    {
        UpwardRounding upward;
        CHECK(num::from_decimal("0.1") == tenth);
        CHECK(num::rounding_is_upward());
    }
    CHECK(num::from_decimal("0.5") == Interval(0.5));
    CHECK(num::from_decimal("-0.1") == Interval(-0.1, -down(0.1)));
    CHECK(num::from_decimal("3") == Interval(3));
    CHECK(num::from_decimal("1e400") == Interval(dmax, inf));
    CHECK(num::from_decimal("1e-400") == Interval(0, 0x1p-1074));
    CHECK(tight(num::from_decimal("3.14159265358979323846"), 3.14159265358979323846L, 1));
    CHECK_THROWS_AS(num::from_decimal(""), std::invalid_argument);
    CHECK_THROWS_AS(num::from_decimal("0.1x"), std::invalid_argument);
    CHECK(std::fegetround() == FE_TONEAREST);
}
