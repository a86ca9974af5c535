// The JIT's on-disk cache of machine code: a tape compiled once is loaded, not compiled, by later
// processes. Keyed by a BLAKE3 hash of the generated module's bitcode before optimisation (which holds
// the tape, its tables, the rounding form and the vector width) and of everything else that decides the
// object: LLVM's version, the host's CPU and features, and this cache's format (bump it when the
// helpers' calling conventions or the pass pipeline change). One file per key,
//
//     "FRACOBJ1" | object size (8 bytes, little-endian) | BLAKE3 of the object (32 bytes) | object
//
// written atomically (support/atomic_file.hpp); a file that does not verify is removed and counts as a
// miss, so a truncated or corrupted entry is never linked. The cache is an optimisation: a directory
// that cannot be created or written leaves every compile to LLVM, silently. Its size is bounded: after
// a store, the entries least recently used are removed until the directory holds at most 3/4 of
// `max_bytes` (a hit refreshes its entry's modification time). Private to backend/llvm.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>

namespace llvm {
class MemoryBuffer;
} // namespace llvm

namespace frac::jit {

class CodeCache {
public:
    // `dir` is created on the first store; `target` names what the IR does not say (CPU, features).
    CodeCache(std::string dir, std::size_t max_bytes) : dir_(std::move(dir)), max_bytes_(max_bytes) {}

    // The key of a module: its bitcode and the target.
    static std::string key(std::string_view module_bitcode, std::string_view target);

    // The verified object of `key`, or null on a miss.
    std::unique_ptr<llvm::MemoryBuffer> load(const std::string& key) const;
    // Stores the object of `key` (failures are ignored: the cache is an optimisation).
    void store(const std::string& key, std::string_view object) const;

    // The path of the entry of `key` (for tests).
    std::string path(const std::string& key) const;

private:
    void evict() const;
    std::string dir_;
    std::size_t max_bytes_;
};

} // namespace frac::jit
