// Exact rational numbers on GMP's mpq_class.
//
// Model constants such as 0.1 or 1/3 have no double value; the constraint solver and the linear algebra
// over them (numeric/matrix.hpp) need them exactly. `enclose` is the one bridge to interval arithmetic:
// the tightest double interval around the rational.
#pragma once

#include "numeric/interval.hpp"

#include <gmpxx.h>

#include <compare>
#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>

namespace frac::num {

class Rational {
public:
    Rational() = default;                       // 0
    Rational(long value) : value_(value) {}     // NOLINT: an integer is a rational
    Rational(int value) : value_(value) {}      // NOLINT: an integer is a rational
    explicit Rational(mpq_class value);         // canonicalised
    Rational(long numerator, long denominator); // throws std::domain_error when denominator == 0

    // The exact value of a finite double (every double is a dyadic rational); throws on inf and NaN.
    static Rational from_double(double value);

    // A decimal literal, exactly: [+-] digits [. digits] [(e|E) [+-] digits], or with the digits before
    // the point left out (".5"), as in the grammar's `number`. "0.1" is 1/10, "1e-3" is 1/1000. nullopt
    // for anything else, including exponents beyond +-100000 (whose values would take megabytes).
    static std::optional<Rational> parse_decimal(std::string_view text);

    const mpq_class& value() const { return value_; }
    // Numerator and denominator in lowest terms; the denominator is positive.
    mpz_class numerator() const { return value_.get_num(); }
    mpz_class denominator() const { return value_.get_den(); }

    int sign() const { return sgn(value_); }
    bool is_zero() const { return sign() == 0; }
    bool is_integer() const { return value_.get_den() == 1; }

    // "1/3", "-2", "0".
    std::string to_string() const { return value_.get_str(); }
    // The double nearest to the value (ties to even), +-inf beyond the double range.
    double to_double() const;

    Rational& operator+=(const Rational& o);
    Rational& operator-=(const Rational& o);
    Rational& operator*=(const Rational& o);
    Rational& operator/=(const Rational& o); // throws std::domain_error on division by zero

    friend Rational operator+(Rational a, const Rational& b) { return a += b; }
    friend Rational operator-(Rational a, const Rational& b) { return a -= b; }
    friend Rational operator*(Rational a, const Rational& b) { return a *= b; }
    friend Rational operator/(Rational a, const Rational& b) { return a /= b; }
    friend Rational operator-(const Rational& a) { return Rational(mpq_class(-a.value_)); }

    friend bool operator==(const Rational& a, const Rational& b) { return a.value_ == b.value_; }
    friend std::strong_ordering operator<=>(const Rational& a, const Rational& b) {
        return cmp(a.value_, b.value_) <=> 0;
    }

private:
    mpq_class value_;
};

// Writes to_string(), e.g. for test failure messages.
std::ostream& operator<<(std::ostream& os, const Rational& a);

Rational abs(const Rational& a);
// a^n for any integer n; a^0 = 1 (also for a = 0). Throws std::domain_error for 0^n with n < 0.
Rational pow(const Rational& base, std::int64_t exponent);

// The tightest interval of doubles around a: [RD(a), RU(a)], thin exactly when a is a double. Beyond the
// double range the outer end is infinite (and the inner one +-DBL_MAX). Any rounding mode.
Interval enclose(const Rational& a);

} // namespace frac::num
