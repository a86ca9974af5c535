// The typed stage: the typed tree, the typing rules on sized types, and errors of both stages in one run.
#include "driver/pipeline.hpp"
#include "frontend/types.hpp"

#include <catch2/catch.hpp>

using namespace frac;
using namespace frac::front;

namespace {

std::string message_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const CompileError& e) {
        return e.what();
    }
    return "";
}

} // namespace

TEST_CASE("a generic function is checked once per signature", "[typecheck]") {
    auto c = driver::compile_source("t.frac", "fn twice(a) = a + a;\n"
                                              "shape s(x, y) = twice(x) + twice((x, y)).y + twice(y);");
    REQUIRE(c->ok());
    std::vector<std::string> signatures;
    for (const FunctionInstance& f : c->typed.instances) {
        CHECK(f.function->name == "twice");
        CHECK(f.result == f.params.at(0));
        signatures.push_back(type_spelling(f.params[0]));
    }
    CHECK(signatures == std::vector<std::string>{"number", "point2"});
    // The shape's expression and the function's body have their types in the typed program.
    for (const Item& it : c->program.items) {
        if (it.kind == ItemKind::fn) CHECK(c->typed.roots.at(it.body.get()) == Type::point(2)); // the latest
        if (it.kind == ItemKind::shape) {
            REQUIRE(c->typed.roots.count(it.body.get()));
            CHECK(c->typed.roots.at(it.body.get()) == Type::number());
            CHECK(c->typed.items.at(&it) == Type{Type::Kind::shape, 2});
        }
    }
}

TEST_CASE("matrices and transforms have sized types", "[typecheck]") {
    const Location l{};
    const Type m23 = Type::matrix(2, 3), m34 = Type::matrix(3, 4), m33 = Type::matrix(3, 3);
    CHECK(binary_rule(Tok::star, m23, m34, l, l, l) == Type::matrix(2, 4));
    CHECK(binary_rule(Tok::plus, m33, m33, l, l, l) == m33);
    CHECK(binary_rule(Tok::star, Type::number(), m23, l, l, l) == m23);
    CHECK(binary_rule(Tok::star, m23, Type::point(3), l, l, l) == Type::point(2));
    // A transform takes the dimension of the one it is composed with; of R2 it is a 3×3 matrix.
    CHECK(binary_rule(Tok::star, Type::transform(0), Type::transform(2), l, l, l) == Type::transform(2));
    CHECK(binary_rule(Tok::star, Type::transform(2), m33, l, l, l) == m33);
    CHECK(binary_rule(Tok::star, Type::transform(0), Type::matrix(4, 4), l, l, l) == Type::matrix(4, 4));
    CHECK(message_of([&] { binary_rule(Tok::star, m23, m23, l, l, l); }) ==
          "the product of a 2×3 matrix and a 2×3 matrix is undefined: 3 columns against 2 rows");
    CHECK(message_of([&] { binary_rule(Tok::star, Type::transform(2), Type::transform(3), l, l, l); }) ==
          "transforms of R2 and R3 do not compose");
    CHECK(message_of([&] { binary_rule(Tok::plus, m23, m33, l, l, l); }) ==
          "'+' is not defined between a 2×3 matrix and a 3×3 matrix");
    CHECK(message_of([&] { require_number(m33, l); }) == "expected a number, found a 3×3 matrix");
}

TEST_CASE("type errors and value errors are reported in one run", "[typecheck]") {
    // Line 1 is a type error (the type checker), line 2 a value error (lowering: constant bounds).
    auto c = driver::compile_source("t.frac",
                                    "shape s(x, y) over 3 = x;\nshape t(x, y) over [1, 0] × [0, 1] = x;");
    const std::string e = c->diags.render(c->sources);
    CHECK(e.find("t.frac:1:20: error: 'over' needs a box") != std::string::npos);
    CHECK(e.find("t.frac:2:20: error: the lower bound of an interval must not exceed its upper bound") !=
          std::string::npos);
    CHECK(c->diags.error_count() == 2);
}
