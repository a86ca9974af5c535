// Exact rationals: arithmetic, powers, decimal parsing, text and the outward enclosure.
#include "helpers.hpp"

#include "numeric/rational.hpp"

#include <cfloat>
#include <random>
#include <stdexcept>
#include <string>

using num::Rational;

namespace {
Rational q(const char* text) {
    const auto r = Rational::parse_decimal(text);
    REQUIRE(r);
    return *r;
}
} // namespace

TEST_CASE("rational arithmetic is exact", "[numeric][rational]") {
    CHECK(Rational(1, 3) + Rational(1, 6) == Rational(1, 2));
    CHECK(Rational(1, 3) - Rational(1, 2) == Rational(-1, 6));
    CHECK(Rational(2, 3) * Rational(9, 4) == Rational(3, 2));
    CHECK(Rational(2, 3) / Rational(4, 9) == Rational(3, 2));
    CHECK(-Rational(5, 7) == Rational(-5, 7));
    CHECK(Rational(6, -4) == Rational(-3, 2)); // canonical: sign on the numerator, lowest terms
    CHECK(Rational(6, -4).numerator() == -3);
    CHECK(Rational(6, -4).denominator() == 2);
    CHECK(num::abs(Rational(-7, 3)) == Rational(7, 3));
    CHECK_THROWS_AS(Rational(1, 0), std::domain_error);
    CHECK_THROWS_AS(Rational(1) / Rational(0), std::domain_error);

    // 1/10 summed ten times is 1 exactly (in doubles it is not).
    Rational sum;
    for (int i = 0; i < 10; ++i) sum += Rational(1, 10);
    CHECK(sum == Rational(1));
}

TEST_CASE("rationals compare exactly", "[numeric][rational]") {
    CHECK(Rational(1, 3) < Rational(1, 2));
    CHECK(Rational(-1, 2) < Rational(-1, 3));
    CHECK(Rational(2, 4) == Rational(1, 2));
    CHECK(Rational(2, 4) >= Rational(1, 2));
    CHECK(Rational(1, 3) != Rational::from_double(1.0 / 3.0));
    CHECK(Rational(1) > Rational::from_double(std::nextafter(1.0, 0.0)));
    CHECK(Rational().is_zero());
    CHECK(Rational(-3).sign() == -1);
    CHECK(Rational(4, 2).is_integer());
    CHECK_FALSE(Rational(1, 2).is_integer());
}

TEST_CASE("rational powers by integer exponents", "[numeric][rational]") {
    CHECK(num::pow(Rational(2, 3), 3) == Rational(8, 27));
    CHECK(num::pow(Rational(-2, 3), 3) == Rational(-8, 27));
    CHECK(num::pow(Rational(-2, 3), -2) == Rational(9, 4));
    CHECK(num::pow(Rational(-2, 3), -3) == Rational(-27, 8));
    CHECK(num::pow(Rational(0), 0) == Rational(1));
    CHECK(num::pow(Rational(0), 5) == Rational(0));
    CHECK_THROWS_AS(num::pow(Rational(0), -1), std::domain_error);
    CHECK(num::pow(Rational(3), 20) == Rational(3486784401L));
    CHECK(num::pow(Rational(10), -3) == q("0.001"));
}

TEST_CASE("decimal literals parse exactly", "[numeric][rational]") {
    CHECK(q("0.1") == Rational(1, 10));
    CHECK(q("0.1") * Rational(3) == q("0.3"));
    CHECK(q("0.1") * Rational(3) == Rational(3, 10));
    CHECK(q("1e-3") == Rational(1, 1000));
    CHECK(q("2.5E+2") == Rational(250));
    CHECK(q("-1.25") == Rational(-5, 4));
    CHECK(q("+7") == Rational(7));
    CHECK(q(".5") == Rational(1, 2));
    CHECK(q("5.") == Rational(5));
    CHECK(q("00012.3400e-0002") == Rational(1234, 10000));
    CHECK(q("0") == Rational(0));
    CHECK(q("1e-400") == num::pow(Rational(10), -400));
    for (const char* bad : {"", ".", "-", "1e", "1e+", "e3", "3^20", "1/3", "0x10", "1.2.3", "1e3.5", " 1",
                            "1 ", "--1", "1e999999999", "inf", "nan"}) {
        INFO(bad);
        CHECK_FALSE(Rational::parse_decimal(bad));
    }
}

TEST_CASE("rationals print in lowest terms", "[numeric][rational]") {
    CHECK(Rational(1, 3).to_string() == "1/3");
    CHECK(Rational(-2).to_string() == "-2");
    CHECK(Rational(4, -6).to_string() == "-2/3");
    CHECK(Rational().to_string() == "0");
    CHECK(q("0.125").to_string() == "1/8");
    CHECK(Rational(1, 3).to_double() == 1.0 / 3.0);
    CHECK(Rational::from_double(0.1).to_double() == 0.1);
}

TEST_CASE("enclose gives the two doubles around a rational", "[numeric][rational][enclose]") {
    const Rational third(1, 3);
    const Interval e = num::enclose(third);
    CHECK(Rational::from_double(e.lo) < third);
    CHECK(third < Rational::from_double(e.hi));
    CHECK(e.hi == up(e.lo)); // one ulp wide
    CHECK(e.contains(1.0 / 3.0));

    const Interval m = num::enclose(-third);
    CHECK(m == Interval(-e.hi, -e.lo));

    // Doubles are enclosed exactly, whatever the rounding mode.
    CHECK(num::enclose(Rational(3, 4)) == Interval(0.75));
    CHECK(num::enclose(Rational::from_double(0.1)) == Interval(0.1));
    CHECK(num::enclose(Rational(0)) == Interval(0.0));
    {
        UpwardRounding upward;
        CHECK(num::enclose(third) == e);
        CHECK(num::enclose(Rational::from_double(-DBL_MIN / 8)) == Interval(-DBL_MIN / 8));
    }

    // Beyond the double range, and below the smallest subnormal.
    CHECK(num::enclose(num::pow(Rational(10), 400)) == Interval(DBL_MAX, inf));
    CHECK(num::enclose(-num::pow(Rational(10), 400)) == Interval(-inf, -DBL_MAX));
    CHECK(num::enclose(num::pow(Rational(10), -400)) ==
          Interval(0.0, std::numeric_limits<double>::denorm_min()));
    // A subnormal neighbourhood: 3/2 of the smallest subnormal lies between it and twice it.
    const Rational tiny = Rational::from_double(std::numeric_limits<double>::denorm_min());
    CHECK(num::enclose(tiny * Rational(3, 2)) == Interval(tiny.to_double(), 2 * tiny.to_double()));
}

TEST_CASE("enclose of a decimal literal matches the interval parser", "[numeric][rational][enclose]") {
    // num::from_decimal encloses literals through strtod in directed rounding: an independent route.
    std::mt19937_64 rng(17);
    for (int i = 0; i < 2000; ++i) {
        std::string text = std::to_string(rng() % 100000);
        text += "." + std::to_string(rng() % 1000000);
        text += "e" + std::to_string(static_cast<int>(rng() % 630) - 330);
        INFO(text);
        CHECK(num::enclose(q(text.c_str())) == num::from_decimal(text));
    }
}
