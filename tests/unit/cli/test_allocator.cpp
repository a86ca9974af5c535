// The frac command's allocator (cli/allocator.cpp): tuned, a fresh thread's large allocations lie in
// memory advised for huge pages.
#include "cli/allocator.hpp"
#include "tests/unit/vm_flags.hpp"

#include <catch2/catch.hpp>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>

TEST_CASE("the tuned allocator gives a fresh thread huge-page memory") {
#if defined(FRAC_MIMALLOC)
    // The kernel's advice flag: `hg` (MADV_HUGEPAGE) or `ht` (hugetlbfs pages, where the system reserves
    // them); a kernel without transparent huge pages cannot take the advice.
    const bool kernel_has_thp = std::filesystem::exists("/sys/kernel/mm/transparent_hugepage");
    const auto huge_advised = [](const std::string& flags) {
        return flags.find(" hg") != std::string::npos || flags.find(" ht") != std::string::npos;
    };
    const auto flags_of_fresh_block = [&] {
        std::string flags;
        std::thread([&] {
            constexpr std::size_t bytes = std::size_t{64} << 20;
            std::unique_ptr<char[]> block(new char[bytes]);
            std::memset(block.get(), 1, bytes);
            flags = frac::test::vm_flags_at(block.get() + bytes / 2);
        }).join();
        return flags;
    };

    // mimalloc reads its environment once, at the process's start: a user's setting there stays.
    if (const char* users = std::getenv("MIMALLOC_LARGE_OS_PAGES")) {
        frac::cli::tune_allocator();
        CHECK(frac::cli::allocator_in_use() == (std::atoi(users) != 0 ? "mimalloc, huge pages" : "mimalloc"));
        return;
    }
    frac::cli::tune_allocator();
    CHECK(frac::cli::allocator_in_use() == "mimalloc, huge pages");
    const std::string flags = flags_of_fresh_block();
    INFO(flags);
    REQUIRE(!flags.empty());
    if (kernel_has_thp) CHECK(huge_advised(flags));
#else
    frac::cli::tune_allocator();
    CHECK(frac::cli::allocator_in_use() == "the C library's");
#endif
}
