// Atomic output files: the target changes only on commit, failures leave it as it was, and no
// temporary stays beside it.
#include "support/atomic_file.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/stat.h>
#include <thread>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace frac::support;

namespace {

std::string read(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// A fresh empty directory for one test case.
fs::path scratch(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / ("frac-atomic-" + std::to_string(getpid()) + "-" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::size_t entries(const fs::path& dir) {
    return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

} // namespace

TEST_CASE("an atomic file replaces the target only when committed", "[support]") {
    const fs::path dir = scratch("commit");
    const fs::path target = dir / "out.txt";
    write_file_atomically(target.string(), "old", "text");
    {
        AtomicFile f(target.string(), "text");
        f.write("new contents");
        CHECK(read(target) == "old"); // not yet
        f.commit();
    }
    CHECK(read(target) == "new contents");
    CHECK(entries(dir) == 1);
    fs::remove_all(dir);
}

TEST_CASE("an atomic file abandoned leaves the old target and no temporary", "[support]") {
    const fs::path dir = scratch("abandon");
    const fs::path target = dir / "out.txt";
    write_file_atomically(target.string(), "old", "text");
    {
        AtomicFile f(target.string(), "text");
        f.write("half");
        std::fputs(" written", f.stream());
    } // an exception on its way, say
    CHECK(read(target) == "old");
    CHECK(entries(dir) == 1);
    fs::remove_all(dir);
}

TEST_CASE("a replaced file keeps its permissions; a copy takes its source's", "[support]") {
    const fs::path dir = scratch("modes");
    const fs::path target = dir / "out.txt", source = dir / "tool.out";
    write_file_atomically(target.string(), "old", "text");
    fs::permissions(target, fs::perms::owner_read | fs::perms::owner_write);
    write_file_atomically(target.string(), "new", "text");
    CHECK(fs::status(target).permissions() == (fs::perms::owner_read | fs::perms::owner_write));
    write_file_atomically(source.string(), "binary", "text");
    fs::permissions(source, fs::perms::owner_all);
    copy_file_atomically(source.string(), (dir / "copy").string(), "library");
    CHECK(read(dir / "copy") == "binary");
    CHECK(fs::status(dir / "copy").permissions() == fs::perms::owner_all);
    fs::remove_all(dir);
}

TEST_CASE("unwritable outputs are named before any work", "[support]") {
    const fs::path dir = scratch("problems");
    CHECK(output_problem((dir / "fine.png").string()).empty());
    CHECK(output_problem((dir / "no" / "such.png").string()).find("no directory") != std::string::npos);
    CHECK(output_problem(dir.string()) == "it is a directory");
    CHECK(entries(dir) == 0); // the probe leaves nothing
    REQUIRE_THROWS_WITH(write_file_atomically((dir / "no" / "x.stl").string(), "x", "STL"),
                        Catch::Contains("cannot write STL") && Catch::Contains("x.stl"));
    if (getuid() != 0) { // root writes anywhere
        fs::permissions(dir, fs::perms::owner_read | fs::perms::owner_exec);
        CHECK_FALSE(output_problem((dir / "fine.png").string()).empty());
        fs::permissions(dir, fs::perms::owner_all);
    }
    fs::remove_all(dir);
}

TEST_CASE("temporaries of dead writers are removed, those of live ones kept", "[support]") {
    const fs::path dir = scratch("stale");
    const fs::path target = dir / "out.svg";
    // pid 0x7fffffff: above any pid_max, never alive; our own pid: alive.
    const fs::path dead = dir / ".out.svg.frac-tmp.2147483647.0";
    const fs::path live = dir / (".out.svg.frac-tmp." + std::to_string(getpid()) + ".9");
    const fs::path other = dir / ".other.svg.frac-tmp.2147483647.0";
    for (const fs::path& p : {dead, live, other}) std::ofstream(p) << "partial";
    remove_stale_temporaries(target.string());
    CHECK_FALSE(fs::exists(dead));
    CHECK(fs::exists(live));
    CHECK(fs::exists(other)); // another output's: its own writer sweeps it
    fs::remove_all(dir);
}

TEST_CASE("a target that is not a regular file is written through and stays what it was", "[support]") {
    // A FIFO (as a device or /dev/stdout would be): renaming over it would replace it with a file.
    const fs::path dir = scratch("fifo");
    const fs::path fifo = dir / "out.png";
    REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
    CHECK(output_problem(fifo.string()).empty());
    std::string received;
    std::thread reader([&] { received = read(fifo); });
    write_file_atomically(fifo.string(), "picture bytes", "PNG");
    reader.join();
    CHECK(received == "picture bytes");
    CHECK(fs::is_fifo(fifo));
    CHECK(entries(dir) == 1);
}

TEST_CASE("same_file knows a file under its other names and a path not written yet", "[support]") {
    const fs::path dir = scratch("same");
    std::ofstream(dir / "model.frac") << "shape s(x, y) = x;";
    fs::create_hard_link(dir / "model.frac", dir / "linked.frac");
    fs::create_symlink(dir / "model.frac", dir / "symlinked.frac");
    CHECK(same_file((dir / "model.frac").string(), (dir / "linked.frac").string()));
    CHECK(same_file((dir / "symlinked.frac").string(), (dir / "model.frac").string()));
    CHECK(same_file((dir / "sub/../model.frac").string(), (dir / "model.frac").string()));
    CHECK(same_file((dir / "new.o").string(), (dir / "." / "new.o").string()));
    CHECK_FALSE(same_file((dir / "model.frac").string(), (dir / "new.o").string()));
    CHECK_FALSE(same_file((dir / "a.h").string(), (dir / "a.o").string()));
}
