// frac compile: shapes -> an object file or a shared library with the C ABI of docs/c-abi.md. The code
// is generated (backend/llvm/aot.cpp) and linked with the run-time archive (aot_build.cpp) by the backend;
// this file checks the command line and the outputs, and writes the header.
#include "backend/llvm/aot.hpp"
#include "backend/llvm/jit.hpp"
#include "cli/commands.hpp"
#include "support/atomic_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <iostream>

namespace frac::cli {
namespace fs = std::filesystem;

namespace {

std::string header_guard(const std::string& header_path) {
    std::string g = "FRAC_MODEL_";
    for (char c : fs::path(header_path).filename().string())
        g += std::isalnum(static_cast<unsigned char>(c))
                 ? static_cast<char>(std::toupper(static_cast<unsigned char>(c)))
                 : '_';
    return g;
}

std::vector<jit::AotShape> chosen_shapes(const front::Compilation& c, const std::vector<std::string>& names) {
    std::vector<const front::ShapeInfo*> infos;
    if (names.empty()) {
        for (const front::ShapeInfo& s : c.module.shapes) infos.push_back(&s);
        if (infos.empty()) throw UsageError("the model defines no shape");
    } else {
        for (const std::string& n : names) {
            const front::ShapeInfo* s = &find_shape(c, n);
            if (std::find(infos.begin(), infos.end(), s) == infos.end()) infos.push_back(s);
        }
    }
    std::vector<jit::AotShape> shapes;
    for (const front::ShapeInfo* s : infos) {
        ir::Tape tape = ir::build_tape(c.module.graph, s->root, s->dimension);
        if (std::string defect = ir::verify_tape(tape); !defect.empty())
            throw front::InternalError("malformed tape: " + defect);
        shapes.push_back({s->name, std::move(tape), s->box});
    }
    return shapes;
}

} // namespace

std::string check_compile_output(const std::string& path) {
    if (ends_with(path, ".o") || ends_with(path, ".so") || ends_with(path, ".ll")) return "";
    return fmt::format(
        "cannot tell what to write to '{}': use .o (object), .so (shared library) or .ll (LLVM IR)", path);
}

int run_compile(const std::string& file, const CompileOptions& o) {
    if (std::string problem = check_compile_output(o.output); !problem.empty()) throw UsageError(problem);
    const bool ir_only = ends_with(o.output, ".ll");
    const std::string ir_path = ir_only       ? o.output
                                : o.emit_llvm ? fs::path(o.output).replace_extension(".ll").string()
                                              : std::string();
    // Every output is written atomically (support/atomic_file.hpp) and checked before any work: none may
    // be the model or another output.
    std::vector<std::string> taken;
    for (const std::string& path : {o.output, ir_only ? std::string() : ir_path, o.header}) {
        if (path.empty()) continue;
        check_output_writable(path, {file});
        for (const std::string& other : taken)
            if (support::same_file(path, other))
                throw UsageError(fmt::format("'{}' is the file of two outputs ('{}' too): give each its own",
                                             path, other));
        taken.push_back(path);
    }
    jit::AotConfig config;
    config.options.max_terms = o.max_terms;
    config.cpu = o.cpu;
    config.prefix = o.prefix;
    if (!jit::is_c_identifier(config.prefix + "x"))
        throw UsageError(fmt::format("--prefix '{}' cannot begin a C identifier", config.prefix));

    auto c = compile_or_report(file);
    if (!c) return front::exit_compile_error;
    const std::vector<jit::AotShape> shapes = chosen_shapes(*c, o.shapes);
    for (const jit::AotShape& s : shapes)
        driver::check_compile_size(s.tape.instruction_count(), compile_instruction_limit(),
                                   fmt::format("shape '{}'", s.name));
    for (const jit::AotShape& s : shapes)
        if (!jit::is_c_identifier(config.prefix + s.name))
            throw RunError(fmt::format("shape '{}' does not give C names ({}{}_eval_box)", s.name,
                                       config.prefix, s.name));

    jit::AotInfo info;
    try {
        info = ir_only ? jit::compile_aot(shapes, config, "", ir_path)
                       : jit::build_aot(shapes, config, o.output, ir_path);
    } catch (const std::invalid_argument& e) {
        throw RunError(e.what());
    } catch (const jit::JitError& e) {
        throw RunError(e.what());
    }
    if (!o.header.empty()) {
        try {
            support::write_file_atomically(o.header,
                                           jit::aot_header(shapes, config, info,
                                                           fs::path(file).filename().string(),
                                                           header_guard(o.header)),
                                           "header");
        } catch (const std::runtime_error& e) {
            throw RunError(e.what());
        }
    }

    std::string names;
    for (const jit::AotShape& s : shapes) names += (names.empty() ? "" : ", ") + s.name;
    std::cerr << fmt::format(
        "wrote {}{}{}: {} shape{} ({}); {} code for {}, {} rounding, {} lanes, at most {} "
        "series terms\n",
        o.output, ir_path.empty() || ir_only ? "" : ", " + ir_path, o.header.empty() ? "" : ", " + o.header,
        shapes.size(), shapes.size() == 1 ? "" : "s", names, info.cpu, info.triple, info.rounding, info.lanes,
        o.max_terms);
    return 0;
}

} // namespace frac::cli
