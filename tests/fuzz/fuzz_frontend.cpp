// libFuzzer target: the whole frontend (lex, parse, resolve, inline size, type check, constants,
// lowering) on arbitrary bytes. Every input must give a model or located diagnostics: an internal error
// (a defect of Frac, exit 70 in the CLI), a crash or a hang is a finding.
#include "driver/pipeline.hpp"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        (void)frac::driver::compile_source("fuzz.frac", text);
    } catch (const frac::front::InternalError& e) {
        std::fprintf(stderr, "internal error: %s\n", e.what());
        std::abort();
    }
    return 0;
}
