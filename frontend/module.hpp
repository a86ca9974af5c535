// What the frontend produces from a model: the expression graph and, over it, the shapes, tests and
// print statements of the model.
#pragma once

#include "frontend/diagnostics.hpp"
#include "ir/automaton.hpp"
#include "ir/graph.hpp"

#include <string>
#include <vector>

namespace frac::front {

using ir::Interval;
using ir::NodeId;

struct ShapeInfo {
    std::string name;
    Location loc;
    int dimension = 2;
    std::vector<Interval> box; // default view box, one interval per axis
    NodeId root = ir::no_node; // reads Var(k) = coordinate k
};

// An ifs or cifs: its automaton IR and where its parts are written.
struct AutomatonInfo {
    std::string name;
    Location loc;
    ir::Automaton automaton;
    std::vector<Location> state_locs, arc_locs; // by state and arc index
    std::string contraction;                    // how the compiler proved that the system contracts
    // A bcifs: the solution of its constraints as `frac solve` prints it (with the values its free
    // entries took), and the degrees of freedom by state.
    std::string solution;
    std::vector<int> dof;
    // A fif: its interpolation points (t, x[, y]), nearest doubles.
    std::vector<std::vector<double>> fif_points;
};

// A run-time question a test asks of a shape or an automaton; its answer is the input Var(index) of
// test graphs.
struct Query {
    enum class Kind { enclose, dimension, automaton_dimension, automaton_point } kind = Kind::enclose;
    Location loc;
    std::size_t shape = 0;            // index into Module::shapes (Module::automata for automaton_dimension)
    std::vector<Interval> box;        // enclose: the box; dimension: the root box
    int from = 0, to = 0, split = 2;  // dimension: levels used for box counting
    std::vector<std::size_t> address; // automaton_point: the arcs taken (base-N digits of t = i / N^p)
    int component = 0;                // automaton_point: the coordinate of F(t) asked for
};

// What an Op::External node of the graph computes; its index in Module::externals is the node's imm.
// The frontend leaves Graph::externals null: the driver binds an implementation to each (the runtime's
// distance to an attractor, driver/external_functions.hpp).
struct ExternalUse {
    enum class Kind { distance } kind = Kind::distance;
    Location loc;                                         // the first call
    std::size_t automaton = static_cast<std::size_t>(-1); // distance: index into Module::automata
    std::string automaton_name;                           // distance: for messages
};

enum class ValueKind { scalar, boolean, point, interval, box };

struct Expectation {
    Location loc;
    std::string source;         // the expression's source line, for messages
    NodeId truth = ir::no_node; // boolean: must evaluate to proven true
    std::vector<NodeId> shown;  // values printed when it fails
};

struct TestInfo {
    std::string name;
    Location loc;
    std::vector<Expectation> expects;
};

struct PrintInfo {
    Location loc;
    ValueKind kind = ValueKind::scalar;
    std::vector<NodeId> nodes; // scalar/boolean: 1; point: its components
    std::vector<Interval> box; // interval/box values
};

struct Module {
    ir::Graph graph;
    std::vector<ShapeInfo> shapes;
    std::vector<AutomatonInfo> automata;
    std::vector<Query> queries;
    std::vector<TestInfo> tests;
    std::vector<PrintInfo> prints;
    std::vector<ExternalUse> externals;

    const ShapeInfo* find_shape(const std::string& name) const {
        for (const ShapeInfo& s : shapes)
            if (s.name == name) return &s;
        return nullptr;
    }
    const AutomatonInfo* find_automaton(const std::string& name) const {
        for (const AutomatonInfo& a : automata)
            if (a.name == name) return &a;
        return nullptr;
    }
};

} // namespace frac::front
