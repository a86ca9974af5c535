// Cleaners: what a process leaves to be removed goes when it ends, even by SIGKILL.
#include "support/process_cleaner.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <csignal>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

namespace fs = std::filesystem;
using namespace frac::support;

namespace {

fs::path scratch(const std::string& name) {
    const fs::path dir =
        fs::temp_directory_path() / ("frac-cleaner-" + std::to_string(getpid()) + "-" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

} // namespace

TEST_CASE("names to be removed when the process ends go even when it is killed", "[support]") {
    const fs::path dir = scratch("killed");
    // Names with a newline, a backslash and a space arrive whole: their pieces, which exist too, stay.
    const std::vector<fs::path> doomed = {dir / "plain.tmp", dir / "two\nlines", dir / "back\\slash x",
                                          dir / "end\n"};
    const std::vector<fs::path> kept = {dir / "two", dir / "lines", dir / "back", dir / "end",
                                        dir / "never.tmp"};
    for (const fs::path& p : doomed) std::ofstream(p) << "partial";
    for (const fs::path& p : kept) std::ofstream(p) << "user's";
    const pid_t child = fork();
    REQUIRE(child >= 0);
    if (child == 0) {
        for (const fs::path& p : doomed) remove_when_process_ends(p.string());
        remove_when_process_ends((dir / "never.tmp.other").string()); // does not exist: nothing happens
        ::raise(SIGKILL);                                             // no destructor, no exit handler runs
        ::_exit(1);
    }
    int status = 0;
    REQUIRE(::waitpid(child, &status, 0) == child);
    REQUIRE(WIFSIGNALED(status));
    REQUIRE(WTERMSIG(status) == SIGKILL);
    // The cleaner acts once it sees the end of its input: give it time on a loaded machine.
    for (int waited = 0; waited < 200 && std::any_of(doomed.begin(), doomed.end(),
                                                     [](const fs::path& p) { return fs::exists(p); });
         ++waited)
        ::usleep(50'000);
    for (const fs::path& p : doomed) CHECK_FALSE(fs::exists(p));
    for (const fs::path& p : kept) CHECK(fs::exists(p));
    fs::remove_all(dir);
}

TEST_CASE("a cleaner holds no descriptor of its process but its input", "[support]") {
    // A pipe left open to child processes on purpose (as the compile's cleaner's input): the cleaner
    // spawned meanwhile must not keep it open, or the two cleaners and the process wait on each other.
    int held[2], input[2];
    REQUIRE(::pipe(held) == 0);
    REQUIRE(::pipe2(input, O_CLOEXEC) == 0);
    const pid_t cleaner = spawn_cleaner(input[0], "cat >/dev/null", "frac-cleanup-test", {});
    REQUIRE(cleaner > 0);
    ::close(input[0]);
    ::close(held[1]);
    pollfd end{held[0], POLLIN, 0};
    REQUIRE(::poll(&end, 1, 10'000) == 1); // the end of the held pipe: no one else has its write end
    char byte = 0;
    CHECK(::read(held[0], &byte, 1) == 0);
    ::close(held[0]);
    ::close(input[1]); // the cleaner's input ends: it exits
    int status = 0;
    REQUIRE(::waitpid(cleaner, &status, 0) == cleaner);
    CHECK(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 0);
}
