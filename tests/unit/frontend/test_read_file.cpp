// Reading model files: whole files of any length up to the limit, byte for byte (several read chunks),
// a file one byte over the limit refused, devices without end stopped at the limit, directories and
// missing files refused with a reason.
#include "frontend/loader.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace {

std::string temp_file(const std::string& contents) {
    static int n = 0;
    const auto path = std::filesystem::temp_directory_path() /
                      ("frac-test-read-" + std::to_string(::getpid()) + "-" + std::to_string(n++));
    std::ofstream(path, std::ios::binary) << contents;
    return path.string();
}

} // namespace

TEST_CASE("read_file reads whole files up to its limit and refuses larger ones", "[frontend]") {
    std::string text, why;
    // 200,003 bytes (longer than a read chunk), every byte value.
    std::string big;
    for (int i = 0; i < 200003; ++i) big.push_back(static_cast<char>((i * 7919) & 0xff));
    const std::string path = temp_file(big);
    REQUIRE(frac::front::read_file(path, big.size(), text, why));
    CHECK(text == big);
    REQUIRE(frac::front::read_file(path, std::size_t{1} << 24, text, why));
    CHECK(text == big);
    CHECK_FALSE(frac::front::read_file(path, big.size() - 1, text, why));
    CHECK(why.find("larger than the limit") != std::string::npos);

    const std::string empty = temp_file("");
    REQUIRE(frac::front::read_file(empty, 10, text, why));
    CHECK(text.empty());

    if (std::filesystem::exists("/dev/zero")) {
        CHECK_FALSE(frac::front::read_file("/dev/zero", 100000, text, why));
        CHECK(why.find("larger than the limit") != std::string::npos);
    }
    CHECK_FALSE(frac::front::read_file(std::filesystem::temp_directory_path().string(), 10, text, why));
    CHECK(why == "is a directory");
    CHECK_FALSE(frac::front::read_file(path + ".missing", 10, text, why));
    CHECK_FALSE(why.empty());
    std::filesystem::remove(path);
    std::filesystem::remove(empty);
}
