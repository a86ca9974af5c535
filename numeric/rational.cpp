#include "numeric/rational.hpp"

#include <mpfr.h>

#include <cctype>
#include <cmath>
#include <ostream>
#include <stdexcept>
#include <utility>

namespace frac::num {

Rational::Rational(mpq_class value) : value_(std::move(value)) {
    value_.canonicalize();
}

Rational::Rational(long numerator, long denominator) {
    if (denominator == 0) throw std::domain_error("rational with denominator 0");
    value_ = mpq_class(numerator, denominator);
    value_.canonicalize();
}

Rational Rational::from_double(double value) {
    if (!std::isfinite(value)) throw std::domain_error("rational from a non-finite double");
    return Rational(mpq_class(value)); // exact: mpq_set_d converts without rounding
}

namespace {

// A string of decimal digits as a nonnegative integer; empty means 0.
mpz_class digits_value(const std::string& digits) {
    if (digits.empty()) return 0;
    return mpz_class(digits, 10);
}

bool all_digits(std::string_view s) {
    for (char c : s)
        if (!std::isdigit(static_cast<unsigned char>(c))) return false;
    return true;
}

constexpr long kMaxExponent = 100000;

} // namespace

std::optional<Rational> Rational::parse_decimal(std::string_view text) {
    const auto take_sign = [](std::string_view& s) {
        const bool negative = !s.empty() && s[0] == '-';
        if (!s.empty() && (s[0] == '+' || s[0] == '-')) s.remove_prefix(1);
        return negative;
    };
    const bool negative = take_sign(text);

    long exponent = 0;
    if (const auto e = text.find_first_of("eE"); e != std::string_view::npos) {
        std::string_view exponent_text = text.substr(e + 1);
        text = text.substr(0, e);
        const bool exponent_negative = take_sign(exponent_text);
        if (exponent_text.empty() || !all_digits(exponent_text)) return std::nullopt;
        const std::size_t first = exponent_text.find_first_not_of('0');
        if (first != std::string_view::npos) {
            const std::string_view significant = exponent_text.substr(first);
            if (significant.size() > 6) return std::nullopt;
            exponent = std::stol(std::string(significant));
            if (exponent > kMaxExponent) return std::nullopt;
        }
        if (exponent_negative) exponent = -exponent;
    }

    std::string_view integer_part = text, fraction_part;
    if (const auto dot = text.find('.'); dot != std::string_view::npos) {
        integer_part = text.substr(0, dot);
        fraction_part = text.substr(dot + 1);
    }
    if (integer_part.empty() && fraction_part.empty()) return std::nullopt;
    if (!all_digits(integer_part) || !all_digits(fraction_part)) return std::nullopt;

    // The value is (integer digits followed by fraction digits) * 10^(exponent - number of fraction digits).
    exponent -= static_cast<long>(fraction_part.size());
    mpz_class numerator = digits_value(std::string(integer_part) + std::string(fraction_part));
    mpz_class power;
    mpz_ui_pow_ui(power.get_mpz_t(), 10, static_cast<unsigned long>(exponent < 0 ? -exponent : exponent));
    mpz_class denominator = 1;
    if (exponent < 0)
        denominator = power;
    else
        numerator *= power;
    if (negative) numerator = -numerator;
    return Rational(mpq_class(numerator, denominator));
}

double Rational::to_double() const {
    mpfr_t x;
    mpfr_init2(x, 53);
    mpfr_set_q(x, value_.get_mpq_t(), MPFR_RNDN);
    const double d = mpfr_get_d(x, MPFR_RNDN);
    mpfr_clear(x);
    return d;
}

Rational& Rational::operator+=(const Rational& o) {
    value_ += o.value_;
    return *this;
}
Rational& Rational::operator-=(const Rational& o) {
    value_ -= o.value_;
    return *this;
}
Rational& Rational::operator*=(const Rational& o) {
    value_ *= o.value_;
    return *this;
}
Rational& Rational::operator/=(const Rational& o) {
    if (o.is_zero()) throw std::domain_error("rational division by zero");
    value_ /= o.value_;
    return *this;
}

std::ostream& operator<<(std::ostream& os, const Rational& a) {
    return os << a.to_string();
}

Rational abs(const Rational& a) {
    return a.sign() < 0 ? -a : a;
}

Rational pow(const Rational& base, std::int64_t exponent) {
    if (exponent < 0 && base.is_zero()) throw std::domain_error("0 to a negative power");
    const unsigned long n =
        exponent < 0 ? 0UL - static_cast<unsigned long>(exponent) : static_cast<unsigned long>(exponent);
    mpz_class numerator, denominator;
    mpz_pow_ui(numerator.get_mpz_t(), base.value().get_num_mpz_t(), n);
    mpz_pow_ui(denominator.get_mpz_t(), base.value().get_den_mpz_t(), n);
    if (exponent < 0) std::swap(numerator, denominator);
    return Rational(mpq_class(numerator, denominator)); // canonicalize moves the sign to the numerator
}

Interval enclose(const Rational& a) {
    // mpfr_set_q rounds once to 53 bits with MPFR's unbounded exponent range; mpfr_get_d then rounds in
    // the same direction into the double range (subnormals, overflow). Two roundings in one direction
    // give the directed rounding of the exact value: every double below a is below the 53-bit RD(a).
    mpfr_t x;
    mpfr_init2(x, 53);
    mpfr_set_q(x, a.value().get_mpq_t(), MPFR_RNDD);
    const double lo = mpfr_get_d(x, MPFR_RNDD);
    mpfr_set_q(x, a.value().get_mpq_t(), MPFR_RNDU);
    const double hi = mpfr_get_d(x, MPFR_RNDU);
    mpfr_clear(x);
    return {lo, hi};
}

} // namespace frac::num
