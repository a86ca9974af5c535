#include "support/fill_later.hpp"

#include <catch2/catch.hpp>
#include <cstdint>
#include <vector>

using frac::support::FillLater;

namespace {

struct Cell {
    std::uint8_t level = 7;
    std::uint32_t ix = 9;
};

} // namespace

TEST_CASE("a FillLater vector's resize leaves the new elements unwritten", "[support][fill_later]") {
    std::vector<Cell, FillLater<Cell>> v(1000, Cell{1, 2});
    const Cell* data = v.data();
    v.clear();
    v.resize(1000); // in the same room: what was there stays (std::allocator would write 7 and 9)
    REQUIRE(v.data() == data);
    CHECK(v[0].level == 1);
    CHECK(v[999].ix == 2);
    v.resize(1500);
    v[1200] = {3, 4};
    CHECK(v[1200].ix == 4);
}

TEST_CASE("a FillLater vector constructs from values and copies as usual", "[support][fill_later]") {
    std::vector<Cell, FillLater<Cell>> v;
    v.push_back({5, 6});
    v.emplace_back(Cell{});
    v.insert(v.end(), 3, Cell{8, 1});
    CHECK(v.size() == 5);
    CHECK(v[0].ix == 6);
    CHECK(v[1].level == 7); // a copy of a default Cell: written
    CHECK(v[4].level == 8);
    const std::vector<Cell, FillLater<Cell>> w = v;
    CHECK(w[4].ix == 1);
    std::vector<Cell, FillLater<std::uint32_t>::rebind<Cell>::other> same(w.begin(), w.end());
    CHECK(same.size() == 5);
}
