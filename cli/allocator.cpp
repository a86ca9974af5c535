#include "cli/allocator.hpp"

#if defined(FRAC_MIMALLOC)
#include <cstdlib>
#include <mimalloc.h>
#endif

namespace frac::cli {

#if defined(FRAC_MIMALLOC)
namespace {

void set_unless_in_environment(mi_option_t option, const char* variable, long value) {
    if (std::getenv(variable) == nullptr) mi_option_set(option, value);
}

} // namespace

// A large model's frontend and its pruned cover touch a few hundred megabytes of fresh heap. Where a
// page fault costs microseconds (virtual machines) and transparent huge pages come only on request
// (`madvise`, the default of many distributions), 4 KB faults were half the wall time of `frac render` on
// the 7000-clause model (docs/performance.md, "The allocator's heap on huge pages"). So: segments get
// huge pages (`madvise`; reserved hugetlbfs pages where the system has them), every thread's first
// segment too (no eager-commit delay), and freed memory stays committed: decommitting remaps it as
// fresh 4 KB pages, faulted in again one by one.
void tune_allocator() {
    set_unless_in_environment(mi_option_large_os_pages, "MIMALLOC_LARGE_OS_PAGES", 1);
    set_unless_in_environment(mi_option_eager_commit_delay, "MIMALLOC_EAGER_COMMIT_DELAY", 0);
    set_unless_in_environment(mi_option_allow_decommit, "MIMALLOC_ALLOW_DECOMMIT", 0);
}

std::string_view allocator_in_use() {
    return mi_option_is_enabled(mi_option_large_os_pages) ? "mimalloc, huge pages" : "mimalloc";
}
#else
void tune_allocator() {}

std::string_view allocator_in_use() {
    return "the C library's";
}
#endif

} // namespace frac::cli
