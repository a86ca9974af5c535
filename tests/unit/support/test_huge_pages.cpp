// Huge pages asked for on a large buffer: the kernel records the advice on the buffer's 2 MB-aligned
// interior (VmFlags "hg" in /proc/self/smaps); small, empty or null ranges are left alone.
#include "support/huge_pages.hpp"
#include "tests/unit/vm_flags.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <string>
#include <vector>

TEST_CASE("a large reserved buffer is advised to use huge pages", "[support]") {
    std::vector<double> v;
    frac::support::reserve_huge(v, std::size_t{8} << 20); // 64 MB
    REQUIRE(v.capacity() >= std::size_t{8} << 20);
    // Nothing to check where the kernel has no transparent huge pages, or no smaps.
    const bool thp = std::filesystem::exists("/sys/kernel/mm/transparent_hugepage/enabled");
    const std::string flags = frac::test::vm_flags_at(v.data() + (std::size_t{4} << 20));
    if (thp && !flags.empty()) CHECK(flags.find(" hg") != std::string::npos);
    // Ranges too small for a huge page, and null, are ignored (no call, no failure).
    std::vector<double> small;
    frac::support::reserve_huge(small, 1000);
    frac::support::advise_huge_pages(nullptr, std::size_t{1} << 30);
    frac::support::advise_huge_pages(small.data(), 0);
    small.push_back(1);
    CHECK(small.back() == 1);
    v.push_back(2);
    CHECK(v.back() == 2);
}
