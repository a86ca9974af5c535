// Output files written in full or not at all. The bytes go to an unnamed file in the target's directory
// (O_TMPFILE; a hidden temporary where the file system lacks it) that commit() names and renames over the
// target: a run that fails, is killed or fills the disk leaves the previous file as it was and no partial
// one. A named temporary is handed to the process's cleaner (support/process_cleaner.hpp) before it exists,
// so that a kill at any moment leaves nothing beside the target once the process is gone.
// A target that exists and is neither a regular file nor a directory (a device such as /dev/null, a FIFO,
// a terminal, /dev/stdout) is written straight through instead: renaming over it would replace it.
// Used by every writer of user-visible outputs (pictures, meshes, compiled models, headers).
#pragma once

#include <cstdio>
#include <string>
#include <string_view>

namespace frac::support {

class AtomicFile {
public:
    // Opens the temporary; `what` names the output in errors ("PNG", "mesh"). Throws std::runtime_error
    // "cannot write WHAT 'PATH': REASON".
    AtomicFile(std::string path, std::string what);
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;
    ~AtomicFile(); // not committed: the temporary goes, the target is untouched

    void write(const void* data, std::size_t size);
    void write(std::string_view text) { write(text.data(), text.size()); }
    // A stdio stream on the temporary, for writers that take one (libpng); owned by this object.
    std::FILE* stream();
    // The descriptor, for writers that take one (LLVM's raw_fd_ostream); not to be closed.
    int descriptor() const { return fd_; }
    // Flushes, closes and renames the temporary over the target (keeping the old file's permissions).
    void commit();
    // The error thrown for this output, with `reason`.
    [[noreturn]] void fail(const std::string& reason) const;

private:
    void discard() noexcept;
    std::string path_, what_;
    std::string named_temp_; // the temporary's name when it has one (no O_TMPFILE)
    bool direct_ = false;    // writing to the target itself (not a regular file)
    int fd_ = -1;
    std::FILE* stream_ = nullptr;
};

// The whole of `bytes` as the file `path`, atomically.
void write_file_atomically(const std::string& path, std::string_view bytes, const std::string& what);
// A copy of the file `from` as the file `path`, atomically (`from` may be on another file system).
void copy_file_atomically(const std::string& from, const std::string& path, const std::string& what);

// Checks, before any work, that `path` can be written: its directory exists and takes new files, and
// it is not a directory. Returns the reason it cannot, or "" when it can. Creates nothing.
std::string output_problem(const std::string& path);

// Whether `a` and `b` name one file: the same existing file (through links too), or the same path once
// made absolute and normal when either does not exist yet.
bool same_file(const std::string& a, const std::string& b);

// Removes the temporaries that runs killed before they could (those of processes no longer alive)
// beside `path`. AtomicFile calls it; exposed for tests.
void remove_stale_temporaries(const std::string& path);

} // namespace frac::support
