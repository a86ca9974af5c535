// Lowering of a type-checked program to the expression graph, with functions, shapes and lets inlined,
// constants folded (exactly where they are rational) and every infinite series bounded
// (series_bounds). Type errors were reported by the type checker (typecheck.hpp); what is left here
// needs values: constant bounds and indices, series tails, escape certificates.
#pragma once

#include "frontend/ast.hpp"
#include "frontend/limits.hpp"
#include "frontend/module.hpp"

#include <cstdint>
#include <optional>

namespace frac::front {

struct TypedProgram;

struct ConstantValues;

// `constants`: the values of the constant stage (consteval.hpp), used instead of lowering the
// definitions of constants again; null: constants are lowered where they are used.
// `free_entry_seed`: the free entries of every bcifs take values drawn from this seed (reproducible)
// instead of the most uniform ones (--seed).
void lower(const Program& program, const TypedProgram& typed, const SourceManager& sources,
           const Limits& limits, Module& out, Diagnostics& diags, const ConstantValues* constants = nullptr,
           std::optional<std::uint64_t> free_entry_seed = std::nullopt);

// A map of the plane or space for dynamical systems (fn henon(p) = (...)): the graph nodes of its
// components applied to the point (Var(0), ..., Var(dimension - 1)), added to out.graph. Throws
// CompileError when `map` is no fn of one point returning a point of `dimension` coordinates.
std::vector<NodeId> lower_point_map(const Program& program, const TypedProgram& typed,
                                    const SourceManager& sources, const Limits& limits, Module& out,
                                    const Item& map, int dimension);

} // namespace frac::front
