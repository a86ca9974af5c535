// Compiling a model from text in frontend tests: a model that must compile, or the diagnostics of one
// that must not.
#pragma once

#include "driver/pipeline.hpp"

#include <catch2/catch.hpp>
#include <memory>
#include <string>

namespace frac::test {

inline std::unique_ptr<front::Compilation> compile_ok(const std::string& text,
                                                      const driver::CompileOptions& options = {}) {
    auto c = driver::compile_source("t.frac", text, options);
    if (!c->ok()) FAIL(c->diags.render(c->sources));
    return c;
}

inline std::string errors_of(const std::string& text) {
    auto c = driver::compile_source("t.frac", text);
    return c->diags.render(c->sources);
}

} // namespace frac::test
