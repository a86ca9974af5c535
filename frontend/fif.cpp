#include "frontend/fif.hpp"

#include "frontend/loader.hpp"
#include "numeric/rational.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <deque>
#include <map>
#include <optional>
#include <set>
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
    if (e.series) c->series = std::make_unique<SeriesSyntax>(*e.series);
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
        if (f_.malformed) return; // its parse errors are reported; what is left would only add noise
        if (!f_.pieces.empty()) {
            if (!f_.points.empty() || !f_.data.empty() || !f_.scales.empty() || !f_.domains.empty()) {
                d_.error(f_.pieces.front().loc,
                         "a fif of pieces (a PFIF) has its maps in them: no points, data, scale or domains");
                return;
            }
            partitioned();
            return;
        }
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

    // ---- A partitioned FIF (seed 001 sec. 2.3): F = U_i T_i(F[alpha_i, beta_i]) ----
    //
    // The graph over an interval I is the union, over the ranges R_j that I overlaps, of T_j applied to
    // the graph over the preimage of I n R_j, a part of D_j: a state per interval, starting from the
    // whole, until no new interval appears (exactly, in rationals). The states are finite when the
    // domains' ends close up under the maps' inverses (ends on a grid the maps keep, as data fits have);
    // otherwise the count passes max_fif_pieces and the PFIF is refused as no finite automaton.

    using Q = num::Rational;
    static constexpr std::size_t max_pfif_bits = 1024; // numerator and denominator of an interval's end

    // An exact number written with + - * / and literals; nullopt for anything else.
    static std::optional<Q> exact(const Expr& e) {
        try {
            switch (e.kind) {
            case ExprKind::number: return Q::parse_decimal(e.text);
            case ExprKind::unary: {
                auto v = exact(*e.kids[0]);
                if (!v || (e.op != Tok::minus && e.op != Tok::plus)) return std::nullopt;
                return e.op == Tok::minus ? -*v : *v;
            }
            case ExprKind::binary: {
                auto a = exact(*e.kids[0]), b = exact(*e.kids[1]);
                if (!a || !b) return std::nullopt;
                switch (e.op) {
                case Tok::plus: return *a + *b;
                case Tok::minus: return *a - *b;
                case Tok::star: return *a * *b;
                case Tok::slash:
                    if (b->is_zero()) return std::nullopt;
                    return *a / *b;
                default: return std::nullopt;
                }
            }
            default: return std::nullopt;
            }
        } catch (const std::exception&) {
            return std::nullopt;
        }
    }

    struct Piece {
        Q from, to, a, d;                   // domain [from, to]; t -> a t + d
        Q range_lo, range_hi;               // its image
        std::vector<std::vector<double>> m; // the matrix, for the chords
    };

    bool read_pieces(std::vector<Piece>& pieces) {
        if (f_.pieces.size() > max_fif_pieces) {
            d_.error(f_.pieces[max_fif_pieces].loc,
                     fmt::format("a fif of {} pieces is more than the limit of {}", f_.pieces.size(),
                                 max_fif_pieces));
            return false;
        }
        std::size_t size = 0;
        for (std::size_t i = 0; i < f_.pieces.size(); ++i) {
            const FifPiece& fp = f_.pieces[i];
            Piece p;
            const auto from = exact(*fp.from), to = exact(*fp.to);
            if (!from || !to) {
                d_.error((from ? fp.to : fp.from)->loc,
                         "a piece's domain ends are exact numbers (decimals, fractions, + - * /), so its "
                         "pieces can be found exactly");
                return false;
            }
            if (!(*from < *to)) {
                d_.error(fp.from->loc, fmt::format("the domain [{}, {}] of piece {} is empty: alpha < beta",
                                                   from->to_double(), to->to_double(), i + 1));
                return false;
            }
            const Expr& m = *fp.map;
            const std::size_t n = m.kind == ExprKind::matrix ? m.kids.size() : 0;
            if ((n != 3 && n != 4) || m.kids.front()->kids.size() != n || (size && n != size)) {
                d_.error(m.loc, size ? fmt::format("piece {}'s map is not {} x {} as the first piece's",
                                                   i + 1, size, size)
                                     : "a piece's map is a homogeneous matrix, 3 x 3 over (t, x) or 4 x 4 "
                                       "over (t, x, y): [[a, 0, d], [b, c, e], [0, 0, 1]]");
                return false;
            }
            size = n;
            p.m.assign(n, std::vector<double>(n));
            for (std::size_t r = 0; r < n; ++r)
                for (std::size_t c = 0; c < n; ++c) {
                    const Expr& entry = *m.kids[r]->kids[c];
                    const auto v = exact(entry);
                    if (!v) {
                        d_.error(
                            entry.loc,
                            "a piece's map has exact numbers for entries (decimals, fractions, + - * /)");
                        return false;
                    }
                    const bool t_row_zero = r == 0 && c != 0 && c + 1 != n, last_row = r + 1 == n;
                    if ((t_row_zero || last_row) && *v != Q(last_row && c + 1 == n ? 1 : 0)) {
                        d_.error(entry.loc,
                                 last_row
                                     ? "the last row of a piece's map is [0, ..., 0, 1]"
                                     : "a piece's map takes t to a t + d: its first row is [a, 0, ..., d]");
                        return false;
                    }
                    p.m[r][c] = v->to_double();
                    if (r == 0 && c == 0) p.a = *v;
                    if (r == 0 && c + 1 == n) p.d = *v;
                }
            if (!(abs(p.a) < Q(1)) || p.a.is_zero()) {
                d_.error(m.kids[0]->kids[0]->loc,
                         fmt::format("piece {} does not contract (eq. 2): |a| = {:.6g}, its range must be "
                                     "shorter than its domain and not a point",
                                     i + 1, abs(p.a).to_double()));
                return false;
            }
            p.from = *from;
            p.to = *to;
            const Q u = p.a * p.from + p.d, v = p.a * p.to + p.d;
            p.range_lo = std::min(u, v);
            p.range_hi = std::max(u, v);
            pieces.push_back(std::move(p));
        }
        // The ranges tile [t0, tN]; every domain lies in it.
        std::vector<std::size_t> order(pieces.size());
        for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
        std::sort(order.begin(), order.end(),
                  [&](std::size_t x, std::size_t y) { return pieces[x].range_lo < pieces[y].range_lo; });
        for (std::size_t k = 1; k < order.size(); ++k) {
            const Piece &prev = pieces[order[k - 1]], &p = pieces[order[k]];
            if (p.range_lo != prev.range_hi) {
                d_.error(
                    f_.pieces[order[k]].loc,
                    fmt::format("the ranges of a PFIF tile an interval: piece {}'s range [{:.6g}, {:.6g}] "
                                "{} piece {}'s [{:.6g}, {:.6g}]",
                                order[k] + 1, p.range_lo.to_double(), p.range_hi.to_double(),
                                p.range_lo < prev.range_hi ? "overlaps" : "leaves a gap after",
                                order[k - 1] + 1, prev.range_lo.to_double(), prev.range_hi.to_double()));
                return false;
            }
        }
        by_range_ = order;
        t0_ = pieces[order.front()].range_lo;
        tn_ = pieces[order.back()].range_hi;
        for (std::size_t i = 0; i < pieces.size(); ++i)
            if (pieces[i].from < t0_ || pieces[i].to > tn_) {
                d_.error(
                    f_.pieces[i].from->loc,
                    fmt::format("piece {}'s domain [{:.6g}, {:.6g}] leaves the graph's interval [{:.6g}, "
                                "{:.6g}] (the union of the ranges)",
                                i + 1, pieces[i].from.to_double(), pieces[i].to.to_double(), t0_.to_double(),
                                tn_.to_double()));
                return false;
            }
        return true;
    }

    // The graph's value at t approached from the right (side > 0) or the left: the descent
    // X(t) = b s + C X(s) + e, s the preimage of t in the piece whose range holds t on that side,
    // summed until the product of the C's is negligible (the scalings contract).
    std::vector<double> limit_value(const std::vector<Piece>& pieces, double t, int side) const {
        const std::size_t dims = pieces.front().m.size() - 2;
        std::vector<double> value(dims, 0.0), product(dims * dims, 0.0);
        for (std::size_t r = 0; r < dims; ++r) product[r * dims + r] = 1;
        const double lo = t0_.to_double(), hi = tn_.to_double();
        for (int step = 0; step < 100000; ++step) {
            if (t <= lo) side = 1;
            if (t >= hi) side = -1;
            const Piece* piece = nullptr;
            for (const Piece& p : pieces) {
                const double r0 = p.range_lo.to_double(), r1 = p.range_hi.to_double();
                if (side > 0 ? (r0 <= t && t < r1) : (r0 < t && t <= r1)) piece = &p;
            }
            if (!piece) break;
            const auto& m = piece->m;
            const std::size_t last = dims + 1;
            const double s = (t - m[0][last]) / m[0][0];
            double largest = 0;
            std::vector<double> next(dims * dims, 0.0);
            for (std::size_t r = 0; r < dims; ++r) {
                for (std::size_t k = 0; k < dims; ++k)
                    value[r] += product[r * dims + k] * (m[1 + k][0] * s + m[1 + k][last]);
                for (std::size_t c = 0; c < dims; ++c) {
                    for (std::size_t k = 0; k < dims; ++k)
                        next[r * dims + c] += product[r * dims + k] * m[1 + k][1 + c];
                    largest = std::max(largest, std::abs(next[r * dims + c]));
                }
            }
            product = std::move(next);
            if (m[0][0] < 0) side = -side;
            t = s;
            if (largest < 1e-18) break;
        }
        return value;
    }

    ExprPtr literal(double v, Location loc) const {
        ExprPtr n = number(fmt::format("{:.17g}", std::abs(v)), loc);
        if (!(v < 0)) return n;
        auto neg = make(ExprKind::unary, loc);
        neg->op = Tok::minus;
        neg->kids.push_back(std::move(n));
        return neg;
    }

    // segment((u, X(u+)), (v, X(v-))): the chord of a state's graph, for the leaves of evaluation trees
    // (the ends to double precision: drawing only).
    ExprPtr partitioned_chord(const std::vector<Piece>& pieces, const Q& u, const Q& v) const {
        auto e = make(ExprKind::call, it_.loc);
        e->text = "segment";
        for (const auto& [t, side] : {std::pair{u, 1}, std::pair{v, -1}}) {
            auto p = make(ExprKind::tuple, it_.loc);
            p->kids.push_back(literal(t.to_double(), it_.loc));
            for (double x : limit_value(pieces, t.to_double(), side)) p->kids.push_back(literal(x, it_.loc));
            e->args.push_back({"", it_.loc, std::move(p)});
        }
        return e;
    }

    // The points the dimension query reads (lower.cpp fif_points, runtime fif_box_dimension): the graph's
    // ends, and where the graph is no segment, its one-sided value farthest off the chord, at a cut
    // point inside. If every one-sided value at every cut (state and range ends) lies on the chord, each
    // piece maps the chord's part over its domain onto the chord's part over its range, so the graph is
    // the chord (its deviation is scaled by |c| < 1 at each step): D = 1, and only the ends are given.
    void shape_points(const std::vector<Piece>& pieces, const std::vector<std::pair<Q, Q>>& intervals) {
        std::set<Q> cuts;
        for (const auto& [u, v] : intervals) cuts.insert({u, v});
        for (const Piece& p : pieces) cuts.insert({p.range_lo, p.range_hi});
        const double t0 = t0_.to_double(), tn = tn_.to_double();
        const std::vector<double> x0 = limit_value(pieces, t0, 1), xn = limit_value(pieces, tn, -1);
        const auto point = [&](double t, const std::vector<double>& x) {
            auto tuple = make(ExprKind::tuple, it_.loc);
            tuple->kids.push_back(literal(t, it_.loc));
            for (double c : x) tuple->kids.push_back(literal(c, it_.loc));
            return tuple;
        };
        double worst = 0, worst_t = 0;
        std::vector<double> worst_x;
        const double scale = std::abs(tn - t0) + std::abs(xn[0] - x0[0]);
        for (const Q& cut : cuts) {
            const double t = cut.to_double();
            if (!(t > t0 && t < tn)) continue;
            for (const int side : {-1, 1}) {
                const std::vector<double> x = limit_value(pieces, t, side);
                double off = 0;
                for (std::size_t r = 0; r < x.size(); ++r)
                    off = std::max(off, std::abs((tn - t0) * (x[r] - x0[r]) - (xn[r] - x0[r]) * (t - t0)));
                if (off > worst) worst = off, worst_t = t, worst_x = x;
            }
        }
        f_.values.push_back(point(t0, x0));
        if (worst > 1e-12 * scale * scale) f_.values.push_back(point(worst_t, worst_x));
        f_.values.push_back(point(tn, xn));
    }

    void partitioned() {
        std::vector<Piece> pieces;
        if (!read_pieces(pieces)) return;
        const SpaceDecl space{false, static_cast<int>(pieces.front().m.size()) - 1, it_.loc};
        std::map<std::pair<Q, Q>, std::size_t> index;
        std::vector<std::pair<Q, Q>> intervals;
        const auto state_name = [&](std::size_t k) { return k == 0 ? it_.name : fmt::format("g{}", k); };
        // A finite closure keeps its ends on a grid: ends of ever more bits mean it does not close up
        // (and would only cost time), so they are refused like too many intervals.
        const auto bits = [](const Q& x) {
            return mpz_sizeinbase(x.value().get_num_mpz_t(), 2) +
                   mpz_sizeinbase(x.value().get_den_mpz_t(), 2);
        };
        const auto state = [&](const Q& u, const Q& v) -> std::optional<std::size_t> {
            const auto [at, added] = index.try_emplace({u, v}, intervals.size());
            if (added) {
                if (intervals.size() >= max_fif_pieces || bits(u) > max_pfif_bits || bits(v) > max_pfif_bits)
                    return std::nullopt;
                intervals.push_back({u, v});
            }
            return at->second;
        };
        if (!state(t0_, tn_)) {
            d_.error(f_.pieces.front().loc,
                     fmt::format("the interval of PFIF '{}' has ends of more than {} bits", it_.name,
                                 max_pfif_bits));
            return;
        }
        std::vector<ArcDecl> arcs;
        for (std::size_t k = 0; k < intervals.size(); ++k) {
            const auto [u, v] = intervals[k];
            // The ranges tile: those that overlap (u, v) are consecutive from the last one starting at
            // or before u.
            auto first = std::upper_bound(by_range_.begin(), by_range_.end(), u,
                                          [&](const Q& x, std::size_t j) { return x < pieces[j].range_lo; });
            if (first != by_range_.begin()) --first;
            for (auto at = first; at != by_range_.end() && pieces[*at].range_lo < v; ++at) {
                const std::size_t j = *at;
                const Piece& p = pieces[j];
                const Q lo = std::max(u, p.range_lo), hi = std::min(v, p.range_hi);
                if (!(lo < hi)) continue;
                const Q s = (lo - p.d) / p.a, e = (hi - p.d) / p.a;
                const auto to = state(std::min(s, e), std::max(s, e));
                if (!to) {
                    d_.error(
                        f_.pieces.front().loc,
                        fmt::format("the domains of PFIF '{}' cut its graph into more than {} intervals, or "
                                    "at ends of more than {} bits: it is no finite automaton (the ends of "
                                    "its domains do not close up under the maps; put them on a grid the "
                                    "maps keep)",
                                    it_.name, max_fif_pieces, max_pfif_bits));
                    return;
                }
                if (arcs.size() >= max_fif_arcs) {
                    d_.error(f_.pieces.front().loc,
                             fmt::format("PFIF '{}' needs more than {} arcs, the limit of a fif", it_.name,
                                         max_fif_arcs));
                    return;
                }
                ArcDecl arc;
                arc.from = state_name(k);
                arc.to = state_name(*to);
                arc.label = fmt::format("T{}", j + 1);
                arc.loc = arc.from_loc = arc.to_loc = f_.pieces[j].loc;
                arc.op = copy(*f_.pieces[j].map);
                arcs.push_back(std::move(arc));
            }
        }
        shape_points(pieces, intervals);
        for (std::size_t k = 0; k < intervals.size(); ++k)
            a_.states.push_back({state_name(k),
                                 it_.loc,
                                 space,
                                 partitioned_chord(pieces, intervals[k].first, intervals[k].second),
                                 {},
                                 {},
                                 {}});
        a_.arcs = std::move(arcs);
    }

    Q t0_, tn_;                         // a PFIF's interval
    std::vector<std::size_t> by_range_; // its pieces in the order of their ranges

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
