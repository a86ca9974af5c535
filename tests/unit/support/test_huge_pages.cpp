// Huge pages asked for on a large buffer: the kernel records the advice on the buffer's 2 MB-aligned
// interior (VmFlags "hg" in /proc/self/smaps); small, empty or null ranges are left alone.
#include "support/huge_pages.hpp"

#include <catch2/catch.hpp>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

// The VmFlags of the mapping holding `address`, or "" when smaps cannot be read.
std::string vm_flags_at(const void* address) {
    std::ifstream smaps("/proc/self/smaps");
    const auto a = reinterpret_cast<std::uintptr_t>(address);
    bool inside = false;
    for (std::string line; std::getline(smaps, line);) {
        std::uintptr_t lo = 0, hi = 0;
        char dash = 0;
        std::istringstream head(line);
        if (head >> std::hex >> lo >> dash >> hi && dash == '-') {
            inside = lo <= a && a < hi;
            continue;
        }
        if (inside && line.rfind("VmFlags:", 0) == 0) return line;
    }
    return "";
}

} // namespace

TEST_CASE("a large reserved buffer is advised to use huge pages", "[support]") {
    std::vector<double> v;
    frac::support::reserve_huge(v, std::size_t{8} << 20); // 64 MB
    REQUIRE(v.capacity() >= std::size_t{8} << 20);
    // Nothing to check where the kernel has no transparent huge pages, or no smaps.
    const bool thp = std::filesystem::exists("/sys/kernel/mm/transparent_hugepage/enabled");
    const std::string flags = vm_flags_at(v.data() + (std::size_t{4} << 20));
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
