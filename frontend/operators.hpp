// Operators of automata during lowering: matrices written entry by entry and the affine transforms of
// R2 and R3 (translate, rotate, scale, shear), composed right to left. An entry keeps its exact rational
// value when the constant folded exactly, so an operator written exactly stays exact (checks of
// barycentric columns and similarity ratios use it); every operator also has an outward enclosure.
#pragma once

#include "ir/automaton.hpp"

#include <optional>
#include <vector>

namespace frac::front {

// A constant entry: its exact value when known, and its enclosure.
struct Entry {
    std::optional<num::Rational> exact;
    num::Interval enclosure;
    static Entry of(int v) { return {num::Rational(v), num::Interval(v)}; }
};

// A matrix, or a transform of R^d in homogeneous coordinates. A transform whose dimension no operand
// fixed (scale(1/2), identity) is kept for R2 and for R3 until one does.
struct LinearValue {
    bool transform = false;
    int dimension = 0;                  // a transform's: 2, 3, or 0 while either
    std::optional<ir::Operator> r2, r3; // a transform's matrices; a matrix's is r2
    // The matrix: a transform's in R^d (d = 2, 3), or the matrix itself.
    const ir::Operator& in(int d) const;
    static LinearValue matrix(ir::Operator m);
};

ir::Operator operator_of(const std::vector<std::vector<Entry>>& rows);
ir::Operator compose(const ir::Operator& a, const ir::Operator& b);
ir::Operator scale_by(const Entry& s, const ir::Operator& a);
ir::Operator add(const ir::Operator& a, const ir::Operator& b, bool subtract);
// The Kronecker product: entry (r1 * rows(b) + r2, c1 * cols(b) + c2) is a(r1, c1) * b(r2, c2).
ir::Operator kronecker(const ir::Operator& a, const ir::Operator& b);

// a * b under the typing rule of types.cpp (compose_rule), which the type checker applied.
LinearValue compose(const LinearValue& a, const LinearValue& b);

// translate(v...) (2 or 3 entries), scale(s) or scale(sx, sy[, sz]), rotate by an angle whose cosine
// and sine are given (R2), shear(kx, ky) (R2), identity.
LinearValue translate(const std::vector<Entry>& v);
LinearValue scale(const std::vector<Entry>& s);
LinearValue rotate(const Entry& cosine, const Entry& sine);
LinearValue shear(const Entry& kx, const Entry& ky);
LinearValue identity();
// controls(P0, ..., Pn-1): the (d + 1) × n matrix of the points (columns) with 1 appended.
ir::Operator controls(const std::vector<std::vector<Entry>>& points);

} // namespace frac::front
