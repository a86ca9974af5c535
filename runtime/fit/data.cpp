#include "runtime/fit/data.hpp"

#include <charconv>
#include <cmath>
#include <fmt/format.h>

namespace frac::rt::fit {

namespace {

struct Field {
    std::string_view text;
    std::size_t column; // 1-based
};

std::vector<Field> split_row(std::string_view line) {
    const bool commas = line.find(',') != std::string_view::npos;
    std::vector<Field> fields;
    std::size_t i = 0;
    while (i <= line.size()) {
        std::size_t end = i;
        if (commas)
            end = std::min(line.find(',', i), line.size());
        else {
            while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
            if (i == line.size()) break;
            end = i;
            while (end < line.size() && line[end] != ' ' && line[end] != '\t') ++end;
        }
        std::size_t b = i, e = end;
        while (b < e && (line[b] == ' ' || line[b] == '\t')) ++b;
        while (e > b && (line[e - 1] == ' ' || line[e - 1] == '\t')) --e;
        fields.push_back({line.substr(b, e - b), b + 1});
        i = end + 1;
    }
    return fields;
}

bool is_name(std::string_view s) {
    return s == "t" || s == "x" || s == "y";
}

double parse_number(const Field& f, std::size_t line) {
    double v = 0;
    const char* begin = f.text.data();
    if (!f.text.empty() && f.text[0] == '+') ++begin;
    const auto [end, ec] = std::from_chars(begin, f.text.data() + f.text.size(), v);
    if (f.text.empty()) throw SamplesError(line, f.column, "an empty field where a number was expected");
    if (ec != std::errc() || end != f.text.data() + f.text.size())
        throw SamplesError(line, f.column, fmt::format("'{}' is not a number", f.text));
    if (!std::isfinite(v))
        throw SamplesError(line, f.column, fmt::format("'{}' is not a finite number", f.text));
    return v;
}

} // namespace

Samples parse_csv(std::string_view text, DataKind kind) {
    Samples s;
    std::size_t width = 0, line_no = 0, last_line = 0, pos = 0;
    bool header_seen = false, t_given = true;
    while (pos < text.size()) {
        std::size_t eol = text.find('\n', pos);
        if (eol == std::string_view::npos) eol = text.size();
        std::string_view line = text.substr(pos, eol - pos);
        pos = eol + 1;
        ++line_no;
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        const std::size_t hash = line.find('#');
        if (hash != std::string_view::npos) line = line.substr(0, hash);
        if (line.find_first_not_of(" \t,") == std::string_view::npos) continue;
        const std::vector<Field> fields = split_row(line);
        if (width == 0 && !header_seen && !fields.empty() && is_name(fields[0].text)) {
            std::string names;
            for (const Field& f : fields) {
                if (!is_name(f.text))
                    throw SamplesError(line_no, f.column,
                                       fmt::format("'{}' is not a column name (t, x or y)", f.text));
                names += std::string(f.text);
            }
            if (names != "tx" && names != "xy" && names != "txy")
                throw SamplesError(line_no, 1,
                                   "the header names the columns t,x (a function), x,y or t,x,y (a curve)");
            if (names == "xy") {
                if (kind == DataKind::function)
                    throw SamplesError(line_no, 1,
                                       "the header names a curve (x,y) but a function (t,x) was asked for");
                kind = DataKind::curve;
            }
            if (names == "tx" && kind == DataKind::curve)
                throw SamplesError(line_no, 1, "the header names a function (t,x) but a curve was asked for");
            header_seen = true;
            width = fields.size();
            continue;
        }
        if (width == 0) width = fields.size();
        if (fields.size() != width)
            throw SamplesError(
                line_no, fields.size() > width ? fields[width].column : line.size() + 1,
                fmt::format("a row of {} fields where the rows have {}", fields.size(), width));
        if (width < 2 || width > 3)
            throw SamplesError(
                line_no, 1,
                fmt::format("a row of {} fields: the data has 2 columns (t,x or x,y) or 3 (t,x,y)", width));
        std::vector<double> v;
        for (const Field& f : fields) v.push_back(parse_number(f, line_no));
        const bool curve = width == 3 || kind == DataKind::curve;
        if (width == 3 && kind == DataKind::function)
            throw SamplesError(line_no, 1,
                               "a row of 3 fields (t,x,y: a curve) but a function (t,x) was asked for");
        t_given = width == 3 || !curve;
        if (t_given) {
            if (!s.t.empty() && !(v[0] > s.t.back()))
                throw SamplesError(line_no, fields[0].column,
                                   fmt::format("the parameter {} does not increase (the row before has {})",
                                               fields[0].text, s.t.back()));
            s.t.push_back(v[0]);
            s.x.push_back(v[1]);
            if (curve) s.y.push_back(v[2]);
        } else {
            s.x.push_back(v[0]);
            s.y.push_back(v[1]);
        }
        last_line = line_no;
    }
    const std::size_t n = s.x.size();
    if (n < min_samples)
        throw SamplesError(
            last_line, 0,
            fmt::format("{} data point{}: a fit needs at least {}", n, n == 1 ? "" : "s", min_samples));
    if (!t_given) // (x, y) points: the parameter runs uniformly over [0, 1]
        for (std::size_t i = 0; i < n; ++i) s.t.push_back(double(i) / double(n - 1));
    return s;
}

std::string to_csv(const Samples& s) {
    std::string out = s.curve() ? "t,x,y\n" : "t,x\n";
    for (std::size_t i = 0; i < s.size(); ++i)
        out += s.curve() ? fmt::format("{},{},{}\n", s.t[i], s.x[i], s.y[i])
                         : fmt::format("{},{}\n", s.t[i], s.x[i]);
    return out;
}

} // namespace frac::rt::fit
