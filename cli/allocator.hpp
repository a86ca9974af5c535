// The allocator of the `frac` command (docs/design.md, "The end of a command").
#pragma once

#include <string_view>

namespace frac::cli {

// Tunes the allocator the command is linked with (mimalloc where it was found at configure time) before
// any work starts: its heap on huge pages, committed once and kept. A setting the user gives in the
// environment (MIMALLOC_LARGE_OS_PAGES, ...) wins. Nothing to do with the C library's allocator.
void tune_allocator();

// The allocator, in words, for benchmarks' reports: "mimalloc, huge pages" or "the C library's".
std::string_view allocator_in_use();

} // namespace frac::cli
