#include "backend/llvm/code_cache.hpp"

#include "support/atomic_file.hpp"

#include <llvm/ADT/StringExtras.h>
#include <llvm/Config/llvm-config.h>
#include <llvm/Support/BLAKE3.h>
#include <llvm/Support/MemoryBuffer.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <system_error>
#include <vector>

namespace frac::jit {
namespace {

namespace fs = std::filesystem;

constexpr char magic[8] = {'F', 'R', 'A', 'C', 'O', 'B', 'J', '1'};
constexpr std::size_t header_bytes = sizeof(magic) + 8 + 32;
// Bump when the object a module compiles to may change for the same IR: the helpers' calling
// conventions (helpers.cpp), the pass pipeline (pipeline.cpp), the code generation level (jit.cpp),
// the form of the key (2: the module's bitcode instead of its printed IR).
constexpr std::string_view cache_format = "frac-jit-cache-2";

llvm::BLAKE3Result<32> digest(std::string_view bytes) {
    llvm::BLAKE3 h;
    h.update(llvm::StringRef(bytes.data(), bytes.size()));
    return h.final();
}

} // namespace

std::string CodeCache::key(std::string_view module_bitcode, std::string_view target) {
    llvm::BLAKE3 h;
    // Each part with its length, so that no two different inputs hash the same bytes.
    for (std::string_view part :
         {cache_format, std::string_view(LLVM_VERSION_STRING), target, module_bitcode}) {
        const std::uint64_t n = part.size();
        h.update(llvm::ArrayRef<std::uint8_t>(reinterpret_cast<const std::uint8_t*>(&n), sizeof n));
        h.update(llvm::StringRef(part.data(), part.size()));
    }
    return llvm::toHex(h.final(), /*LowerCase=*/true);
}

std::string CodeCache::path(const std::string& key) const {
    return (fs::path(dir_) / (key + ".o")).string();
}

std::unique_ptr<llvm::MemoryBuffer> CodeCache::load(const std::string& key) const {
    const std::string file = path(key);
    std::ifstream in(file, std::ios::binary);
    if (!in) return nullptr;
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::uint64_t size = 0;
    if (bytes.size() >= header_bytes) std::memcpy(&size, bytes.data() + sizeof(magic), sizeof size);
    const std::string_view object =
        bytes.size() >= header_bytes ? std::string_view(bytes).substr(header_bytes) : std::string_view();
    const bool valid = bytes.size() >= header_bytes && std::memcmp(bytes.data(), magic, sizeof magic) == 0 &&
                       size == object.size() &&
                       std::memcmp(digest(object).data(), bytes.data() + sizeof(magic) + 8, 32) == 0;
    std::error_code ec;
    if (!valid) {
        fs::remove(file, ec); // truncated or corrupted: never linked, replaced by the next store
        return nullptr;
    }
    fs::last_write_time(file, fs::file_time_type::clock::now(), ec); // recently used
    return llvm::MemoryBuffer::getMemBufferCopy(llvm::StringRef(object.data(), object.size()), file);
}

void CodeCache::store(const std::string& key, std::string_view object) const {
    std::error_code ec;
    fs::create_directories(dir_, ec);
    if (ec) return;
    std::string bytes(magic, sizeof magic);
    const std::uint64_t size = object.size();
    bytes.append(reinterpret_cast<const char*>(&size), sizeof size);
    const auto d = digest(object);
    bytes.append(reinterpret_cast<const char*>(d.data()), d.size());
    bytes.append(object);
    try {
        support::write_file_atomically(path(key), bytes, "JIT cache entry");
    } catch (const std::exception&) {
        return; // a full disk or a read-only directory: compile next time
    }
    evict();
}

void CodeCache::evict() const {
    struct Entry {
        fs::path path;
        fs::file_time_type used;
        std::uintmax_t bytes;
    };
    std::vector<Entry> entries;
    std::uintmax_t total = 0;
    std::error_code ec;
    for (fs::directory_iterator it(dir_, ec), end; !ec && it != end; it.increment(ec)) {
        if (it->path().extension() != ".o" || !it->is_regular_file(ec)) continue;
        Entry e{it->path(), it->last_write_time(ec), it->file_size(ec)};
        if (ec) continue;
        total += e.bytes;
        entries.push_back(std::move(e));
    }
    if (total <= max_bytes_) return;
    std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.used < b.used; });
    for (const Entry& e : entries) {
        if (total <= max_bytes_ / 4 * 3) break;
        if (fs::remove(e.path, ec)) total -= e.bytes;
    }
}

} // namespace frac::jit
