// Constant evaluation: the stage between type checking and lowering (driver/pipeline.cpp). Every
// `const` of the program is evaluated once — to an exact rational where it folds exactly (1/3 + 1/6 is
// 1/2), to an outward enclosure otherwise (sqrt(2)) — and lowering takes these values instead of
// lowering the definitions again. frac check --emit=consteval prints them.
#pragma once

#include "frontend/ast.hpp"
#include "frontend/lower.hpp"
#include "frontend/module.hpp"
#include "frontend/operators.hpp"
#include "frontend/typecheck.hpp"

#include <memory>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace frac::front {

struct ConstantComponent {
    std::shared_ptr<const num::Rational> exact; // when the value is a rational the compiler knows
    Interval enclosure;
    double point = 0; // the nearest double
};

struct ConstantValue {
    ValueKind kind = ValueKind::scalar;
    std::vector<ConstantComponent> components; // a number or a condition: 1; a point: its coordinates
    std::vector<Interval> box;                 // an interval or a box
    std::shared_ptr<const LinearValue> linear; // a matrix or a transform
    const Item* item = nullptr;                // a shape, fn or automaton the constant names
};

struct ConstantValues {
    std::unordered_map<const Item*, ConstantValue> values;
    std::unordered_set<const Item*> failed; // reported by this stage; lowering skips them
};

// Evaluates every constant that type-checked (defined in lower.cpp: a body is evaluated by lowering it
// into a graph of its own, where it folds).
void evaluate_constants(const Program& program, const TypedProgram& typed, const SourceManager& sources,
                        const Limits& limits, ConstantValues& out, Diagnostics& diags);

// Text form: `const NAME = VALUE` for the constants of file `file` (all when 0), exact values as
// fractions, enclosures as [lo, hi].
std::string print_constants(const Program& program, const ConstantValues& values, std::uint32_t file = 0);

} // namespace frac::front
