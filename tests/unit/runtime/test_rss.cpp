// Recursive space subdivision: soundness of the classification, consistency of the counts, order,
// batching, outward cell boxes, option validation.
#include "runtime/rss.hpp"
#include "shapes.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>
#include <tuple>

using namespace frac;
using namespace frac::rt;
using frac::rt::test::Ball;
using frac::rt::test::Constant;
using frac::rt::test::Disk;
using frac::rt::test::HalfDefined;
using frac::rt::test::HalfPlane;
using frac::rt::test::NanShape;
using frac::rt::test::Stripes;

namespace {

const std::vector<Interval> square{{-1.0, 1.0}, {-1.0, 1.0}};
const std::vector<Interval> unit{{0.0, 1.0}, {0.0, 1.0}};
const std::vector<Interval> cube{{-1.0, 1.0}, {-1.0, 1.0}, {-1.0, 1.0}};

RssOptions opts(int depth, int split = 2, bool keep = true) {
    RssOptions o;
    o.depth = depth;
    o.split = split;
    o.keep_cells = keep;
    return o;
}

std::uint64_t pow_u(std::uint64_t b, int e) {
    std::uint64_t n = 1;
    for (int i = 0; i < e; ++i) n *= b;
    return n;
}

// Every invariant of the counts and of the cell list that holds for any shape.
void check_consistency(const RssResult& r) {
    const int d = r.dimension();
    const int depth = r.options.depth;
    const std::uint64_t fan = pow_u(static_cast<std::uint64_t>(r.options.split), d);
    REQUIRE(r.levels.size() == static_cast<std::size_t>(depth) + 1);
    REQUIRE(r.levels[0].evaluated == 1);
    std::uint64_t evaluated = 0, inside = 0, outside = 0, subdivided = 0;
    for (int k = 0; k <= depth; ++k) {
        const LevelCounts& lc = r.levels[static_cast<std::size_t>(k)];
        CHECK(lc.evaluated == lc.inside + lc.outside + lc.undecided);
        if (k < depth) {
            CHECK(r.levels[static_cast<std::size_t>(k) + 1].evaluated == lc.undecided * fan);
            subdivided += lc.undecided;
        }
        evaluated += lc.evaluated;
        inside += lc.inside;
        outside += lc.outside;
    }
    CHECK(r.evaluated == evaluated);
    CHECK(r.inside == inside);
    CHECK(r.outside == outside);
    CHECK(r.boundary == r.levels.back().undecided);
    CHECK(r.subdivided == subdivided);
    CHECK(r.evaluated == r.inside + r.outside + r.boundary + r.subdivided);
    CHECK(r.seconds >= 0);
    if (!r.options.keep_cells) {
        CHECK(r.cells.empty());
        return;
    }
    REQUIRE(r.cells.size() == r.evaluated);
    // Ordered by (level, iz, iy, ix), no duplicates; classes agree with the counts; each cell of
    // level k+1 is the child of a subdivided cell of level k (with the counts: exactly the children).
    std::vector<LevelCounts> seen(r.levels.size());
    std::set<std::tuple<std::uint32_t, std::uint32_t, std::uint32_t>> subdivided_prev, subdivided_here;
    int level = 0;
    for (std::size_t i = 0; i < r.cells.size(); ++i) {
        const Cell& c = r.cells[i];
        if (i > 0) {
            const Cell& p = r.cells[i - 1];
            REQUIRE(std::tie(p.level, p.iz, p.iy, p.ix) < std::tie(c.level, c.iz, c.iy, c.ix));
        }
        if (c.level != level) {
            REQUIRE(c.level == level + 1);
            level = c.level;
            subdivided_prev.swap(subdivided_here);
            subdivided_here.clear();
        }
        const std::uint64_t n = r.cells_per_axis(c.level);
        REQUIRE(c.ix < n);
        REQUIRE(c.iy < n);
        REQUIRE(c.iz < (d == 3 ? n : 1));
        if (c.level > 0) {
            const auto s = static_cast<std::uint32_t>(r.options.split);
            REQUIRE(subdivided_prev.count({c.ix / s, c.iy / s, c.iz / s}) == 1);
        }
        LevelCounts& lc = seen[c.level];
        ++lc.evaluated;
        switch (c.cls) {
        case CellClass::inside: ++lc.inside; break;
        case CellClass::outside: ++lc.outside; break;
        case CellClass::boundary:
            REQUIRE(c.level == depth);
            ++lc.undecided;
            break;
        case CellClass::subdivided:
            REQUIRE(c.level < depth);
            ++lc.undecided;
            subdivided_here.insert({c.ix, c.iy, c.iz});
            break;
        }
    }
    for (std::size_t k = 0; k < r.levels.size(); ++k) {
        CHECK(seen[k].evaluated == r.levels[k].evaluated);
        CHECK(seen[k].inside == r.levels[k].inside);
        CHECK(seen[k].outside == r.levels[k].outside);
        CHECK(seen[k].undecided == r.levels[k].undecided);
    }
}

// Squared distances from (cx, cy, cz) to the nearest and farthest points of a cell's box, in long
// double (exact for the dyadic boxes used with centred shapes).
struct Range2 {
    long double near, far;
};

Range2 dist2(const RssResult& r, const Cell& c, const double* centre) {
    Range2 d{0, 0};
    for (int a = 0; a < r.dimension(); ++a) {
        const Interval x = r.cell_interval(c, a);
        const long double lo = static_cast<long double>(x.lo) - centre[a];
        const long double hi = static_cast<long double>(x.hi) - centre[a];
        const long double nearest = lo > 0 ? lo : hi < 0 ? -hi : 0;
        const long double farthest = std::max(-lo, hi);
        d.near += nearest * nearest;
        d.far += farthest * farthest;
    }
    return d;
}

// Inside cells lie strictly inside the ball, outside cells strictly outside; with `tight` (exact
// enclosures on dyadic boxes) boundary cells really meet the sphere.
void check_ball(const RssResult& r, const double* centre, double radius, bool tight) {
    const long double r2 = static_cast<long double>(radius) * radius;
    for (const Cell& c : r.cells) {
        const Range2 d = dist2(r, c, centre);
        switch (c.cls) {
        case CellClass::inside: REQUIRE(d.far < r2); break;
        case CellClass::outside: REQUIRE(d.near > r2); break;
        case CellClass::boundary:
        case CellClass::subdivided:
            if (tight) {
                REQUIRE(d.near <= r2);
                REQUIRE(d.far >= r2);
            }
            break;
        }
    }
}

bool same_cells(const RssResult& a, const RssResult& b) {
    return std::equal(
        a.cells.begin(), a.cells.end(), b.cells.begin(), b.cells.end(), [](const Cell& x, const Cell& y) {
            return x.level == y.level && x.cls == y.cls && x.ix == y.ix && x.iy == y.iy && x.iz == y.iz;
        });
}

} // namespace

TEST_CASE("rss: disk classification is sound and tight", "[rss]") {
    Disk disk(0, 0, 0.75);
    const RssResult r = subdivide(disk, square, opts(7));
    check_consistency(r);
    const double centre[2] = {0, 0};
    check_ball(r, centre, 0.75, true);
    CHECK(r.inside > 0);
    CHECK(r.outside > 0);
    CHECK(r.boundary > 0);
    // Level 0 is the root, undecided; at level 1 each quadrant holds the centre's corner and the
    // far corner (distance sqrt 2 > 0.75): undecided too.
    CHECK(r.cells[0].cls == CellClass::subdivided);
    CHECK(r.levels[1].undecided == 4);
}

TEST_CASE("rss: off-centre disk, non-dyadic numbers", "[rss]") {
    Disk disk(0.1, -0.2, 0.6);
    const std::vector<Interval> root{{-0.9, 1.1}, {-1.3, 0.7}};
    const RssResult r = subdivide(disk, root, opts(6));
    check_consistency(r);
    const double centre[2] = {0.1, -0.2};
    check_ball(r, centre, 0.6, false);
    CHECK(r.inside > 0);
}

TEST_CASE("rss: stripes are classified soundly", "[rss]") {
    // 1/4 - dz(2x) < 0 where 2x is within 1/4 of a half-integer: x in (1/8, 3/8) or (5/8, 7/8).
    Stripes stripes(2);
    const RssResult r = subdivide(stripes, unit, opts(6));
    check_consistency(r);
    for (const Cell& c : r.cells) {
        const Interval x = r.cell_interval(c, 0);
        const bool in = (x.lo > 0.125 && x.hi < 0.375) || (x.lo > 0.625 && x.hi < 0.875);
        const bool out = x.hi < 0.125 || (x.lo > 0.375 && x.hi < 0.625) || x.lo > 0.875;
        if (c.cls == CellClass::inside) REQUIRE(in);
        if (c.cls == CellClass::outside) REQUIRE(out);
    }
    // The pattern does not depend on y: as many undecided cells in every row of the deepest level.
    const std::uint64_t n = r.cells_per_axis(6);
    std::vector<std::uint64_t> per_row(n, 0);
    for (const Cell& c : r.cells)
        if (c.cls == CellClass::boundary) ++per_row[c.iy];
    CHECK(std::all_of(per_row.begin(), per_row.end(), [&](std::uint64_t v) { return v == per_row[0]; }));
    CHECK(per_row[0] > 0);
    CHECK(r.boundary == n * per_row[0]);
}

TEST_CASE("rss: the leaves tile the root box", "[rss]") {
    Disk disk(0.1, 0.05, 0.5);
    for (int split : {2, 3}) {
        const RssResult r = subdivide(disk, square, opts(split == 2 ? 6 : 4, split));
        // Area in units of deepest cells: a leaf of level k covers (split^(depth-k))^2 of them.
        const std::uint64_t full = r.cells_per_axis(r.options.depth);
        std::uint64_t area = 0;
        for (const Cell& c : r.cells)
            if (c.cls != CellClass::subdivided) {
                const std::uint64_t side = full / r.cells_per_axis(c.level);
                area += side * side;
            }
        CHECK(area == full * full);
    }
}

TEST_CASE("rss: deterministic, with or without cells", "[rss]") {
    Disk disk(0.1, 0.05, 0.5);
    const RssResult a = subdivide(disk, square, opts(8));
    const RssResult b = subdivide(disk, square, opts(8));
    CHECK(same_cells(a, b));
    const RssResult c = subdivide(disk, square, opts(8, 2, false));
    check_consistency(c);
    CHECK(c.cells.empty());
    CHECK(c.evaluated == a.evaluated);
    CHECK(c.inside == a.inside);
    CHECK(c.outside == a.outside);
    CHECK(c.boundary == a.boundary);
    for (std::size_t k = 0; k < a.levels.size(); ++k) {
        CHECK(c.levels[k].evaluated == a.levels[k].evaluated);
        CHECK(c.levels[k].undecided == a.levels[k].undecided);
    }
    // The batch size changes the calls, not the result.
    RssOptions small = opts(8);
    small.batch = 7;
    const RssResult d = subdivide(disk, square, small);
    CHECK(same_cells(a, d));
}

// The vertical line x = c; records every box it is asked about, in order.
class RecordingLine : public test::TestShape {
public:
    explicit RecordingLine(double c) : TestShape(2), c(c) {}
    double eval_point(const double* p) override { return p[0] - c; }
    Interval eval_box(const Interval* b) override {
        seen.push_back(b[0]);
        seen.push_back(b[1]);
        num::UpwardRounding up;
        return num::sub(b[0], Interval(c));
    }
    std::unique_ptr<ir::Evaluator> clone() const override { return std::make_unique<RecordingLine>(*this); }

    double c;
    std::vector<Interval> seen;
};

TEST_CASE("rss: the boxes evaluated are the cells' boxes, with and without the grid-point table", "[rss]") {
    // Split 3 (1/3 is not a binary number): levels up to 10 have at most 3^10 < 2^16 cells per axis and
    // use the table of grid points; level 11 computes each cell's box directly.
    RecordingLine line(0.3);
    const RssResult r = subdivide(line, square, opts(11, 3));
    REQUIRE(line.seen.size() == 2 * r.cells.size());
    REQUIRE(r.levels[11].evaluated > 0);
    std::size_t mismatches = 0;
    for (std::size_t i = 0; i < r.cells.size(); ++i)
        for (int a = 0; a < 2; ++a) {
            const Interval want = r.cell_interval(r.cells[i], a);
            const Interval got = line.seen[2 * i + static_cast<std::size_t>(a)];
            if (!(got.lo == want.lo && got.hi == want.hi)) ++mismatches;
        }
    CHECK(mismatches == 0);
}

TEST_CASE("rss: evaluates level by level in batches", "[rss]") {
    Disk disk(0, 0, 0.75);
    RssOptions o = opts(6);
    o.batch = 10;
    const RssResult r = subdivide(disk, square, o);
    std::size_t expected = 0;
    for (const LevelCounts& lc : r.levels) expected += static_cast<std::size_t>((lc.evaluated + 9) / 10);
    CHECK(disk.batches == expected);
    CHECK(disk.max_batch == 10);

    Disk big(0, 0, 0.75);
    const RssResult r2 = subdivide(big, square, opts(6));
    std::size_t nonempty = 0;
    for (const LevelCounts& lc : r2.levels) nonempty += lc.evaluated > 0 ? 1 : 0;
    CHECK(big.batches == nonempty); // every level fits one default batch here
}

namespace {

// A disk whose every tape push (in the chunks, as the interpreter's) returns an evaluator of its own,
// which logs the size of each of its eval_boxes calls: the children of a parent evaluated side by side
// log one call of 4. It says it has `instructions` instructions (a long function makes the chunks of
// few cells).
class PushingDisk : public Disk {
public:
    struct Log {
        std::mutex mu;
        std::map<int, std::vector<std::size_t>> calls; // by evaluator (0: the shape's)
        int pushed = 0;
        std::size_t instructions = 0;
    };
    PushingDisk(std::shared_ptr<Log> log, int id) : Disk(0.1, -0.2, 0.6), log(std::move(log)), id(id) {}
    std::size_t instruction_count() const override { return log->instructions; }
    bool may_specialize() const override { return true; }
    bool specializes_independently() const override { return true; }
    std::size_t kept_evaluations() const override { return 4; }
    void eval_boxes(const Interval* boxes, std::size_t n, Interval* out) override {
        {
            std::lock_guard<std::mutex> lock(log->mu);
            log->calls[id].push_back(n);
        }
        Disk::eval_boxes(boxes, n, out);
    }
    std::shared_ptr<ir::Evaluator> specialize_after_eval(std::size_t, const Interval*, double) override {
        std::lock_guard<std::mutex> lock(log->mu);
        return std::make_shared<PushingDisk>(log, ++log->pushed);
    }
    std::unique_ptr<ir::Evaluator> clone() const override { return std::make_unique<PushingDisk>(log, id); }

    std::shared_ptr<Log> log;
    int id;
};

} // namespace

TEST_CASE("rss: a parent's children stay in one chunk when they push tapes", "[rss]") {
    // Batches and chunks cut the level's order (row-major: a parent's children lie in two rows); cut
    // between those rows, its children would evaluate and push in two halves. (Batches at least as
    // large as a parent row's children: a smaller one cannot help cutting them.)
    // A function of 100,000 instructions makes chunks of single cells where they do not split blocks.
    for (const std::size_t instructions : {std::size_t{0}, std::size_t{100000}})
        for (const std::size_t batch : {std::size_t{300}, std::size_t{1000}, std::size_t{4096}}) {
            for (const int threads : {1, 2}) {
                auto log = std::make_shared<PushingDisk::Log>();
                log->instructions = instructions;
                PushingDisk disk(log, 0);
                RssOptions o = opts(7);
                o.batch = batch;
                o.threads = threads;
                const RssResult r = subdivide(disk, square, o);
                check_consistency(r);
                INFO("batch " << batch << ", " << threads << " threads, " << instructions << " instructions");
                REQUIRE(log->pushed > 300);
                for (const auto& [id, calls] : log->calls) {
                    if (id == 0) continue;
                    INFO("pushed evaluator " << id);
                    REQUIRE(calls == std::vector<std::size_t>{4});
                }
            }
        }
}

TEST_CASE("rss: progress reports each level", "[rss]") {
    Disk disk(0, 0, 0.75);
    RssOptions o = opts(5);
    std::vector<std::pair<int, std::uint64_t>> calls;
    o.progress = [&](int level, std::uint64_t evaluated) { calls.emplace_back(level, evaluated); };
    const RssResult r = subdivide(disk, square, o);
    REQUIRE(calls.size() == 6); // a fast run makes only the end-of-level calls
    std::uint64_t sum = 0;
    for (int k = 0; k <= 5; ++k) {
        sum += r.levels[static_cast<std::size_t>(k)].evaluated;
        CHECK(calls[static_cast<std::size_t>(k)].first == k);
        CHECK(calls[static_cast<std::size_t>(k)].second == sum);
    }
    CHECK(calls.back().second == r.evaluated);
}

TEST_CASE("rss: split 3", "[rss]") {
    Disk disk(0, 0, 0.75);
    const RssResult r = subdivide(disk, square, opts(4, 3));
    check_consistency(r);
    const double centre[2] = {0, 0};
    check_ball(r, centre, 0.75, false); // thirds are not dyadic: boxes are outward-rounded
    CHECK(r.levels[1].evaluated == 9);
    CHECK(r.levels[1].inside == 1); // the centre cell [-1/3, 1/3]^2 lies in the disk (0.47 < 0.75)
}

TEST_CASE("rss: cell boxes are outward and leave no gaps", "[rss]") {
    Constant f(2, 1.0);
    const std::vector<Interval> root{{-0.3, 0.7}, {0.1, 0.2}};
    const RssResult r = subdivide(f, root, opts(0, 3));
    for (int level : {1, 3, 5}) {
        const std::uint64_t n = r.cells_per_axis(level);
        for (int axis = 0; axis < 2; ++axis) {
            Interval prev{};
            for (std::uint32_t i = 0; i < n; ++i) {
                Cell c;
                c.level = static_cast<std::uint8_t>(level);
                c.ix = c.iy = i;
                const Interval x = r.cell_interval(c, axis);
                REQUIRE(x.lo < x.hi);
                REQUIRE(root[axis].contains(x));
                if (i == 0) REQUIRE(x.lo == root[axis].lo);
                if (i + 1 == n) REQUIRE(x.hi == root[axis].hi);
                if (i > 0) REQUIRE(prev.hi >= x.lo); // neighbours overlap or touch
                prev = x;
            }
        }
    }
    // Exact grid points on a dyadic root stay exact (no widening where none is needed).
    const RssResult d = subdivide(f, unit, opts(0, 2));
    Cell c;
    c.level = 3;
    c.ix = 5;
    CHECK(d.cell_interval(c, 0) == Interval(0.625, 0.75));
    // Thirds of [0, 1] enclose the exact value.
    const RssResult t = subdivide(f, unit, opts(0, 3));
    c.level = 1;
    c.ix = 1;
    const Interval third = t.cell_interval(c, 0);
    CHECK(static_cast<long double>(third.lo) * 3 <= 1.0L);
    CHECK(static_cast<long double>(third.hi) * 3 >= 2.0L);
    CHECK_THROWS_AS(t.cell_interval(c, 2), std::out_of_range);
}

TEST_CASE("rss: 3D ball", "[rss]") {
    Ball ball(0.75);
    const RssResult r = subdivide(ball, cube, opts(5));
    check_consistency(r);
    const double centre[3] = {0, 0, 0};
    check_ball(r, centre, 0.75, true);
    CHECK(r.levels[1].evaluated == 8);
    CHECK(r.inside > 0);
    CHECK(r.boundary > 0);
    // Symmetry: each octant has the same number of boundary cells.
    const std::uint64_t half = r.cells_per_axis(5) / 2;
    std::uint64_t octants[8] = {};
    for (const Cell& c : r.cells)
        if (c.cls == CellClass::boundary)
            ++octants[(c.ix >= half ? 1 : 0) + (c.iy >= half ? 2 : 0) + (c.iz >= half ? 4 : 0)];
    for (std::uint64_t o : octants) CHECK(o == octants[0]);
}

TEST_CASE("rss: empty enclosures are outside, NaN bounds undecided", "[rss]") {
    HalfDefined f;
    const std::vector<Interval> root{{-1.2, 0.8}, {-1.0, 1.0}};
    const RssResult r = subdivide(f, root, opts(4));
    check_consistency(r);
    for (const Cell& c : r.cells)
        if (r.cell_interval(c, 0).hi < 0) REQUIRE(c.cls == CellClass::outside);
    CHECK(r.levels[1].outside == 2); // the two left quadrants, x in [-1.2, -0.2]: f undefined there
    CHECK(r.levels[1].undecided == 2);

    NanShape nan(2);
    const RssResult n = subdivide(nan, square, opts(3));
    check_consistency(n);
    CHECK(n.inside == 0);
    CHECK(n.outside == 0);
    CHECK(n.boundary == 64);
}

TEST_CASE("rss: trivial shapes and depth 0", "[rss]") {
    Constant in(2, -1.0), out(2, 1.0), zero(2, 0.0);
    const RssResult a = subdivide(in, square, opts(5));
    check_consistency(a);
    CHECK(a.evaluated == 1);
    CHECK(a.inside == 1);
    CHECK(a.levels.size() == 6);
    CHECK(a.levels[5].evaluated == 0);
    const RssResult b = subdivide(out, square, opts(5));
    CHECK(b.outside == 1);
    const RssResult c = subdivide(zero, square, opts(0));
    check_consistency(c);
    CHECK(c.boundary == 1);
    CHECK(c.cells.size() == 1);
    CHECK(c.cells[0].cls == CellClass::boundary);
}

TEST_CASE("rss: the closed rule counts cells touching the surface as inside", "[rss]") {
    // f = x - 1/2: the left half [0, 1/2] x [0, 1] is the closed solid {f <= 0}; its cells have hi = 0.
    HalfPlane f(1, 0, -0.5);
    RssOptions o = opts(1);
    const RssResult open = subdivide(f, unit, o);
    CHECK(open.inside == 0);
    CHECK(open.boundary == 4);
    o.closed_inside = true;
    const RssResult closed = subdivide(f, unit, o);
    check_consistency(closed);
    CHECK(closed.inside == 2);
    CHECK(closed.boundary == 2); // the right cells touch the solid (lo = 0): never outside
    for (const Cell& c : closed.cells)
        if (c.level == 1) CHECK((c.cls == CellClass::inside) == (c.ix == 0));

    // f = 0 everywhere: the solid is the whole root; undefined and NaN cells are unchanged.
    Constant zero(2, 0.0);
    CHECK(subdivide(zero, square, o).inside == 1);
    HalfDefined half;
    const RssResult h = subdivide(half, {{-1.2, 0.8}, {-1.0, 1.0}}, o);
    CHECK(h.levels[1].outside == 2);
    NanShape nan(2);
    const RssResult n = subdivide(nan, square, o);
    CHECK(n.inside == 0);
    CHECK(n.boundary == 4);
}

TEST_CASE("rss: option and box validation", "[rss]") {
    Disk disk(0, 0, 0.5);
    Ball ball(0.5);
    using Catch::Matchers::Contains;
    CHECK_THROWS_WITH(subdivide(disk, square, opts(-1)), Contains("depth -1"));
    CHECK_THROWS_WITH(subdivide(disk, square, opts(max_depth_2d + 1)), Contains("depth 25"));
    CHECK_THROWS_WITH(subdivide(ball, cube, opts(max_depth_3d + 1)), Contains("depth 15"));
    CHECK_THROWS_WITH(subdivide(disk, square, opts(4, 1)), Contains("split 1"));
    CHECK_THROWS_WITH(subdivide(disk, square, opts(4, 5)), Contains("split 5"));
    CHECK_THROWS_WITH(subdivide(disk, square, opts(17, 4)), Contains("2^32"));
    CHECK_THROWS_WITH(subdivide(disk, square, opts(21, 3)), Contains("2^32"));
    Constant in(2, -1.0);
    CHECK_NOTHROW(subdivide(in, square, opts(16, 4)));
    CHECK_NOTHROW(subdivide(in, square, opts(20, 3)));
    CHECK_THROWS_WITH(subdivide(disk, cube, opts(4)), Contains("2 coordinates"));
    CHECK_THROWS_WITH(subdivide(ball, square, opts(4)), Contains("3 coordinates"));
    const std::vector<Interval> one{Interval(0.0, 1.0)};
    CHECK_THROWS_WITH(subdivide(disk, one, opts(4)), Contains("1 axes"));
    const std::vector<Interval> four(4, Interval(0.0, 1.0));
    CHECK_THROWS_WITH(subdivide(disk, four, opts(4)), Contains("4 axes"));
    const std::vector<Interval> thin{Interval(0.0, 1.0), Interval(1.0, 1.0)};
    CHECK_THROWS_WITH(subdivide(disk, thin, opts(4)), Contains("axis 1"));
    const std::vector<Interval> reversed{Interval(2.0, 1.0), Interval(0.0, 1.0)};
    CHECK_THROWS_WITH(subdivide(disk, reversed, opts(4)), Contains("axis 0"));
    const std::vector<Interval> unbounded{Interval(0.0, num::inf), Interval(0.0, 1.0)};
    CHECK_THROWS_AS(subdivide(disk, unbounded, opts(4)), std::invalid_argument);
    const std::vector<Interval> empty{Interval::empty(), Interval(0.0, 1.0)};
    CHECK_THROWS_AS(subdivide(disk, empty, opts(4)), std::invalid_argument);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const std::vector<Interval> nan_box{Interval(nan, 1.0), Interval(0.0, 1.0)};
    CHECK_THROWS_AS(subdivide(disk, nan_box, opts(4)), std::invalid_argument);
    RssOptions o = opts(4);
    o.batch = 0;
    CHECK_THROWS_WITH(subdivide(disk, square, o), Contains("batch"));
    CHECK_THROWS_AS(subdivide(disk, square, opts(30)), std::invalid_argument);
}

namespace {

// A disk that counts its evaluations (over its clones) and records the cover's forecasts.
struct ForecastLog {
    std::mutex mu;
    std::uint64_t evaluated = 0;
    std::vector<std::pair<std::uint64_t, double>> forecasts; // (evaluated before it, cells foreseen)
};

class ForeseenDisk : public Disk {
public:
    ForeseenDisk(std::shared_ptr<ForecastLog> log) : Disk(0.1, 0.2, 0.7), log_(std::move(log)) {}
    void eval_boxes(const Interval* boxes, std::size_t n, Interval* out) override {
        Disk::eval_boxes(boxes, n, out);
        std::lock_guard<std::mutex> lock(log_->mu);
        log_->evaluated += n;
    }
    void foresee(double evaluations) override {
        std::lock_guard<std::mutex> lock(log_->mu);
        log_->forecasts.emplace_back(log_->evaluated, evaluations);
    }
    std::unique_ptr<Evaluator> clone() const override { return std::make_unique<ForeseenDisk>(*this); }

private:
    std::shared_ptr<ForecastLog> log_;
};

} // namespace

TEST_CASE("a cover tells its evaluator the cells it foresees to its depth, once the growth is known",
          "[rss]") {
    for (int threads : {1, 2}) {
        auto log = std::make_shared<ForecastLog>();
        ForeseenDisk disk(log);
        RssOptions o;
        o.depth = 14;
        o.threads = threads;
        const RssResult r = subdivide(disk, {{-1, 1}, {-1, 1}}, o);
        REQUIRE(log->evaluated == r.evaluated);
        // A circle's frontier doubles per level: from about 4,096 undecided cells on (level 10 of 14),
        // one forecast per level, each within 10% of the cells the cover then evaluated.
        CHECK(log->forecasts.size() >= 3);
        CHECK(log->forecasts.size() <= 5);
        for (const auto& [before, foreseen] : log->forecasts) {
            const double left = static_cast<double>(r.evaluated - before);
            INFO("foreseen " << foreseen << " left " << left);
            CHECK(foreseen >= 0.9 * left);
            CHECK(foreseen <= 1.1 * left);
        }
    }
}
