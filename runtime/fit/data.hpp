// Measured data for fitting: a CSV of (t, x) samples of a function, (x, y) points of a curve, or (t, x, y)
// points of a curve with its parameter. Malformed input is a located SamplesError (line and column), never a
// guess: a row of the wrong width, a field that is not a finite number, a parameter that does not increase,
// too few points.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace frac::rt::fit {

// A user error in the data, at a 1-based line and column of the text (line 0: the file as a whole).
struct SamplesError : std::runtime_error {
    std::size_t line, column;
    SamplesError(std::size_t l, std::size_t c, const std::string& message)
        : std::runtime_error(message), line(l), column(c) {}
};

// Samples of a function t -> x (y empty) or of a curve t -> (x, y). The parameter t strictly increases.
struct Samples {
    std::vector<double> t, x, y;
    bool curve() const { return !y.empty(); }
    std::size_t size() const { return t.size(); }
};

enum class DataKind {
    automatic, // two columns: a function (t, x), unless the header names x,y; three columns: (t, x, y)
    function,  // (t, x)
    curve,     // (x, y) with t uniform in [0, 1], or (t, x, y)
};

// The fewest samples a fit accepts.
inline constexpr std::size_t min_samples = 5;

// Parses CSV text: fields separated by commas (or blanks), '#' comments and blank lines ignored, an
// optional header row of names (t, x, y) first. Throws SamplesError.
Samples parse_csv(std::string_view text, DataKind kind = DataKind::automatic);

// The samples as CSV text (a header line, then one row per sample, shortest round-trip decimals).
std::string to_csv(const Samples& samples);

} // namespace frac::rt::fit
