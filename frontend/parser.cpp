// Recursive-descent parser for grammar/frac.ebnf. One function per production.
#include "frontend/ast.hpp"

#include <fmt/format.h>

#include <charconv>
#include <set>

namespace frac::front {

namespace {

class Parser {
public:
    Parser(const std::vector<Token>& tokens, Diagnostics& diags, const Limits& limits)
        : t_(tokens), diags_(diags), max_nesting_(limits.max_nesting), max_operators_(limits.max_operators) {}

    Program program() {
        Program p;
        while (!at(Tok::end)) {
            depth_ = 0;
            operators_ = 0;
            try {
                p.items.push_back(item());
            } catch (const CompileError& e) {
                diags_.error(e.loc, e.what());
                synchronize();
            }
        }
        return p;
    }

private:
    // ---- token helpers ----
    const Token& cur() const { return t_[pos_]; }
    const Token& ahead(std::size_t k) const { return t_[std::min(pos_ + k, t_.size() - 1)]; }
    bool at(Tok k) const { return cur().kind == k; }
    const Token& take() {
        const Token& tok = t_[pos_];
        if (pos_ + 1 < t_.size()) ++pos_;
        return tok;
    }
    bool accept(Tok k) {
        if (!at(k)) return false;
        take();
        return true;
    }
    const Token& expect(Tok k, const char* what) {
        if (!at(k)) {
            // `[0, 1] x [0, 1]`: x is a name (a coordinate), not the box product.
            if (at(Tok::ident) && cur().text == "x" && pos_ > 0 && t_[pos_ - 1].kind == Tok::rbracket)
                fail("'x' is a name, not the box product: write × or * between the intervals, as in "
                     "[0, 1] × [0, 1]");
            fail(fmt::format("expected {} {}, found {}", token_name(k), what, describe(cur())));
        }
        return take();
    }
    static std::string describe(const Token& tok) {
        if (tok.kind == Tok::ident || tok.kind == Tok::number) return fmt::format("'{}'", tok.text);
        return token_name(tok.kind);
    }
    [[noreturn]] void fail(const std::string& message) const { throw CompileError(cur().loc, message); }

    // Skips to the start of the next item after a syntax error.
    void synchronize() {
        int depth = 0;
        while (!at(Tok::end)) {
            const Tok k = cur().kind;
            const bool anonymous_fn = k == Tok::kw_fn && ahead(1).kind == Tok::lparen; // not an item
            if (depth == 0 &&
                ((k == Tok::kw_fn && !anonymous_fn) || k == Tok::kw_const || k == Tok::kw_shape ||
                 k == Tok::kw_test || k == Tok::kw_import || k == Tok::kw_print || at_automaton()))
                return;
            take();
            if (k == Tok::lbrace) ++depth;
            if (k == Tok::rbrace && --depth <= 0) {
                depth = 0;
                if (at(Tok::semicolon)) take();
                return;
            }
            if (k == Tok::semicolon && depth == 0) return;
        }
    }

    // `ifs` and `cifs` are words of the language only where a definition starts (they stay usable as
    // names elsewhere).
    bool at_automaton() const {
        return at(Tok::ident) &&
               (cur().text == "ifs" || cur().text == "cifs" || cur().text == "bcifs" ||
                cur().text == "fif") &&
               ahead(1).kind == Tok::ident;
    }
    bool at_word(const char* word) const { return at(Tok::ident) && cur().text == word; }

    // ---- items ----
    Item item() {
        Item it;
        it.loc = cur().loc;
        if (at_automaton()) return automaton(std::move(it));
        switch (cur().kind) {
        case Tok::kw_import:
            take();
            it.kind = ItemKind::import;
            it.name = expect(Tok::string, "after 'import'").text;
            if (at(Tok::ident) && cur().text == "as") {
                take();
                it.alias = expect(Tok::ident, "after 'as' (the module's prefix)").text;
                aliases_.insert(it.alias);
            }
            expect(Tok::semicolon, "after the import");
            return it;
        case Tok::kw_fn:
            take();
            it.kind = ItemKind::fn;
            it.name = expect(Tok::ident, "after 'fn'").text;
            expect(Tok::lparen, "before the parameters");
            it.params = params();
            it.has_params = true;
            expect(Tok::assign, "before the function body");
            it.body = expr();
            expect(Tok::semicolon, "after the function");
            return it;
        case Tok::kw_const:
            take();
            it.kind = ItemKind::const_;
            it.name = expect(Tok::ident, "after 'const'").text;
            expect(Tok::assign, "in the constant");
            it.body = expr();
            expect(Tok::semicolon, "after the constant");
            return it;
        case Tok::kw_shape:
            take();
            it.kind = ItemKind::shape;
            it.name = expect(Tok::ident, "after 'shape'").text;
            if (accept(Tok::lparen)) {
                it.params = params();
                it.has_params = true;
            }
            if (accept(Tok::kw_over)) it.over = expr();
            expect(Tok::assign, "before the shape's function");
            it.body = expr();
            expect(Tok::semicolon, "after the shape");
            return it;
        case Tok::kw_test:
            take();
            it.kind = ItemKind::test;
            it.name = expect(Tok::string, "(the test's name) after 'test'").text;
            expect(Tok::lbrace, "to open the test");
            while (!at(Tok::rbrace) && !at(Tok::end)) {
                try {
                    it.expects.push_back(expect_stmt());
                } catch (const CompileError& e) {
                    diags_.error(e.loc, e.what());
                    while (!at(Tok::semicolon) && !at(Tok::rbrace) && !at(Tok::end)) take();
                    accept(Tok::semicolon);
                }
            }
            expect(Tok::rbrace, "to close the test");
            return it;
        case Tok::kw_print:
            take();
            it.kind = ItemKind::print;
            it.body = expr();
            expect(Tok::semicolon, "after print");
            return it;
        default:
            fail(fmt::format("expected a definition (fn, const, shape, ifs, cifs, bcifs, fif, test, import "
                             "or print), found {}",
                             describe(cur())));
        }
    }

    // ifs NAME in SPACE { [LABEL =] OP [prob P]; ... [primitive = E;] }
    // cifs NAME { state a, b in SPACE; a -> b : [LABEL =] OP [prob P]; initial a; primitive a = E;
    //             project = controls(...); }
    // bcifs NAME { cell v, e in bary(n); cell l = OTHER.e; param p [in [lo, hi]] [= v];
    //              subdivide e { T0 [-> c] = OP; }
    //              boundary e from v { B0 = OP; } e.B0 * v.T0 == e.T0 * e.B0; fix e.T0[r][c] = E; ... }
    Item automaton(Item it) {
        if (at_word("fif")) return fif(std::move(it));
        const std::string word(take().text);
        const bool graph_directed = word != "ifs";
        it.kind = ItemKind::automaton;
        it.name = expect(Tok::ident, word == "ifs"    ? "after 'ifs'"
                                     : word == "cifs" ? "after 'cifs'"
                                                      : "after 'bcifs'")
                      .text;
        auto a = std::make_shared<AutomatonDecl>();
        a->graph_directed = graph_directed;
        if (word == "bcifs") a->bcifs = std::make_shared<BcifsDecl>();
        if (!graph_directed) {
            if (!at(Tok::kw_in))
                fail("expected 'in' and the space of the ifs (R2, R3 or bary(n)) after its name");
            take();
            a->states.push_back({it.name, it.loc, space(), nullptr, {}, {}, {}});
        }
        expect(Tok::lbrace, "to open the automaton");
        while (!at(Tok::rbrace) && !at(Tok::end)) {
            try {
                automaton_stmt(*a, it.name);
            } catch (const CompileError& e) {
                diags_.error(e.loc, e.what());
                unknown_entries_ = false;
                while (!at(Tok::semicolon) && !at(Tok::rbrace) && !at(Tok::end)) take();
                accept(Tok::semicolon);
            }
        }
        expect(Tok::rbrace, "to close the automaton");
        it.automaton = std::move(a);
        return it;
    }

    // fif NAME { points P0, ..., PN; | data "FILE"; scale C1, ..., CN; [domains (j, k), ...;] }, or a PFIF:
    // fif NAME { piece [ALPHA, BETA] MATRIX; ... } (ast.hpp)
    Item fif(Item it) {
        take();
        it.kind = ItemKind::automaton;
        it.name = expect(Tok::ident, "after 'fif'").text;
        auto a = std::make_shared<AutomatonDecl>();
        a->graph_directed = true;
        a->fif = std::make_shared<FifDecl>();
        FifDecl& f = *a->fif;
        expect(Tok::lbrace, "to open the fif");
        while (!at(Tok::rbrace) && !at(Tok::end)) {
            try {
                const Token& word = expect(Tok::ident, "(points, data, scale, domains or piece) in a fif");
                if (word.text == "piece") {
                    FifPiece piece;
                    piece.loc = word.loc;
                    expect(Tok::lbracket, "to open the piece's domain [alpha, beta]");
                    piece.from = expr();
                    expect(Tok::comma, "between the ends of the piece's domain");
                    piece.to = expr();
                    expect(Tok::rbracket, "to close the piece's domain");
                    piece.map = expr();
                    f.pieces.push_back(std::move(piece));
                } else if (word.text == "points") {
                    f.points_loc = word.loc;
                    do f.points.push_back(expr());
                    while (accept(Tok::comma));
                } else if (word.text == "data") {
                    f.data_loc = word.loc;
                    f.data = expect(Tok::string, "(the CSV file) after 'data'").text;
                } else if (word.text == "scale") {
                    f.scale_loc = word.loc;
                    do f.scales.push_back(expr());
                    while (accept(Tok::comma));
                } else if (word.text == "domains") {
                    f.domains_loc = word.loc;
                    do {
                        f.domain_locs.push_back(cur().loc);
                        expect(Tok::lparen, "to open a domain (j, k): the indices of its end points");
                        const int j = point_index();
                        expect(Tok::comma, "between the domain's two point indices");
                        const int k = point_index();
                        expect(Tok::rparen, "to close the domain");
                        f.domains.push_back({j, k});
                    } while (accept(Tok::comma));
                } else {
                    throw CompileError(word.loc,
                                       fmt::format("expected points, data, scale, domains or piece in a fif, "
                                                   "found '{}'",
                                                   word.text));
                }
                expect(Tok::semicolon, "after the fif statement");
            } catch (const CompileError& e) {
                diags_.error(e.loc, e.what());
                f.malformed = true;
                while (!at(Tok::semicolon) && !at(Tok::rbrace) && !at(Tok::end)) take();
                accept(Tok::semicolon);
            }
        }
        expect(Tok::rbrace, "to close the fif");
        it.automaton = std::move(a);
        return it;
    }

    int point_index() {
        const Token& n = expect(Tok::number, "(a point index, counted from 0)");
        int v = 0;
        const auto [end, ec] = std::from_chars(n.text.data(), n.text.data() + n.text.size(), v);
        if (ec != std::errc() || end != n.text.data() + n.text.size() || v < 0)
            throw CompileError(n.loc, fmt::format("a point index is a whole number from 0, not {}", n.text));
        return v;
    }

    void automaton_stmt(AutomatonDecl& a, const std::string& name) {
        if (a.bcifs && bcifs_stmt(a)) return;
        if (a.graph_directed && !a.bcifs && at_word("state")) {
            take();
            state_list(a, "as a state name", "and the states' space (R2, R3 or bary(n))", 2);
        } else if (a.graph_directed && at_word("initial")) {
            take();
            const Token& n = expect(Tok::ident, "(the initial state) after 'initial'");
            a.initial = n.text;
            a.initial_loc = n.loc;
        } else if (at_word("primitive")) {
            take();
            std::string state = name;
            Location loc = cur().loc;
            if (a.graph_directed) {
                const Token& n = expect(Tok::ident, "(the state) after 'primitive'");
                state = n.text;
                loc = n.loc;
            }
            expect(Tok::assign, "before the primitive");
            ExprPtr e = expr();
            bool found = false;
            for (StateDecl& s : a.states)
                if (s.name == state) {
                    s.primitive = std::move(e);
                    found = true;
                }
            if (!found) throw CompileError(loc, fmt::format("no state '{}' in this automaton", state));
        } else if (a.graph_directed && at_word("project")) {
            take();
            expect(Tok::assign, "after 'project'");
            a.projection = expr();
        } else if (a.bcifs) {
            a.bcifs->constraints.push_back(constraint());
        } else {
            ArcDecl arc;
            arc.loc = cur().loc;
            if (a.graph_directed) {
                const Token& from = expect(Tok::ident, "(a state, or state, initial, primitive, project)");
                arc.from = from.text;
                arc.from_loc = from.loc;
                expect(Tok::minus, "and '>' (an arc: a -> b : T)");
                expect(Tok::gt, "after '-' (an arc: a -> b : T)");
                const Token& to = expect(Tok::ident, "(the arc's target state) after '->'");
                arc.to = to.text;
                arc.to_loc = to.loc;
                expect(Tok::colon, "before the arc's operator");
            } else {
                arc.from = arc.to = name;
                arc.from_loc = arc.to_loc = arc.loc;
            }
            if (at(Tok::ident) && ahead(1).kind == Tok::assign) {
                arc.label = take().text;
                take();
            }
            arc.op = expr();
            if (at_word("prob")) {
                take();
                arc.probability = expr();
            }
            a.arcs.push_back(std::move(arc));
        }
        expect(Tok::semicolon, "after the statement");
    }

    // NAME, NAME ... in SPACE: states (cells) of one space.
    void state_list(AutomatonDecl& a, const char* name_what, const char* space_what, int min_weights) {
        std::vector<std::pair<std::string, Location>> names;
        do {
            const Token& n = expect(Tok::ident, name_what);
            names.emplace_back(n.text, n.loc);
        } while (accept(Tok::comma));
        expect(Tok::kw_in, space_what);
        const SpaceDecl s = space(min_weights);
        for (auto& [n, loc] : names) a.states.push_back({n, loc, s, nullptr, {}, {}, {}});
    }

    // The statements only a bcifs has; false when the statement is a common one (initial, primitive,
    // project) or a constraint. Block statements take their own closing brace (and an optional ';').
    bool bcifs_stmt(AutomatonDecl& a) {
        BcifsDecl& b = *a.bcifs;
        if (at_word("cell")) {
            take();
            if (at(Tok::ident) && ahead(1).kind == Tok::assign) {
                // cell l = spline.e;  a cell of another bcifs, with its solved operators
                StateDecl s;
                const Token& n = take();
                s.name = n.text;
                s.loc = n.loc;
                take();
                const Token& from = expect(Tok::ident, "(a bcifs) after '=' (cell l = spline.e)");
                s.source = from.text;
                s.source_loc = from.loc;
                expect(Tok::dot, "after the bcifs (cell l = spline.e)");
                s.source_cell = expect(Tok::ident, "(a cell of that bcifs) after '.'").text;
                a.states.push_back(std::move(s));
            } else {
                state_list(a, "as a cell name", "and the cells' space (bary(n), R2 or R3)", 1);
            }
        } else if (at_word("param")) {
            take();
            ParamDecl p;
            const Token& n = expect(Tok::ident, "as the parameter's name");
            p.name = n.text;
            p.loc = n.loc;
            if (accept(Tok::kw_in)) {
                expect(Tok::lbracket, "to open the parameter's range [lo, hi]");
                p.lo = expr();
                expect(Tok::comma, "between the range's bounds");
                p.hi = expr();
                expect(Tok::rbracket, "to close the parameter's range");
            }
            if (accept(Tok::assign)) p.value = expr();
            b.params.push_back(std::move(p));
        } else if (at_word("subdivide") || at_word("boundary")) {
            const bool boundary = take().text == "boundary";
            const Token& cell = expect(Tok::ident, "(a cell)");
            std::string from;
            Location from_loc;
            if (boundary) {
                if (!at_word("from"))
                    fail("expected 'from' and the embedded cell (boundary e from v { ... })");
                take();
                const Token& f = expect(Tok::ident, "(the embedded cell) after 'from'");
                from = f.text;
                from_loc = f.loc;
            }
            expect(Tok::lbrace,
                   boundary ? "to open the boundary operators" : "to open the subdivision operators");
            while (!at(Tok::rbrace) && !at(Tok::end)) {
                OperatorDecl op;
                op.cell = cell.text;
                op.boundary = boundary;
                const Token& label = expect(Tok::ident, "as the operator's name (T0, B1, ...)");
                op.name = label.text;
                op.loc = label.loc;
                op.target = boundary ? from : cell.text;
                op.target_loc = boundary ? from_loc : cell.loc;
                if (!boundary && accept(Tok::minus)) {
                    expect(Tok::gt, "after '-' (T1 -> c = ...: a subdivision into the cell c)");
                    const Token& t = expect(Tok::ident, "(the target cell) after '->'");
                    op.target = t.text;
                    op.target_loc = t.loc;
                }
                expect(Tok::assign, "after the operator's name");
                if (!accept(Tok::question)) {
                    unknown_entries_ = true;
                    op.value = expr();
                    unknown_entries_ = false;
                }
                expect(Tok::semicolon, "after the operator");
                b.operators.push_back(std::move(op));
            }
            expect(Tok::rbrace, "to close the operators");
            accept(Tok::semicolon);
            return true;
        } else if (at_word("topology")) {
            take();
            TopologyDecl t;
            const Token& cell = expect(Tok::ident, "(a cell) after 'topology'");
            t.cell = cell.text;
            t.loc = cell.loc;
            expect(Tok::assign, "after the cell (topology f = quad(e) split 2 x 2)");
            const Token& kind = expect(Tok::ident, "(edge, quad, triangle or cube)");
            t.kind = kind.text;
            t.kind_loc = kind.loc;
            if (t.kind != "edge" && t.kind != "quad" && t.kind != "triangle" && t.kind != "cube")
                throw CompileError(kind.loc,
                                   fmt::format("no topology '{}': the topologies are edge(v) split n, "
                                               "quad(e) split n x n, triangle(e) split n and cube(f) split "
                                               "n x n x n",
                                               t.kind));
            expect(Tok::lparen, "after the topology");
            const Token& of = expect(Tok::ident, t.kind == "edge"   ? "(the vertex cell)"
                                                 : t.kind == "cube" ? "(the face cell)"
                                                                    : "(the edge cell)");
            t.of = of.text;
            t.of_loc = of.loc;
            if (t.kind == "quad" && accept(Tok::comma)) {
                const Token& g = expect(Tok::ident, "(the edge cell of the left and right sides)");
                t.across = g.text;
                t.across_loc = g.loc;
            }
            expect(Tok::rparen, "after the boundary cell");
            if (!at_word("split")) fail("expected 'split' and the number of parts");
            take();
            t.n = count();
            const int axes = t.kind == "quad" ? 2 : t.kind == "cube" ? 3 : 1;
            for (int axis = 1; axis < axes; ++axis) {
                if (!at_word("x") && !at(Tok::times) && !at(Tok::star))
                    fail("expected 'x' and the parts along the next axis");
                take();
                (axis == 1 ? t.m : t.l) = count();
            }
            b.topologies.push_back(std::move(t));
        } else if (at_word("seed")) {
            take();
            const Token& n = expect(Tok::number, "(the seed of the free entries' values) after 'seed'");
            if (n.text.empty() || n.text.size() > 18 ||
                n.text.find_first_not_of("0123456789") != std::string::npos)
                throw CompileError(
                    n.loc, fmt::format("a seed is a whole number of at most 18 digits, not {}", n.text));
            b.seed = std::stoull(std::string(n.text));
        } else if (at_word("fix")) {
            take();
            FixDecl f;
            f.loc = cur().loc;
            f.cell = expect(Tok::ident, "(a cell) after 'fix'").text;
            expect(Tok::dot, "after the cell (fix e.T0[r][c] = value)");
            f.name = expect(Tok::ident, "(an operator) after the cell").text;
            f.index_loc = cur().loc;
            f.row = index();
            f.col = index();
            expect(Tok::assign, "after the entry");
            f.value = expr();
            b.fixes.push_back(std::move(f));
        } else {
            return false;
        }
        expect(Tok::semicolon, "after the statement");
        return true;
    }

    // The number of parts of a topology: 1 to 16.
    int count() {
        const Token& n = expect(Tok::number, "(the number of parts)");
        const int v = std::atoi(std::string(n.text).c_str());
        if (n.text.find_first_not_of("0123456789") != std::string::npos || n.text.size() > 2 || v < 1 ||
            v > 16)
            throw CompileError(n.loc, fmt::format("a topology splits into 1 to 16 parts, not {}", n.text));
        return v;
    }

    // [k]: an entry index, counted from 0.
    int index() {
        expect(Tok::lbracket, "(an entry index [row][column], counted from 0)");
        const Token& n = expect(Tok::number, "as an entry index");
        if (n.text.find_first_not_of("0123456789") != std::string::npos || n.text.size() > 4)
            throw CompileError(n.loc, fmt::format("an entry index is a whole number, not {}", n.text));
        expect(Tok::rbracket, "after the entry index");
        return std::atoi(std::string(n.text).c_str());
    }

    // PRODUCT == PRODUCT, where each factor is an operator cell.name or a constant matrix.
    ConstraintDecl constraint() {
        ConstraintDecl c;
        c.loc = cur().loc;
        c.left = product();
        expect(Tok::eq, "(a constraint: a product of operators == another)");
        c.right = product();
        return c;
    }
    std::vector<FactorDecl> product() {
        std::vector<FactorDecl> factors;
        do {
            FactorDecl f;
            f.loc = cur().loc;
            if (at(Tok::ident) && ahead(1).kind == Tok::dot && ahead(2).kind == Tok::ident &&
                !aliases_.count(cur().text)) {
                f.cell = take().text;
                take();
                f.name = take().text;
            } else {
                f.constant = unary_expr();
            }
            factors.push_back(std::move(f));
        } while (accept(Tok::star));
        return factors;
    }

    // R2, R3 or bary(n).
    SpaceDecl space(int min_weights = 2) {
        SpaceDecl s;
        s.loc = cur().loc;
        if (at(Tok::ident) && (cur().text == "R2" || cur().text == "R3")) {
            s.n = cur().text == "R2" ? 2 : 3;
            take();
            return s;
        }
        if (at_word("bary")) {
            take();
            expect(Tok::lparen, "after 'bary'");
            const Token& n = expect(Tok::number, "(the number of weights) in bary(n)");
            const int v = std::atoi(std::string(n.text).c_str());
            if (v < min_weights || v > 64 || n.text.find_first_not_of("0123456789") != std::string::npos)
                throw CompileError(n.loc, fmt::format("bary(n) needs an integer n from {} to 64, not {}",
                                                      min_weights, n.text));
            expect(Tok::rparen, "after bary(n)");
            s.barycentric = true;
            s.n = v;
            return s;
        }
        fail(fmt::format("expected a space (R2, R3 or bary(n)), found {}", describe(cur())));
    }

    std::vector<Param> params() {
        std::vector<Param> ps;
        if (accept(Tok::rparen)) return ps;
        do {
            const Token& name = expect(Tok::ident, "as a parameter name");
            ps.push_back({std::string(name.text), name.loc});
        } while (accept(Tok::comma));
        expect(Tok::rparen, "after the parameters");
        return ps;
    }

    Expect expect_stmt() {
        Expect e;
        e.loc = expect(Tok::kw_expect, "in a test").loc;
        e.expr = expr();
        if (accept(Tok::kw_within)) e.within = expr();
        expect(Tok::semicolon, "after the expectation");
        return e;
    }

    // ---- expressions, lowest precedence first ----
    ExprPtr make(ExprKind k, Location loc) {
        auto e = std::make_unique<Expr>();
        e->kind = k;
        e->loc = loc;
        return e;
    }
    // A chain a + b + c ... (or a.x.y ...) is a left-deep tree: every later pass recurses along it.
    void count_operator(Location loc) {
        if (++operators_ > max_operators_)
            throw CompileError(loc, fmt::format("this definition has more than the limit of {} operators{}",
                                                max_operators_, raised_by("FRAC_MAX_OPERATORS")));
    }
    // Each level of nesting is a few frames of this parser and of every later pass.
    void enter(Location loc) {
        if (++depth_ > max_nesting_)
            throw CompileError(loc, fmt::format("expression nested deeper than the limit of {} levels{}",
                                                max_nesting_, raised_by("FRAC_MAX_NESTING")));
    }
    ExprPtr binary(Tok op, Location loc, ExprPtr a, ExprPtr b) {
        count_operator(loc);
        auto e = make(ExprKind::binary, loc);
        e->op = op;
        e->kids.reserve(2); // one allocation, not two
        e->kids.push_back(std::move(a));
        e->kids.push_back(std::move(b));
        return e;
    }

    ExprPtr expr() {
        enter(cur().loc);
        ExprPtr e;
        if (at(Tok::kw_let)) {
            e = make(ExprKind::let, take().loc);
            do {
                const Token& name = expect(Tok::ident, "after 'let'");
                expect(Tok::assign, "in the let binding");
                e->bindings.push_back({std::string(name.text), name.loc, expr()});
            } while (accept(Tok::comma));
            expect(Tok::kw_in, "after the let bindings");
            e->kids.push_back(expr());
        } else if (at(Tok::kw_if)) {
            e = make(ExprKind::if_, take().loc);
            e->kids.push_back(expr());
            expect(Tok::kw_then, "after the condition");
            e->kids.push_back(expr());
            expect(Tok::kw_else, "in the if expression");
            e->kids.push_back(expr());
        } else {
            e = or_expr();
        }
        --depth_;
        return e;
    }

    ExprPtr or_expr() {
        ExprPtr e = and_expr();
        while (at(Tok::kw_or)) {
            const Location loc = take().loc;
            e = binary(Tok::kw_or, loc, std::move(e), and_expr());
        }
        return e;
    }
    ExprPtr and_expr() {
        ExprPtr e = not_expr();
        while (at(Tok::kw_and)) {
            const Location loc = take().loc;
            e = binary(Tok::kw_and, loc, std::move(e), not_expr());
        }
        return e;
    }
    ExprPtr not_expr() {
        if (at(Tok::kw_not)) {
            enter(cur().loc);
            auto e = make(ExprKind::unary, take().loc);
            e->op = Tok::kw_not;
            e->kids.push_back(not_expr());
            --depth_;
            return e;
        }
        return cmp_expr();
    }
    ExprPtr cmp_expr() {
        ExprPtr e = union_expr();
        const Tok k = cur().kind;
        if (k == Tok::lt || k == Tok::le || k == Tok::gt || k == Tok::ge || k == Tok::eq || k == Tok::ne) {
            const Location loc = take().loc;
            e = binary(k, loc, std::move(e), union_expr());
            const Tok again = cur().kind;
            if (again == Tok::lt || again == Tok::le || again == Tok::gt || again == Tok::ge ||
                again == Tok::eq || again == Tok::ne)
                fail("comparisons do not chain; combine them with 'and'");
        }
        return e;
    }
    ExprPtr union_expr() {
        ExprPtr e = inter_expr();
        while (at(Tok::bar)) {
            const Location loc = take().loc;
            e = binary(Tok::bar, loc, std::move(e), inter_expr());
        }
        return e;
    }
    ExprPtr inter_expr() {
        ExprPtr e = box_expr();
        while (at(Tok::amp)) {
            const Location loc = take().loc;
            e = binary(Tok::amp, loc, std::move(e), box_expr());
        }
        return e;
    }
    ExprPtr box_expr() {
        ExprPtr e = add_expr();
        while (at(Tok::times)) {
            const Location loc = take().loc;
            e = binary(Tok::times, loc, std::move(e), add_expr());
        }
        return e;
    }
    ExprPtr add_expr() {
        ExprPtr e = mul_expr();
        while (at(Tok::plus) || at(Tok::minus)) {
            const Tok k = cur().kind;
            const Location loc = take().loc;
            e = binary(k, loc, std::move(e), mul_expr());
        }
        return e;
    }
    ExprPtr mul_expr() {
        ExprPtr e = unary_expr();
        while (at(Tok::star) || at(Tok::slash)) {
            const Tok k = cur().kind;
            const Location loc = take().loc;
            e = binary(k, loc, std::move(e), unary_expr());
        }
        return e;
    }
    ExprPtr unary_expr() {
        if (at(Tok::minus) || at(Tok::plus) || at(Tok::tilde)) {
            enter(cur().loc);
            const Tok k = cur().kind;
            auto e = make(ExprKind::unary, take().loc);
            e->op = k;
            e->kids.push_back(unary_expr());
            --depth_;
            return e;
        }
        return power_expr();
    }
    ExprPtr power_expr() {
        ExprPtr base = postfix_expr();
        if (at(Tok::caret)) {
            // Right associative: a^b^c ... nests to the right, counted before the recursion.
            enter(cur().loc);
            const Location loc = take().loc;
            ExprPtr e = binary(Tok::caret, loc, std::move(base), unary_expr());
            --depth_;
            return e;
        }
        return base;
    }
    ExprPtr postfix_expr() {
        ExprPtr e = primary();
        while (at(Tok::dot)) {
            const Location loc = take().loc;
            count_operator(loc);
            auto f = make(ExprKind::field, loc);
            f->text = expect(Tok::ident, "after '.'").text;
            f->kids.push_back(std::move(e));
            e = std::move(f);
        }
        return e;
    }

    ExprPtr primary() {
        const Token& tok = cur();
        switch (tok.kind) {
        case Tok::number: {
            auto e = make(ExprKind::number, tok.loc);
            e->text = take().text;
            return e;
        }
        case Tok::ident: {
            const Token& name = take();
            std::string text(name.text);
            // alias.name: a name of a module imported `as alias` (the alias shadows a point's fields).
            if (aliases_.count(text) && at(Tok::dot) && ahead(1).kind == Tok::ident) {
                take();
                (text += ".") += take().text;
            }
            if (!at(Tok::lparen)) {
                auto e = make(ExprKind::name, name.loc);
                e->text = std::move(text);
                return e;
            }
            take();
            if ((text == "sum" || text == "min" || text == "max") && at(Tok::ident) &&
                ahead(1).kind == Tok::kw_in)
                return series(name);
            auto e = make(ExprKind::call, name.loc);
            e->text = std::move(text);
            if (!accept(Tok::rparen)) {
                do {
                    Arg a;
                    a.loc = cur().loc;
                    if (at(Tok::ident) && ahead(1).kind == Tok::colon) {
                        a.name = take().text;
                        take();
                    }
                    a.value = at(Tok::kw_fn) ? lambda() : expr();
                    e->args.push_back(std::move(a));
                } while (accept(Tok::comma));
                expect(Tok::rparen, "after the arguments");
            }
            return e;
        }
        case Tok::lparen: {
            const Location loc = take().loc;
            ExprPtr first = expr();
            if (!at(Tok::comma)) {
                expect(Tok::rparen, "to close the parenthesis");
                return first;
            }
            auto e = make(ExprKind::tuple, loc);
            e->kids.push_back(std::move(first));
            while (accept(Tok::comma)) e->kids.push_back(expr());
            expect(Tok::rparen, "to close the point");
            return e;
        }
        case Tok::lbracket: {
            if (ahead(1).kind == Tok::lbracket) return matrix();
            auto e = make(ExprKind::interval, take().loc);
            e->kids.push_back(expr());
            expect(Tok::comma, "between the interval's bounds");
            e->kids.push_back(expr());
            expect(Tok::rbracket, "to close the interval");
            return e;
        }
        case Tok::question: {
            if (!unknown_entries_)
                fail("'?' (an unknown entry) is written only in a bcifs operator's matrix");
            auto e = make(ExprKind::name, tok.loc);
            e->text = take().text; // "?"
            return e;
        }
        case Tok::kw_fn:
            fail("an anonymous function 'fn (...) = ...' is only an argument, where a function is expected");
        default: fail(fmt::format("expected an expression, found {}", describe(tok)));
        }
    }

    // [[a, b, c], [d, e, f]]: a matrix, row by row.
    ExprPtr matrix() {
        auto m = make(ExprKind::matrix, take().loc);
        do {
            auto row = make(ExprKind::tuple, expect(Tok::lbracket, "to open a matrix row").loc);
            do row->kids.push_back(expr());
            while (accept(Tok::comma));
            expect(Tok::rbracket, "to close the matrix row");
            if (!m->kids.empty() && row->kids.size() != m->kids.front()->kids.size())
                throw CompileError(row->loc, fmt::format("this row has {} entries, the first row {}",
                                                         row->kids.size(), m->kids.front()->kids.size()));
            m->kids.push_back(std::move(row));
        } while (accept(Tok::comma));
        expect(Tok::rbracket, "to close the matrix");
        return m;
    }

    // fn (a, b) = body: an anonymous function, passed as an argument where a function is expected.
    ExprPtr lambda() {
        auto e = make(ExprKind::lambda, take().loc);
        expect(Tok::lparen, "after 'fn' in an anonymous function");
        for (Param& p : params()) e->bindings.push_back({std::move(p.name), p.loc, nullptr});
        expect(Tok::assign, "after the parameters of an anonymous function");
        e->kids.push_back(expr());
        return e;
    }

    // sum(i in a.., body), min(i in a..b, body), max(...)
    ExprPtr series(const Token& name) {
        auto e = make(ExprKind::series, name.loc);
        e->series = std::make_unique<SeriesSyntax>();
        e->text = name.text;
        e->series->var = take().text;
        expect(Tok::kw_in, "after the series index");
        e->kids.push_back(add_expr());
        expect(Tok::dotdot, "in the index range");
        e->kids.push_back(at(Tok::comma) ? nullptr : add_expr());
        expect(Tok::comma, "after the index range");
        // An orbit: p in orbit(p0, M) walks p_k = M(p_{k-1}) along with the index.
        if (at(Tok::ident) && ahead(1).kind == Tok::kw_in && ahead(2).kind == Tok::ident &&
            ahead(2).text == "orbit" && ahead(3).kind == Tok::lparen) {
            e->series->orbit_loc = cur().loc;
            e->series->orbit_var = take().text;
            take();
            take();
            take();
            ExprPtr init = expr();
            expect(Tok::comma, "after the orbit's initial point");
            e->series->orbit_map = expect(Tok::ident, "(the map of the orbit)").text;
            if (aliases_.count(e->series->orbit_map) && at(Tok::dot) && ahead(1).kind == Tok::ident) {
                take();
                (e->series->orbit_map += ".") += take().text;
            }
            expect(Tok::rparen, "to close the orbit");
            // An escape certificate: `escape R`, a radius the compiler proves orbits never return from.
            ExprPtr escape;
            if (at(Tok::ident) && cur().text == "escape") {
                e->series->escape_loc = take().loc;
                escape = add_expr();
            }
            expect(Tok::comma, "after the orbit");
            e->kids.push_back(expr());
            e->kids.push_back(std::move(init));
            if (escape) e->kids.push_back(std::move(escape));
        } else {
            e->kids.push_back(expr());
        }
        expect(Tok::rparen, "to close the series");
        return e;
    }

    std::set<std::string, std::less<>> aliases_; // of this file's qualified imports so far
    const std::vector<Token>& t_;
    Diagnostics& diags_;
    int max_nesting_, max_operators_;
    std::size_t pos_ = 0;
    int depth_ = 0;
    int operators_ = 0;
    bool unknown_entries_ = false; // inside a bcifs operator: `?` is an unknown entry
};

} // namespace

Program parse(const std::vector<Token>& tokens, Diagnostics& diags, const Limits& limits) {
    return Parser(tokens, diags, limits).program();
}

} // namespace frac::front
