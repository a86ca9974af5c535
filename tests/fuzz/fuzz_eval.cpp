// libFuzzer target: the evaluators' enclosures. The input chooses an expression of x and y (the
// language's operators and functions) and a box; the interpreter and the JIT evaluate it over the box
// and at points of the box. The true value at a point lies in the enclosure over the point and in the
// enclosure over the box, so the two must meet (Halide's bounds fuzzer checks the same inclusion).
#include "driver/engines.hpp"
#include "driver/pipeline.hpp"

#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

namespace {

using frac::ir::Interval;

std::string number(FuzzedDataProvider& in) {
    static const char* const numbers[] = {"0", "1", "2", "0.5", "3", "1/3", "1e-3", "1e3", "pi", "-1", "0.1"};
    return numbers[in.ConsumeIntegralInRange<std::size_t>(0, std::size(numbers) - 1)];
}

std::string expression(FuzzedDataProvider& in, int depth) {
    if (depth == 0 || in.remaining_bytes() == 0 || in.ConsumeIntegralInRange(0, 3) == 0) {
        switch (in.ConsumeIntegralInRange(0, 2)) {
        case 0: return "x";
        case 1: return "y";
        default: return number(in);
        }
    }
    static const char* const binary[] = {"+", "-", "*", "/", "^"};
    static const char* const unary[] = {"sqrt", "abs",  "sin",  "cos",   "exp",
                                        "log",  "atan", "tanh", "floor", "dz"};
    static const char* const pair[] = {"min", "max", "atan2"};
    const auto sub = [&] { return expression(in, depth - 1); };
    switch (in.ConsumeIntegralInRange(0, 4)) {
    case 0: {
        const std::string a = sub();
        const char* op = binary[in.ConsumeIntegralInRange<std::size_t>(0, std::size(binary) - 1)];
        // Powers with small integer exponents: a real power of a negative base is undefined anyway.
        const std::string b = op[0] == '^' ? std::to_string(in.ConsumeIntegralInRange(-3, 4)) : sub();
        return "(" + a + " " + op + " (" + b + "))";
    }
    case 1:
        return std::string(unary[in.ConsumeIntegralInRange<std::size_t>(0, std::size(unary) - 1)]) + "(" +
               sub() + ")";
    case 2: {
        const char* f = pair[in.ConsumeIntegralInRange<std::size_t>(0, std::size(pair) - 1)];
        const std::string a = sub();
        return std::string(f) + "(" + a + ", " + sub() + ")";
    }
    case 3: {
        const std::string c = sub();
        const std::string a = sub();
        return "(if " + c + " < 0 then " + a + " else " + sub() + ")";
    }
    default: return "(-" + sub() + ")";
    }
}

double coordinate(FuzzedDataProvider& in) {
    return static_cast<double>(in.ConsumeIntegralInRange(-4000, 4000)) / 1000.0;
}

bool meet(Interval a, Interval b) {
    return !a.is_empty() && !b.is_empty() && a.lo <= b.hi && b.lo <= a.hi;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    FuzzedDataProvider in(data, size);
    const std::string body = expression(in, 5);
    std::array<Interval, 2> box;
    for (Interval& axis : box) {
        const double a = coordinate(in), b = coordinate(in);
        axis = {std::min(a, b), std::max(a, b)};
    }
    auto c = frac::driver::compile_source("fuzz.frac", "shape s(x, y) = " + body + ";\n");
    if (!c->ok() || c->module.shapes.size() != 1) return 0; // refused (a constant error, say): no finding
    const frac::front::ShapeInfo& s = c->module.shapes[0];
    for (const char* engine : {"interp", "jit"}) {
        frac::driver::EngineOptions options;
        options.engine = engine;
        auto eval = frac::driver::make_evaluator(c->module, s.root, 2, options);
        const Interval whole = eval->eval_box(box.data());
        for (int k = 0; k < 5; ++k) {
            std::array<double, 2> p;
            // The corners, then points chosen by the input (clamped: lo + (hi - lo) * t may round past hi).
            for (std::size_t a = 0; a < 2; ++a)
                p[a] = k < 4
                           ? ((k >> a) & 1 ? box[a].hi : box[a].lo)
                           : std::clamp(box[a].lo + (box[a].hi - box[a].lo) * in.ConsumeProbability<double>(),
                                        box[a].lo, box[a].hi);
            std::array<Interval, 2> point{Interval{p[0], p[0]}, Interval{p[1], p[1]}};
            const Interval at = eval->eval_box(point.data());
            if (!at.is_empty() && !meet(at, whole)) {
                std::fprintf(
                    stderr,
                    "unsound (%s): s(x, y) = %s\nbox [%.17g, %.17g] x [%.17g, %.17g] gives [%.17g, %.17g]"
                    "\npoint (%.17g, %.17g) gives [%.17g, %.17g]\n",
                    engine, body.c_str(), box[0].lo, box[0].hi, box[1].lo, box[1].hi, whole.lo, whole.hi,
                    p[0], p[1], at.lo, at.hi);
                std::abort();
            }
        }
    }
    return 0;
}
