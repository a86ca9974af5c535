#include "frontend/fif.hpp"

#include "frontend/loader.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace frac::front {

namespace {

ExprPtr make(ExprKind kind, Location loc) {
    auto e = std::make_unique<Expr>();
    e->kind = kind;
    e->loc = loc;
    return e;
}

ExprPtr copy(const Expr& e) {
    auto c = std::make_unique<Expr>();
    c->kind = e.kind;
    c->loc = e.loc;
    c->text = e.text;
    c->var = e.var;
    c->orbit_var = e.orbit_var;
    c->orbit_map = e.orbit_map;
    c->orbit_loc = e.orbit_loc;
    c->escape_loc = e.escape_loc;
    c->op = e.op;
    for (const ExprPtr& k : e.kids) c->kids.push_back(k ? copy(*k) : nullptr);
    for (const Arg& a : e.args) c->args.push_back({a.name, a.loc, a.value ? copy(*a.value) : nullptr});
    for (const Binding& b : e.bindings)
        c->bindings.push_back({b.name, b.loc, b.value ? copy(*b.value) : nullptr});
    return c;
}

ExprPtr number(const std::string& text, Location loc) {
    auto e = make(ExprKind::number, loc);
    e->text = text;
    return e;
}

ExprPtr binary(Tok op, ExprPtr a, ExprPtr b) {
    auto e = make(ExprKind::binary, a->loc);
    e->op = op;
    e->kids.push_back(std::move(a));
    e->kids.push_back(std::move(b));
    return e;
}

ExprPtr operator+(ExprPtr a, ExprPtr b) {
    return binary(Tok::plus, std::move(a), std::move(b));
}
ExprPtr operator-(ExprPtr a, ExprPtr b) {
    return binary(Tok::minus, std::move(a), std::move(b));
}
ExprPtr operator*(ExprPtr a, ExprPtr b) {
    return binary(Tok::star, std::move(a), std::move(b));
}
ExprPtr operator/(ExprPtr a, ExprPtr b) {
    return binary(Tok::slash, std::move(a), std::move(b));
}

// A decimal as the lexer reads it: digits, an optional fraction, an optional exponent.
bool is_decimal(const std::string& s) {
    std::size_t i = 0, digits = 0;
    while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i]))) ++i, ++digits;
    if (i < s.size() && s[i] == '.')
        for (++i; i < s.size() && std::isdigit(static_cast<unsigned char>(s[i])); ++i) ++digits;
    if (digits == 0) return false;
    if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
        ++i;
        if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
        const std::size_t start = i;
        while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i]))) ++i;
        if (i == start) return false;
    }
    return i == s.size();
}

std::string trim(const std::string& s) {
    const auto b = s.find_first_not_of(" \t\r");
    if (b == std::string::npos) return "";
    return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

class Expansion {
public:
    Expansion(Item& it, Diagnostics& d) : it_(it), a_(*it.automaton), f_(*a_.fif), d_(d) {}

    void run(const std::filesystem::path& dir, std::size_t max_file_bytes) {
        if (!f_.data.empty() && !f_.points.empty()) {
            d_.error(f_.data_loc, "a fif takes its points from 'points' or from 'data', not both");
            return;
        }
        if (!f_.data.empty() && !read_data(dir / f_.data, max_file_bytes)) return;
        if (f_.data.empty() && !own_points()) return;
        const Location at = f_.data.empty() ? f_.points_loc : f_.data_loc;
        if (points_.size() < 2) {
            d_.error(at.line ? at : it_.loc,
                     fmt::format("a fif interpolates at least 2 points, not {}", points_.size()));
            return;
        }
        const std::size_t n = points_.size() - 1;
        if (n > max_fif_pieces) {
            d_.error(at,
                     truncated_
                         ? fmt::format("a fif of more than {} pieces: that is its limit", max_fif_pieces)
                         : fmt::format("a fif of {} pieces is more than the limit of {}", n, max_fif_pieces));
            return;
        }
        for (const auto& point : points_) {
            auto tuple = make(ExprKind::tuple, point.front()->loc);
            for (const Expr* c : point) tuple->kids.push_back(copy(*c));
            f_.values.push_back(std::move(tuple));
        }
        if (f_.scales.empty()) {
            d_.error(it_.loc,
                     fmt::format("fif '{}' needs the vertical scalings of its {} piece{}: scale {}; (or "
                                 "one for all pieces)",
                                 it_.name, n, n == 1 ? "" : "s",
                                 n == 1 ? std::string("c1") : fmt::format("c1, ..., c{}", n)));
            return;
        }
        if (f_.scales.size() != 1 && f_.scales.size() != n) {
            d_.error(f_.scale_loc, fmt::format("{} scalings for {} pieces (one per piece, or one for all)",
                                               f_.scales.size(), n));
            return;
        }
        if (!f_.domains.empty() && f_.domains.size() != n) {
            d_.error(f_.domains_loc,
                     fmt::format("{} domains for {} pieces (one per piece)", f_.domains.size(), n));
            return;
        }
        std::size_t arcs = 0; // an RFIF's piece i has an arc to each range its domain covers
        for (const auto& [j, k] : f_.domains) arcs += static_cast<std::size_t>(std::abs(k - j));
        if (arcs > max_fif_arcs) {
            d_.error(f_.domains_loc,
                     fmt::format("the domains cover {} ranges in all, more than the limit of {} "
                                 "arcs of a fif",
                                 arcs, max_fif_arcs));
            return;
        }
        for (std::size_t i = 0; i < f_.domains.size(); ++i) {
            const auto [j, k] = f_.domains[i];
            if (static_cast<std::size_t>(std::max(j, k)) > n || j == k) {
                d_.error(f_.domain_locs[i],
                         fmt::format("domain ({}, {}) of piece {}: two different point indices "
                                     "from 0 to {}",
                                     j, k, i + 1, n));
                return;
            }
        }
        build();
    }

private:
    // The points written in the model: tuples of 2 or 3 coordinates, all alike.
    bool own_points() {
        for (const ExprPtr& p : f_.points) {
            if (p->kind != ExprKind::tuple || (p->kids.size() != 2 && p->kids.size() != 3)) {
                d_.error(p->loc, "a fif's point is (t, x), or (t, x, y) for a curve");
                return false;
            }
            if (p->kids.size() != f_.points.front()->kids.size()) {
                d_.error(p->loc, fmt::format("this point has {} coordinates, the first {}", p->kids.size(),
                                             f_.points.front()->kids.size()));
                return false;
            }
            std::vector<const Expr*> c;
            for (const ExprPtr& k : p->kids) c.push_back(k.get());
            points_.push_back(c);
        }
        return true;
    }

    // Rows "t, x[, y]" of decimals; blank lines, lines starting with '#' and one header line are skipped.
    bool read_data(const std::filesystem::path& path, std::size_t max_file_bytes) {
        std::error_code ec;
        if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec) &&
            !std::filesystem::is_directory(path, ec)) {
            d_.error(f_.data_loc, fmt::format("cannot read data '{}': not a regular file", path.string()));
            return false;
        }
        std::string text, why;
        if (!read_file(path.string(), max_file_bytes, text, why)) {
            d_.error(f_.data_loc, fmt::format("cannot read data '{}': {}", path.string(), why));
            return false;
        }
        std::istringstream in(text);
        std::string line;
        std::size_t number_of_line = 0, columns = 0;
        bool header_allowed = true;
        while (std::getline(in, line)) {
            ++number_of_line;
            line = trim(line);
            if (line.empty() || line[0] == '#') continue;
            std::vector<std::string> fields;
            std::size_t start = 0;
            while (true) {
                const std::size_t comma = line.find(',', start);
                fields.push_back(
                    trim(line.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
                if (comma == std::string::npos) break;
                start = comma + 1;
            }
            const auto numeric = [](const std::string& s) {
                return is_decimal(!s.empty() && (s[0] == '-' || s[0] == '+') ? s.substr(1) : s);
            };
            const bool all_numeric = std::all_of(fields.begin(), fields.end(), numeric);
            if (!all_numeric && header_allowed) { // a header: t,x,y
                header_allowed = false;
                continue;
            }
            header_allowed = false;
            const std::string where = fmt::format("{}:{}", path.filename().string(), number_of_line);
            if (fields.size() != 2 && fields.size() != 3) {
                d_.error(f_.data_loc, fmt::format("data {}: a row is t, x or t, x, y, not {} fields", where,
                                                  fields.size()));
                return false;
            }
            if (columns != 0 && fields.size() != columns) {
                d_.error(f_.data_loc, fmt::format("data {}: {} fields where the first row has {}", where,
                                                  fields.size(), columns));
                return false;
            }
            columns = fields.size();
            std::vector<const Expr*> point;
            for (const std::string& s : fields) {
                if (!numeric(s)) {
                    d_.error(f_.data_loc, fmt::format("data {}: '{}' is not a number", where,
                                                      s.size() > 40 ? s.substr(0, 40) + "..." : s));
                    return false;
                }
                const bool minus = s[0] == '-';
                ExprPtr v = number(s[0] == '-' || s[0] == '+' ? s.substr(1) : s, f_.data_loc);
                if (!std::isfinite(std::strtod(v->text.c_str(), nullptr))) {
                    d_.error(f_.data_loc, fmt::format("data {}: '{}' is too large", where, s));
                    return false;
                }
                if (minus) {
                    auto neg = make(ExprKind::unary, f_.data_loc);
                    neg->op = Tok::minus;
                    neg->kids.push_back(std::move(v));
                    v = std::move(neg);
                }
                point.push_back(v.get());
                data_.push_back(std::move(v));
            }
            points_.push_back(point);
            if (points_.size() > max_fif_pieces + 1) { // reported by run()
                truncated_ = true;
                break;
            }
        }
        return true;
    }

    ExprPtr t(std::size_t i) const { return copy(*points_[i][0]); }
    ExprPtr value(std::size_t i, std::size_t r) const { return copy(*points_[i][1 + r]); }

    // The vertical scaling of piece i: entry (r, c) of C.
    ExprPtr scaling(std::size_t i, std::size_t r, std::size_t c) const {
        const Expr& s = *f_.scales[f_.scales.size() == 1 ? 0 : i];
        if (!curve_) return copy(s);
        if (s.kind == ExprKind::matrix && s.kids.size() == 2 && s.kids[r]->kids.size() == 2)
            return copy(*s.kids[r]->kids[c]);
        if (s.kind == ExprKind::tuple && s.kids.size() == 2)
            return r == c ? copy(*s.kids[r]) : number("0", s.loc);
        return r == c ? copy(s) : number("0", s.loc);
    }

    // (C X_j)_r
    ExprPtr scaled_point(std::size_t i, std::size_t r, std::size_t j) const {
        ExprPtr sum;
        for (std::size_t c = 0; c < dims_; ++c) {
            ExprPtr term = scaling(i, r, c) * value(j, c);
            sum = sum ? std::move(sum) + std::move(term) : std::move(term);
        }
        return sum;
    }

    // T_i as a homogeneous matrix over (t, x[, y]): T_i(P_j) = P_(i-1), T_i(P_k) = P_i.
    ExprPtr shear(std::size_t i, std::size_t j, std::size_t k) const {
        const Location loc = f_.scales[f_.scales.size() == 1 ? 0 : i]->loc;
        const std::size_t size = dims_ + 2;
        std::vector<std::vector<ExprPtr>> m(size);
        const auto span = [&] { return t(k) - t(j); };
        // a and d
        m[0].push_back((t(i + 1) - t(i)) / span());
        for (std::size_t c = 0; c < dims_; ++c) m[0].push_back(number("0", loc));
        m[0].push_back(t(i) - (t(i + 1) - t(i)) / span() * t(j));
        for (std::size_t r = 0; r < dims_; ++r) {
            const auto b = [&] {
                return (value(i + 1, r) - value(i, r) - (scaled_point(i, r, k) - scaled_point(i, r, j))) /
                       span();
            };
            m[1 + r].push_back(b());
            for (std::size_t c = 0; c < dims_; ++c) m[1 + r].push_back(scaling(i, r, c));
            m[1 + r].push_back(value(i, r) - scaled_point(i, r, j) - b() * t(j));
        }
        for (std::size_t c = 0; c + 1 < size; ++c) m[size - 1].push_back(number("0", loc));
        m[size - 1].push_back(number("1", loc));
        auto e = make(ExprKind::matrix, loc);
        for (auto& row : m) {
            auto r = make(ExprKind::tuple, loc);
            for (auto& x : row) r->kids.push_back(std::move(x));
            e->kids.push_back(std::move(r));
        }
        return e;
    }

    // segment(P_i, P_j): what a range draws at the leaves of an evaluation tree (its chord).
    ExprPtr chord(std::size_t i, std::size_t j) const {
        auto e = make(ExprKind::call, it_.loc);
        e->text = "segment";
        for (const std::size_t k : {i, j}) {
            auto p = make(ExprKind::tuple, points_[k].front()->loc);
            for (const Expr* c : points_[k]) p->kids.push_back(copy(*c));
            e->args.push_back({"", p->loc, std::move(p)});
        }
        return e;
    }

    void build() {
        curve_ = points_.front().size() == 3;
        dims_ = curve_ ? 2 : 1;
        if (!curve_)
            for (const ExprPtr& s : f_.scales)
                if (s->kind == ExprKind::tuple || s->kind == ExprKind::matrix) {
                    d_.error(s->loc,
                             "a function's scaling is one number (a pair or a 2 x 2 matrix is for a curve "
                             "(t, x, y))");
                    return;
                }
        const std::size_t n = points_.size() - 1;
        const SpaceDecl space{false, curve_ ? 3 : 2, it_.loc};
        const bool recurrent =
            std::any_of(f_.domains.begin(), f_.domains.end(), [&](const std::array<int, 2>& d) {
                return std::min(d[0], d[1]) != 0 || static_cast<std::size_t>(std::max(d[0], d[1])) != n;
            });
        const auto domain = [&](std::size_t i) -> std::array<std::size_t, 2> {
            if (f_.domains.empty()) return {0, n};
            return {static_cast<std::size_t>(f_.domains[i][0]), static_cast<std::size_t>(f_.domains[i][1])};
        };
        const auto piece_loc = [&](std::size_t i) {
            return f_.domain_locs.size() == n ? f_.domain_locs[i]
                   : f_.scales.size() == n    ? f_.scales[i]->loc
                   : f_.scale_loc.line        ? f_.scale_loc
                                              : it_.loc;
        };
        a_.states.push_back({it_.name, it_.loc, space, chord(0, n), {}, {}, {}});
        if (!recurrent) {
            for (std::size_t i = 0; i < n; ++i) {
                const auto [j, k] = domain(i);
                ArcDecl arc;
                arc.from = arc.to = it_.name;
                arc.label = fmt::format("T{}", i + 1);
                arc.loc = arc.from_loc = arc.to_loc = piece_loc(i);
                arc.op = shear(i, j, k);
                a_.arcs.push_back(std::move(arc));
            }
            return;
        }
        // An RFIF: range states r1 ... rN (the graph over [t_(i-1), t_i]); the initial state is their union.
        const auto range = [&](std::size_t i) { return fmt::format("r{}", i); };
        for (std::size_t i = 1; i <= n; ++i)
            a_.states.push_back({range(i), it_.loc, space, chord(i - 1, i), {}, {}, {}});
        for (std::size_t i = 1; i <= n; ++i) {
            ArcDecl arc;
            arc.from = it_.name;
            arc.to = range(i);
            arc.loc = arc.from_loc = arc.to_loc = it_.loc;
            arc.op = make(ExprKind::matrix, it_.loc);
            const auto size = static_cast<std::size_t>(space.n) + 1;
            for (std::size_t r = 0; r < size; ++r) {
                auto row = make(ExprKind::tuple, it_.loc);
                for (std::size_t c = 0; c < size; ++c)
                    row->kids.push_back(number(r == c ? "1" : "0", it_.loc));
                arc.op->kids.push_back(std::move(row));
            }
            a_.arcs.push_back(std::move(arc));
        }
        for (std::size_t i = 0; i < n; ++i) {
            const auto [j, k] = domain(i);
            for (std::size_t m = std::min(j, k) + 1; m <= std::max(j, k); ++m) {
                ArcDecl arc;
                arc.from = range(i + 1);
                arc.to = range(m);
                arc.label = fmt::format("T{}", i + 1);
                arc.loc = arc.from_loc = arc.to_loc = piece_loc(i);
                arc.op = shear(i, j, k);
                a_.arcs.push_back(std::move(arc));
            }
        }
    }

    Item& it_;
    AutomatonDecl& a_;
    FifDecl& f_;
    Diagnostics& d_;
    std::vector<std::vector<const Expr*>> points_; // coordinates of each point (into f_.points or data_)
    std::vector<ExprPtr> data_;                    // numbers read from a data file
    bool curve_ = false;
    bool truncated_ = false; // a data file with more points than the limit: read up to it
    std::size_t dims_ = 1;
};

} // namespace

void expand_fif(Item& it, const std::filesystem::path& dir, std::size_t max_file_bytes, Diagnostics& d) {
    Expansion(it, d).run(dir, max_file_bytes);
}

} // namespace frac::front
