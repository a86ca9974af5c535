#include "support/atomic_file.hpp"
#include "support/process_cleaner.hpp"

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <dirent.h>
#include <fcntl.h>
#include <filesystem>
#include <stdexcept>
#include <sys/stat.h>
#include <unistd.h>

namespace frac::support {
namespace fs = std::filesystem;

namespace {

// Temporaries are ".NAME.frac-tmp.PID.N": the pid tells a later run whether their writer is gone.
std::string temp_prefix(const fs::path& target) {
    return "." + target.filename().string() + ".frac-tmp.";
}

std::string next_temp_name(const fs::path& target) {
    static std::atomic<unsigned> counter{0};
    return (target.parent_path() /
            (temp_prefix(target) + std::to_string(getpid()) + "." + std::to_string(counter++)))
        .string();
}

fs::path directory_of(const fs::path& target) {
    return target.parent_path().empty() ? fs::path(".") : target.parent_path();
}

// Whether `path` exists as something other than a regular file or a directory (following links).
bool is_special(const std::string& path) {
    struct stat st {};
    return ::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode);
}

// A symbolic link is written through, as opening it for writing would.
std::string resolved(const std::string& path) {
    std::error_code ec;
    if (!fs::is_symlink(path, ec)) return path;
    const fs::path target = fs::weakly_canonical(path, ec);
    return ec ? path : target.string();
}

} // namespace

AtomicFile::AtomicFile(std::string path, std::string what) : what_(std::move(what)) {
    if (is_special(path)) {
        path_ = std::move(path);
        direct_ = true;
        fd_ = ::open(path_.c_str(), O_WRONLY | O_CLOEXEC);
        if (fd_ < 0) fail(std::strerror(errno));
        return;
    }
    path_ = resolved(path);
    remove_stale_temporaries(path_);
    const fs::path target(path_);
    if (target.filename().empty()) fail("not a file name");
    fd_ = ::open(directory_of(target).c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666);
    if (fd_ < 0 && (errno == EOPNOTSUPP || errno == EISDIR || errno == EINVAL)) {
        // No unnamed files here: a named temporary, removed on failure or by the next run.
        for (int attempt = 0; attempt < 100 && fd_ < 0; ++attempt) {
            named_temp_ = next_temp_name(target);
            remove_when_process_ends(named_temp_);
            fd_ = ::open(named_temp_.c_str(), O_CREAT | O_EXCL | O_WRONLY | O_CLOEXEC, 0666);
            if (fd_ < 0 && errno != EEXIST) break;
        }
        if (fd_ < 0) named_temp_.clear();
    }
    if (fd_ < 0) fail(std::strerror(errno));
    struct stat old {};
    if (::stat(path_.c_str(), &old) == 0 && S_ISREG(old.st_mode)) (void)::fchmod(fd_, old.st_mode & 07777);
}

AtomicFile::~AtomicFile() {
    discard();
}

void AtomicFile::discard() noexcept {
    if (stream_)
        std::fclose(stream_); // closes fd_
    else if (fd_ >= 0)
        ::close(fd_);
    stream_ = nullptr;
    fd_ = -1;
    if (!named_temp_.empty()) ::unlink(named_temp_.c_str());
    named_temp_.clear();
}

void AtomicFile::fail(const std::string& reason) const {
    throw std::runtime_error("cannot write " + (what_.empty() ? "" : what_ + " ") + "'" + path_ +
                             "': " + reason);
}

void AtomicFile::write(const void* data, std::size_t size) {
    if (fd_ < 0) fail("already closed");
    if (stream_) {
        if (std::fwrite(data, 1, size, stream_) != size) fail(std::strerror(errno));
        return;
    }
    const auto* p = static_cast<const char*>(data);
    while (size > 0) {
        const ssize_t n = ::write(fd_, p, size);
        if (n < 0) {
            if (errno == EINTR) continue;
            fail(std::strerror(errno));
        }
        p += n;
        size -= static_cast<std::size_t>(n);
    }
}

std::FILE* AtomicFile::stream() {
    if (fd_ < 0) fail("already closed");
    if (!stream_) {
        stream_ = ::fdopen(fd_, "wb");
        if (!stream_) fail(std::strerror(errno));
    }
    return stream_;
}

void AtomicFile::commit() {
    if (fd_ < 0) fail("already closed");
    if (stream_ && (std::fflush(stream_) != 0 || std::ferror(stream_))) fail(std::strerror(errno));
    if (direct_) {
        const int closed = stream_ ? std::fclose(stream_) : ::close(fd_);
        const int close_errno = errno;
        stream_ = nullptr;
        fd_ = -1;
        if (closed != 0) fail(std::strerror(close_errno));
        return;
    }
    if (named_temp_.empty()) {
        // Give the unnamed file a name beside the target (linkat through /proc needs no privilege), then
        // rename it over the target: the name exists for the span of two system calls.
        const std::string proc = "/proc/self/fd/" + std::to_string(fd_);
        for (int attempt = 0; attempt < 100 && named_temp_.empty(); ++attempt) {
            const std::string name = next_temp_name(path_);
            // The name exists until the rename below; a kill in between leaves it to the cleaner.
            remove_when_process_ends(name);
            if (::linkat(AT_FDCWD, proc.c_str(), AT_FDCWD, name.c_str(), AT_SYMLINK_FOLLOW) == 0)
                named_temp_ = name;
            else if (errno != EEXIST)
                fail(std::strerror(errno));
        }
        if (named_temp_.empty()) fail("no free temporary name");
    }
    const int closed = stream_ ? std::fclose(stream_) : ::close(fd_);
    const int close_errno = errno;
    stream_ = nullptr;
    fd_ = -1;
    if (closed != 0) {
        discard();
        fail(std::strerror(close_errno));
    }
    if (std::rename(named_temp_.c_str(), path_.c_str()) != 0) {
        const std::string why = std::strerror(errno);
        discard();
        fail(why);
    }
    named_temp_.clear();
}

void write_file_atomically(const std::string& path, std::string_view bytes, const std::string& what) {
    AtomicFile out(path, what);
    out.write(bytes);
    out.commit();
}

void copy_file_atomically(const std::string& from, const std::string& path, const std::string& what) {
    const int in = ::open(from.c_str(), O_RDONLY | O_CLOEXEC);
    if (in < 0) throw std::runtime_error("cannot read '" + from + "': " + std::strerror(errno));
    try {
        struct stat source {
        }, old{};
        const bool replacing = ::stat(path.c_str(), &old) == 0;
        AtomicFile out(path, what);
        // A new file takes the source's permissions (a linker's executable bits), an old one keeps its own.
        if (!replacing && ::fstat(in, &source) == 0) (void)::fchmod(out.descriptor(), source.st_mode & 0777);
        char buffer[1 << 16];
        for (;;) {
            const ssize_t n = ::read(in, buffer, sizeof buffer);
            if (n < 0 && errno == EINTR) continue;
            if (n < 0) out.fail(std::string("reading '") + from + "': " + std::strerror(errno));
            if (n == 0) break;
            out.write(buffer, static_cast<std::size_t>(n));
        }
        out.commit();
    } catch (...) {
        ::close(in);
        throw;
    }
    ::close(in);
}

std::string output_problem(const std::string& path) {
    if (is_special(path)) return ::access(path.c_str(), W_OK) == 0 ? "" : std::strerror(errno);
    const fs::path target(resolved(path));
    if (target.filename().empty()) return "not a file name";
    std::error_code ec;
    if (fs::is_directory(target, ec)) return "it is a directory";
    const fs::path dir = directory_of(target);
    if (!fs::is_directory(dir, ec)) return "no directory '" + dir.string() + "'";
    // A real probe: an unnamed file (gone when closed), else a named one removed at once.
    int fd = ::open(dir.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666);
    if (fd < 0 && (errno == EOPNOTSUPP || errno == EISDIR || errno == EINVAL)) {
        const std::string probe = next_temp_name(target);
        fd = ::open(probe.c_str(), O_CREAT | O_EXCL | O_WRONLY | O_CLOEXEC, 0666);
        if (fd >= 0) ::unlink(probe.c_str());
    }
    if (fd < 0) return std::strerror(errno);
    ::close(fd);
    return "";
}

bool same_file(const std::string& a, const std::string& b) {
    std::error_code ec;
    if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
    const fs::path pa = fs::weakly_canonical(fs::absolute(a, ec), ec),
                   pb = fs::weakly_canonical(fs::absolute(b, ec), ec);
    return pa == pb;
}

void remove_stale_temporaries(const std::string& path) {
    const fs::path target(path);
    const std::string prefix = temp_prefix(target);
    DIR* dir = ::opendir(directory_of(target).c_str());
    if (!dir) return;
    while (const dirent* e = ::readdir(dir)) {
        const std::string name = e->d_name;
        if (name.compare(0, prefix.size(), prefix) != 0) continue;
        const std::string rest = name.substr(prefix.size());
        const std::size_t dot = rest.find('.');
        if (dot == 0 || dot == std::string::npos || rest.find_first_not_of("0123456789") != dot ||
            rest.size() == dot + 1)
            continue;
        const pid_t pid = static_cast<pid_t>(std::stol(rest.substr(0, dot)));
        if (::kill(pid, 0) != 0 && errno == ESRCH) ::unlinkat(dirfd(dir), name.c_str(), 0);
    }
    ::closedir(dir);
}

} // namespace frac::support
