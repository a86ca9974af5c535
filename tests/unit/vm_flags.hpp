// The kernel's flags of a mapping (/proc/self/smaps), shared by the support and cli unit tests: huge
// pages asked for show as `hg` (hugetlbfs pages as `ht`).
#pragma once

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>

namespace frac::test {

// The VmFlags line of the mapping holding `address`, or "" when none does or smaps cannot be read.
inline std::string vm_flags_at(const void* address) {
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

} // namespace frac::test
