// The opcode table's queries (ir/opcodes.def). Apart from the graph so that compiled models' run-time
// archive, which needs the opcodes but not the graph, stays free of GMP.
#include "ir/graph.hpp"

namespace frac::ir {

namespace {

struct OpInfo {
    int arity;
    const char* name;
    OpClass cls;
};

constexpr OpInfo op_table[] = {
#define FRAC_OP(name, arity, text, cls) {arity, text, OpClass::cls},
#include "ir/opcodes.def"
#undef FRAC_OP
};

} // namespace

int arity(Op op) {
    return op_table[static_cast<int>(op)].arity;
}
const char* op_name(Op op) {
    return op_table[static_cast<int>(op)].name;
}
OpClass op_class(Op op) {
    return op_table[static_cast<int>(op)].cls;
}

} // namespace frac::ir
