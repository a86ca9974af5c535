#include "support/process_cleaner.hpp"

#include <cctype>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <mutex>
#include <spawn.h>
#include <sys/socket.h>
#include <unistd.h>

extern char** environ;

namespace frac::support {
namespace fs = std::filesystem;

pid_t spawn_cleaner(int input, const std::string& script, const std::string& name,
                    const std::vector<std::string>& args) {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, input, STDIN_FILENO);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
    // Nothing else: a descriptor held open on purpose (another cleaner's input) must not wait for this one.
    posix_spawn_file_actions_addclosefrom_np(&actions, STDERR_FILENO + 1);
    // The terminal's signals reach the whole process group: the cleaner must outlive what it cleans after.
    const std::string guarded = "trap '' INT TERM HUP QUIT\n" + script;
    std::vector<const char*> argv = {"sh", "-c", guarded.c_str(), name.c_str()};
    for (const std::string& arg : args) argv.push_back(arg.c_str());
    argv.push_back(nullptr);
    pid_t pid = 0;
    const int err =
        posix_spawn(&pid, "/bin/sh", &actions, nullptr, const_cast<char* const*>(argv.data()), environ);
    posix_spawn_file_actions_destroy(&actions);
    return err == 0 ? pid : -1;
}

namespace {

// The cleaner of names this process must not leave behind: an `sh` that collects them from a socket only
// this process holds and, when the socket closes, removes those that still exist. One per process,
// started on first use.
class ProcessCleaner {
public:
    static ProcessCleaner& instance() {
        static ProcessCleaner cleaner;
        return cleaner;
    }

    void add(const std::string& path) {
        const std::string line = escaped(path) + "\n";
        const std::lock_guard lock(mutex_);
        if (owner_ != ::getpid()) { // first use, or a forked child: its own cleaner, for its own end
            if (fd_ >= 0) ::close(fd_);
            owner_ = ::getpid();
            start();
        }
        if (fd_ < 0) return; // no cleaner: a later run still removes the temporaries of dead writers
        for (std::size_t sent = 0; sent < line.size();) {
            const ssize_t n = ::send(fd_, line.data() + sent, line.size() - sent, MSG_NOSIGNAL);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) return;
            sent += static_cast<std::size_t>(n);
        }
    }

private:
    // A line for the cleaner's `printf %b`: every byte but [A-Za-z0-9._/+-] as \0ooo, so that names with
    // newlines or backslashes arrive whole.
    static std::string escaped(const std::string& path) {
        std::string out;
        for (const char c : path) {
            const auto byte = static_cast<unsigned char>(c);
            if (std::isalnum(byte) || std::strchr("._/+-", c))
                out += c;
            else {
                const char octal[] = {'\\', '0', static_cast<char>('0' + (byte >> 6)),
                                      static_cast<char>('0' + ((byte >> 3) & 7)),
                                      static_cast<char>('0' + (byte & 7))};
                out.append(octal, sizeof octal);
            }
        }
        return out;
    }

    void start() {
        fd_ = -1;
        int fds[2];
        if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, fds) != 0) return;
        // `x` keeps the trailing newlines of a name that command substitution would strip.
        const pid_t pid = spawn_cleaner(
            fds[0],
            "while IFS= read -r line; do f=$(printf '%bx' \"$line\"); set -- \"$@\" \"${f%x}\"; done\n"
            "[ $# -eq 0 ] || exec rm -f -- \"$@\"",
            "frac-cleanup", {});
        ::close(fds[0]);
        if (pid < 0) {
            ::close(fds[1]);
            return;
        }
        fd_ = fds[1]; // the cleaner is never waited for: it ends after this process
    }

    std::mutex mutex_;
    pid_t owner_ = 0; // the process the cleaner was started for
    int fd_ = -1;     // -1: could not start
};

} // namespace

void remove_when_process_ends(const std::string& path) {
    std::error_code ec;
    const fs::path absolute = fs::absolute(path, ec); // the process may change directory later
    ProcessCleaner::instance().add(ec ? path : absolute.string());
}

} // namespace frac::support
