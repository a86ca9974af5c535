// Properties of the generated code that make its rounding safe, and the JIT's API.
#include "engines.hpp"

#include <functional>
#include <regex>
#include <sstream>

using namespace frac;
using namespace frac::test;

namespace {

// The text of one function of the printed module.
std::string function_text(const std::string& module, const std::string& suffix) {
    const std::size_t at = module.find(suffix + "(ptr");
    REQUIRE(at != std::string::npos);
    const std::size_t start = module.rfind("define", at);
    const std::size_t end = module.find("\n}\n", at);
    return module.substr(start, end - start);
}

} // namespace

TEST_CASE("the JIT is available on this machine", "[llvm][api]") {
    std::string why;
    CHECK(jit::jit_available(&why));
    INFO(why);
    CHECK(why.empty());
}

namespace {

std::size_t count_lines(const std::string& text, const std::function<bool(const std::string&)>& pred) {
    std::size_t n = 0;
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);) n += pred(line);
    return n;
}

bool has(const std::string& line, const char* what) {
    return line.find(what) != std::string::npos;
}

} // namespace

TEST_CASE("interval code rounds upward in every operation, never fast-math", "[llvm][codegen]") {
    using R = jit::JitConfig::Rounding;
    const Model m =
        compile("import \"fractals\"; shape g(x, y) = x / y + sqrt(x) * sin(y) - x^3 + mod(x, 1);");
    std::vector<jit::JitConfig> configs = {jit::codegen_config(R::constrained, 1),
                                           jit::codegen_config(R::constrained, 4)};
    if (jit::host_has_avx512())
        configs.insert(configs.end(), {jit::codegen_config(R::avx512, 1), jit::codegen_config(R::avx512, 8)});
    // (Integer-to-double conversions of series indices below 2^53 are exact: allowed as plain IR in the
    // AVX-512 form, where the optimiser may turn sitofp into uitofp.)
    const std::regex plain(R"(= (fadd|fsub|fmul|fdiv|frem|fptrunc|fpext) )");
    for (const jit::JitConfig& config : configs) {
        for (std::size_t i = 0; i < m.tapes.size(); ++i) {
            INFO(m.shape(i).name << ", " << (config.rounding == R::avx512 ? "avx512" : "constrained") << " x"
                                 << config.lanes);
            for (bool optimized : {false, true}) {
                const std::string ir = jit::emit_llvm(m.tapes[i], {}, optimized, config);
                // The box code: the body that <name>_box and <name>_cells call.
                const std::string box = function_text(ir, "_box.body");
                // No fast-math flag anywhere in the module.
                for (const char* flag :
                     {" fast ", " nnan ", " ninf ", " nsz ", " arcp ", " contract ", " afn ", " reassoc "})
                    CHECK(ir.find(flag) == std::string::npos);
                // No rounding arithmetic that is not explicitly upward.
                CHECK_FALSE(std::regex_search(box, plain));
                const auto is_strictfp = [&](const std::string& function) {
                    std::smatch group;
                    REQUIRE(std::regex_search(function, group, std::regex(R"(^define[^\n]*(#[0-9]+) \{)")));
                    const std::size_t attrs = ir.find("attributes " + group[1].str() + " = {");
                    REQUIRE(attrs != std::string::npos);
                    return ir.substr(attrs, ir.find('}', attrs) - attrs).find("strictfp") !=
                           std::string::npos;
                };
                const bool strictfp = is_strictfp(box);
                // The two entry points into the body are strictfp where it is.
                for (const char* entry : {"_box", "_cells"})
                    CHECK(is_strictfp(function_text(ir, entry)) == strictfp);
                if (config.rounding == R::constrained) {
                    // strictfp, and every constrained operation says round.upward.
                    CHECK(strictfp);
                    // (fptosi converts integral doubles: exact, no rounding argument.)
                    const auto ops = count_lines(box, [](const std::string& l) {
                        return has(l, "call") && has(l, "@llvm.experimental.constrained.") &&
                               !has(l, ".fcmp") && !has(l, ".floor") && !has(l, ".ceil") &&
                               !has(l, ".roundeven") && !has(l, ".fptosi");
                    });
                    const auto upward = count_lines(box, [](const std::string& l) {
                        return has(l, "call") && has(l, "@llvm.experimental.constrained.") &&
                               has(l, "!\"round.upward\"");
                    });
                    CHECK(ops > 0);
                    CHECK(upward == ops);
                    CHECK(box.find("round.downward") == std::string::npos);
                    CHECK(box.find("round.tonearest") == std::string::npos);
                    CHECK(box.find("round.dynamic") == std::string::npos);
                    CHECK(box.find("= sitofp") == std::string::npos);
                    CHECK(box.find("= uitofp") == std::string::npos);
                } else {
                    // Every arithmetic instruction carries a directed rounding: {ru-sae} (rounding
                    // argument 10) for upper bounds, {rd-sae} (9) for lower ones; nothing depends on
                    // MXCSR inside the function.
                    CHECK_FALSE(strictfp);
                    CHECK(box.find("constrained") == std::string::npos);
                    const auto ops = count_lines(box, [](const std::string& l) {
                        return has(l, "call") && has(l, "@llvm.x86.avx512.");
                    });
                    const auto upward = count_lines(box, [](const std::string& l) {
                        return has(l, "call") && has(l, "@llvm.x86.avx512.") &&
                               (has(l, "i32 10)") || has(l, "i32 9)"));
                    });
                    CHECK(ops > 0);
                    CHECK(upward == ops);
                }
            }
        }
        // The point function is plain IEEE code in the default environment.
        const std::string point = function_text(jit::emit_llvm(m.tapes[0], {}, true, config), "_point");
        CHECK(point.find("constrained") == std::string::npos);
        CHECK(point.find("avx512") == std::string::npos);
    }
}

TEST_CASE("lower bounds are not folded into upper-rounded operations", "[llvm][codegen]") {
    // x + y over thin inexact operands: an optimiser that turned -((-a) - b) into a + b would give a
    // thin (wrong) enclosure.
    const Model m = compile("shape s(x, y) = x + y - x * y + x / y;");
    auto e = jit::make_jit(m.tapes[0]);
    BoxMaker mk(1);
    for (int n = 0; n < 2000; ++n) {
        const Interval b[2] = {Interval(mk.uniform(0.1, 10)), Interval(mk.uniform(0.1, 10))};
        const Interval r = e->eval_box(b);
        const double nearest = b[0].lo + b[1].lo - b[0].lo * b[1].lo + b[0].lo / b[1].lo;
        CHECK(r.lo <= nearest);
        CHECK(nearest <= r.hi);
        CHECK(r.lo < r.hi);
    }
}

TEST_CASE("compile information is recorded", "[llvm][api]") {
    const Model m = compile("import \"fractals\";");
    auto e = jit::make_jit(m.tapes[0]);
    const jit::CompileInfo* info = jit::compile_info(*e);
    REQUIRE(info);
    CHECK(info->total_ms > 0);
    CHECK(info->ir_instructions > 10);
    CHECK(info->total_ms >= info->codegen_ms + info->optimize_ms + info->machine_ms);
    auto c = e->clone();
    CHECK(jit::compile_info(*c) == info);
    auto in = interp::make_interpreter(m.tapes[0]);
    CHECK(jit::compile_info(*in) == nullptr);
}

TEST_CASE("many compiled shapes come and go", "[llvm][api]") {
    const Model m = compile("shape s(x, y) = x * y - 1;");
    for (int n = 0; n < 200; ++n) {
        auto e = jit::make_jit(m.tapes[0]);
        const double p[2] = {2.0, 3.0};
        REQUIRE(e->eval_point(p) == 5.0);
    }
}
