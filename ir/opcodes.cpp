// The opcodes' names (ir/opcodes.def; arity and class are inline in ir/graph.hpp). Apart from the
// graph so that compiled models' run-time archive, which needs the opcodes but not the graph, stays
// free of GMP.
#include "ir/graph.hpp"

namespace frac::ir {

namespace {

constexpr const char* op_names[] = {
#define FRAC_OP(name, arity, text, cls) text,
#include "ir/opcodes.def"
#undef FRAC_OP
};

} // namespace

const char* op_name(Op op) {
    return op_names[static_cast<int>(op)];
}

} // namespace frac::ir
