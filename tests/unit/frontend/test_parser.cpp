#include "driver/pipeline.hpp"
#include "frontend/ast.hpp"

#include <catch2/catch.hpp>

using namespace frac::front;

namespace {

std::string ast_of(const std::string& text, std::string* errors = nullptr) {
    frac::driver::CompileOptions options;
    options.stop = frac::driver::Stage::parse;
    auto c = frac::driver::compile_source("t.frac", text, options);
    if (errors)
        *errors = c->diags.render(c->sources);
    else if (!c->ok())
        FAIL(c->diags.render(c->sources));
    return print_ast(c->program, 1);
}

} // namespace

// One example of every production of grammar/frac.ebnf.
TEST_CASE("every grammar production parses", "[grammar]") {
    struct Case {
        const char* production;
        const char* source;
        const char* ast;
    };
    const Case cases[] = {
        {"import", "import \"fractals\";", "(import \"fractals\")\n"},
        {"function/params", "fn f(a, b) = a;", "(fn f (a b) a)\n"},
        {"function without params", "fn k() = 1;", "(fn k () 1)\n"},
        {"constant", "const c = 2;", "(const c 2)\n"},
        {"shape", "shape s(x, y) over [0, 1] × [0, 2] = x;",
         "(shape s (x y) (over (× (interval 0 1) (interval 0 2))) x)\n"},
        {"shape without params", "shape s = x;", "(shape s () x)\n"},
        {"test/expectation", "test \"t\" { expect 1 < 2; expect 1 == 1 within 0.1; }",
         "(test \"t\"\n  (expect (< 1 2))\n  (expect (== 1 1) (within 0.1)))\n"},
        {"print", "print 1;", "(print 1)\n"},
        {"let/binding", "const c = let a = 1, b = a in b;", "(const c (let ((a 1) (b a)) b))\n"},
        {"if", "const c = if 1 < 2 then 3 else 4;", "(const c (if (< 1 2) 3 4))\n"},
        {"or/and/not", "const c = not 1 < 2 and 2 < 3 or 1 == 1;",
         "(const c (or (and (not (< 1 2)) (< 2 3)) (== 1 1)))\n"},
        {"comparison ops", "const c = 1 <= 2 and 2 != 0 and 1 >= 0 and 2 > 1 and 0 == 0;", ""},
        {"union/intersection", "const c = 1 | 2 & 3;", "(const c (| 1 (& 2 3)))\n"},
        {"box", "const c = [0, 1] × [2, 3] × [4, 5];",
         "(const c (× (× (interval 0 1) (interval 2 3)) (interval 4 5)))\n"},
        {"sum/product", "const c = 1 + 2 * 3 - 4 / 5;", "(const c (- (+ 1 (* 2 3)) (/ 4 5)))\n"},
        {"unary", "const c = -~+1;", "(const c (- (~ (+ 1))))\n"},
        {"power", "const c = -2^3^-1;", "(const c (- (^ 2 (^ 3 (- 1)))))\n"},
        {"postfix", "const c = (1, 2).y;", "(const c (. y (point 1 2)))\n"},
        {"primary: number forms", "const c = 1.5e-3 + .5 + 2.;", "(const c (+ (+ 1.5e-3 .5) 2.))\n"},
        {"primary: parenthesis", "const c = (1 + 2) * 3;", "(const c (* (+ 1 2) 3))\n"},
        {"primary: point", "const c = (1, 2, 3);", "(const c (point 1 2 3))\n"},
        {"primary: interval", "const c = [1, 2];", "(const c (interval 1 2))\n"},
        {"call/argument", "const c = dimension(s, from: 4, to: 9);",
         "(const c (call dimension s from: 4 to: 9))\n"},
        {"series infinite", "fn f(x) = sum(i in 0.., x / 2^i);", "(fn f (x) (sum i 0 inf (/ x (^ 2 i))))\n"},
        {"series finite", "fn f(x) = min(k in 1..5, x);", "(fn f (x) (min k 1 5 x))\n"},
        {"max call is not a series", "fn f(x) = max(x, 1);", "(fn f (x) (call max x 1))\n"},
        {"series orbit", "fn f(x) = min(k in 0..2, q in orbit((x, x), m), q.x);",
         "(fn f (x) (min k 0 2 (orbit q (point x x) m) (. x q)))\n"},
        {"call of a function parameter", "fn ap(f, x) = f(x, sqrt);", "(fn ap (f x) (call f x sqrt))\n"},
        {"lambda", "const c = ap(fn (t, u) = t + u, 1);", "(const c (call ap (fn (t u) (+ t u)) 1))\n"},
        {"orbit", "fn f(x) = min(k in 0..3, p in orbit((x, 0), m), p.x);",
         "(fn f (x) (min k 0 3 (orbit p (point x 0) m) (. x p)))\n"},
        {"orbit escape", "fn f(x) = min(k in 0.., p in orbit((x, 0), m) escape 1/2, p.x / 3^k);",
         "(fn f (x) (min k 0 inf (orbit p (point x 0) m (escape (/ 1 2))) (/ (. x p) (^ 3 k))))\n"},
        {"comments", "// line\n/* block */ const c = 1; // end", "(const c 1)\n"},
    };
    for (const Case& c : cases) {
        INFO(c.production);
        const std::string got = ast_of(c.source);
        if (*c.ast) CHECK(got == c.ast);
    }
}

TEST_CASE("ranges are not numbers: 0..5", "[lexer]") {
    CHECK(ast_of("fn f(x) = sum(i in 0..5, x);") == "(fn f (x) (sum i 0 5 x))\n");
}

TEST_CASE("syntax errors are located and the parser recovers", "[parser]") {
    std::string errors;
    ast_of("fn f(x) = x +;\nshape s(x, y) = (x;\nconst ok = 1;\nconst c = 1 < 2 < 3;\n", &errors);
    CHECK(errors.find("t.frac:1:14: error: expected an expression, found ';'") != std::string::npos);
    CHECK(errors.find("t.frac:2:19: error: expected ')' to close the parenthesis, found ';'") !=
          std::string::npos);
    CHECK(errors.find("t.frac:4:17: error: comparisons do not chain") != std::string::npos);
    // The source line and a caret under the column.
    CHECK(errors.find("  fn f(x) = x +;\n               ^\n") != std::string::npos);
}

TEST_CASE("deeply nested input is an error, not a stack overflow", "[parser][limits]") {
    std::string deep = "const c = " + std::string(100000, '(') + "1" + std::string(100000, ')') + ";";
    std::string errors;
    ast_of(deep, &errors);
    CHECK(errors.find("nested deeper than") != std::string::npos);
    std::string minus = "const c = " + std::string(100000, '-') + "1;";
    ast_of(minus, &errors);
    CHECK(errors.find("nested deeper than") != std::string::npos);
    // `not` and the right-associative `^` nest too (a chain of 10^5 overflowed the stack).
    std::string nots = "const c = ", powers = "const c = 2";
    for (int i = 0; i < 100000; ++i) {
        nots += "not ";
        powers += "^2";
    }
    for (const std::string& text : {nots + "1 < 2;", powers + ";"}) {
        ast_of(text, &errors);
        CHECK(errors.find("nested deeper than the limit of 200 levels (FRAC_MAX_NESTING raises it)") !=
              std::string::npos);
    }
}

TEST_CASE("operators and field accesses of a definition are limited", "[parser][limits]") {
    Limits limits;
    limits.max_operators = 100;
    std::string fields = "const c = p", sum = "const c = 1";
    for (int i = 0; i < 101; ++i) {
        fields += ".x";
        sum += " + 1";
    }
    for (const std::string& text : {fields + ";", sum + ";"}) {
        Diagnostics d;
        parse(lex(text, 1, d), d, limits);
        REQUIRE(d.error_count() == 1);
        CHECK(d.all()[0].message ==
              "this definition has more than the limit of 100 operators (FRAC_MAX_OPERATORS raises it)");
    }
    Diagnostics d;
    const std::string hundred = sum.substr(0, sum.size() - 4) + ";"; // 100 operators
    parse(lex(hundred, 1, d), d, limits);
    CHECK_FALSE(d.has_errors());
}

TEST_CASE("the unicode box operator is a token", "[lexer]") {
    Diagnostics d;
    const std::string_view text = "[0,1] × [0,1]";
    const auto toks = lex(text, 1, d);
    REQUIRE_FALSE(d.has_errors());
    CHECK(toks[5].kind == Tok::times);
    CHECK(toks[6].loc.column == 9); // columns count characters, not bytes
}

TEST_CASE("a long quoted token is cut in a message", "[diagnostics][limits]") {
    Diagnostics d;
    d.error({}, "unknown name '" + std::string(1000000, 'b') + "'; did you mean 'a'?");
    REQUIRE(d.all().size() == 1);
    CHECK(d.all()[0].message ==
          "unknown name '" + std::string(60, 'b') + "... (1000000 characters)'; did you mean 'a'?");
    d.error({}, "number '" + std::string(80, '9') + "' is too large"); // short enough: whole
    CHECK(d.all()[1].message == "number '" + std::string(80, '9') + "' is too large");
}
