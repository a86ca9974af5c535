// The JIT's on-disk cache of machine code (backend/llvm/code_cache.hpp): a second compile of the same
// tape loads the object instead of running LLVM, with the same bits; a damaged entry is never linked; a
// directory that cannot be written leaves compiling to LLVM; tapes calling external functions are not
// cached; the directory's size stays bounded.
#include "engines.hpp"

#include <filesystem>
#include <fstream>
#include <set>
#include <unistd.h>

using namespace frac;
using namespace frac::test;

namespace {

namespace fs = std::filesystem;

// A fresh directory under the system's temporary one, removed at the end of the test.
struct TempDir {
    fs::path path;
    explicit TempDir(const std::string& name)
        : path(fs::temp_directory_path() / (name + "-" + std::to_string(::getpid()))) {
        fs::remove_all(path);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

std::vector<fs::path> entries(const fs::path& dir) {
    std::vector<fs::path> files;
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
        files.push_back(it->path());
    return files;
}

jit::JitConfig cached(const TempDir& dir) {
    jit::JitConfig config;
    config.cache_dir = dir.path.string();
    return config;
}

// The evaluators agree bit for bit on boxes (one at a time and in a batch), points and series counts.
void require_same_results(ir::Evaluator& a, ir::Evaluator& b, std::uint64_t seed) {
    a.stats = {};
    b.stats = {};
    BoxMaker mk(seed);
    const int d = a.dimension();
    const std::vector<Interval> range(static_cast<std::size_t>(d), Interval{-1.5, 1.5});
    std::vector<Interval> boxes;
    for (int n = 0; n < 300; ++n) {
        const auto box = mk.box(range);
        boxes.insert(boxes.end(), box.begin(), box.end());
        INFO(hex_box(box.data(), d));
        REQUIRE(same(a.eval_box(box.data()), b.eval_box(box.data())));
        const auto p = mk.point(range);
        REQUIRE(same(a.eval_point(p.data()), b.eval_point(p.data())));
    }
    std::vector<Interval> ra(300), rb(300);
    a.eval_boxes(boxes.data(), 300, ra.data());
    b.eval_boxes(boxes.data(), 300, rb.data());
    for (int n = 0; n < 300; ++n) REQUIRE(same(ra[n], rb[n]));
    CHECK(a.stats.series_terms == b.stats.series_terms);
    CHECK(a.stats.series_capped == b.stats.series_capped);
}

const char* const shapes = R"(import "fractals";
shape wave(x, y) = y - sum(i in 0.., sin(2^i * x) * x / 2^i) + sqrt(abs(x * y)) - exp(-x^2);
)";

} // namespace

TEST_CASE("code cache: a second compile loads the object, with the same bits", "[llvm][cache]") {
    const TempDir dir("frac-cache-same");
    const Model m = compile(shapes);
    std::set<std::string> modules; // the distinct IR compiled so far
    for (std::size_t i = 0; i < m.tapes.size(); ++i) {
        INFO(m.shape(i).name);
        // A shape whose code is another's (the same IR) finds that one's entry.
        const bool new_code = modules.insert(jit::emit_llvm(m.tapes[i], {}, false)).second;
        auto miss = jit::make_jit(m.tapes[i], {}, cached(dir));
        CHECK(jit::compile_info(*miss)->cache == (new_code ? "miss" : "hit"));
        CHECK((jit::compile_info(*miss)->ir_instructions > 0) == new_code);
        auto hit = jit::make_jit(m.tapes[i], {}, cached(dir));
        CHECK(jit::compile_info(*hit)->cache == "hit");
        CHECK(jit::compile_info(*hit)->optimize_ms == 0);
        auto uncached = jit::make_jit(m.tapes[i]);
        CHECK(jit::compile_info(*uncached)->cache == "off");
        // Both alive at once: each tape's code is linked into its own library.
        require_same_results(*hit, *uncached, 20261203 + i);
        require_same_results(*miss, *hit, 20261204 + i);
        auto interp = interp::make_interpreter(m.tapes[i]);
        // The numeric core's calls instead of the vector kernels: other IR where the shape calls
        // transcendentals (wave), so its own entry.
        setenv("FRAC_JIT_EXACT_CALLS", "1", 1);
        const bool new_exact_code = modules.insert(jit::emit_llvm(m.tapes[i], {}, false)).second;
        unsetenv("FRAC_JIT_EXACT_CALLS");
        if (m.shape(i).name == "wave") CHECK(new_exact_code);
        auto exact_calls = make_jit_exact_calls(m.tapes[i], {}, cached(dir));
        CHECK(jit::compile_info(*exact_calls)->cache == (new_exact_code ? "miss" : "hit"));
        require_same_results(*exact_calls, *interp, 20261205 + i);
    }
    CHECK(entries(dir.path).size() == modules.size());
}

TEST_CASE("code cache: other options are other entries", "[llvm][cache]") {
    const TempDir dir("frac-cache-keys");
    const Model m = compile(shapes);
    const ir::Tape& t = m.tapes.back();
    auto a = jit::make_jit(t, {}, cached(dir));
    ir::EvalOptions fewer;
    fewer.max_terms = 7;
    auto b = jit::make_jit(t, fewer, cached(dir));
    CHECK(jit::compile_info(*b)->cache == "miss");
    jit::JitConfig scalar = cached(dir);
    scalar.lanes = 1;
    auto c = jit::make_jit(t, {}, scalar);
    CHECK(jit::compile_info(*c)->cache == "miss");
    CHECK(entries(dir.path).size() == 3);
    auto b2 = jit::make_jit(t, fewer, cached(dir));
    CHECK(jit::compile_info(*b2)->cache == "hit");
    require_same_results(*b, *b2, 7);
}

TEST_CASE("code cache: a damaged entry is removed and compiled again", "[llvm][cache]") {
    const TempDir dir("frac-cache-damaged");
    const Model m = compile(shapes);
    const ir::Tape& t = m.tapes.back();
    auto reference = jit::make_jit(t);
    (void)jit::make_jit(t, {}, cached(dir));
    const auto files = entries(dir.path);
    REQUIRE(files.size() == 1);
    const fs::path entry = files[0];
    const auto size = fs::file_size(entry);
    // A flipped byte in the object, a truncation, a zero-length file, a foreign file.
    for (int damage = 0; damage < 4; ++damage) {
        INFO("damage " << damage);
        if (damage == 0) {
            std::fstream f(entry, std::ios::in | std::ios::out | std::ios::binary);
            f.seekp(static_cast<std::streamoff>(size - 100));
            f.put('\x5a');
        } else if (damage == 1) {
            fs::resize_file(entry, size / 2);
        } else if (damage == 2) {
            fs::resize_file(entry, 0);
        } else {
            std::ofstream(entry, std::ios::binary | std::ios::trunc) << "not an object at all";
        }
        auto again = jit::make_jit(t, {}, cached(dir));
        CHECK(jit::compile_info(*again)->cache == "miss");
        require_same_results(*again, *reference, 11 + damage);
        REQUIRE(fs::file_size(entry) == size); // stored afresh
        CHECK(jit::compile_info(*jit::make_jit(t, {}, cached(dir)))->cache == "hit");
    }
}

TEST_CASE("code cache: an unusable directory leaves compiling to LLVM", "[llvm][cache]") {
    const TempDir dir("frac-cache-unusable");
    const Model m = compile(shapes);
    const ir::Tape& t = m.tapes.back();
    auto reference = jit::make_jit(t);
    fs::create_directories(dir.path.parent_path());
    std::ofstream(dir.path) << "a file where the directory should be";
    jit::JitConfig config;
    config.cache_dir = (dir.path / "sub").string();
    auto e = jit::make_jit(t, {}, config);
    CHECK(jit::compile_info(*e)->cache == "miss");
    require_same_results(*e, *reference, 5);
    CHECK(jit::compile_info(*jit::make_jit(t, {}, config))->cache == "miss");
    fs::remove(dir.path);
}

TEST_CASE("code cache: tapes calling external functions are not cached", "[llvm][cache]") {
    const TempDir dir("frac-cache-external");
    const Model m = compile(R"(import "ifs";
shape d(x, y) over [-0.25, 1.25] × [-0.25, 1.25] = dist((x, y), sierpinski) - 0.02;
)");
    REQUIRE(m.tapes[0].externals.size() == 1);
    auto e = jit::make_jit(m.tapes[0], {}, cached(dir));
    CHECK(jit::compile_info(*e)->cache == "off");
    CHECK(entries(dir.path).empty());
}

TEST_CASE("code cache: the least recently used entries go past the size bound", "[llvm][cache]") {
    const TempDir dir("frac-cache-bound");
    std::vector<Model> models;
    for (int k = 1; k <= 6; ++k)
        models.push_back(compile("shape s(x, y) = x * x + y * y - " + std::to_string(k) + ";"));
    jit::JitConfig config = cached(dir);
    (void)jit::make_jit(models[0].tapes[0], {}, config);
    const auto one = fs::file_size(entries(dir.path).at(0));
    config.cache_max_bytes = 4 * one + one / 2; // room for four entries
    for (int k = 1; k < 6; ++k) {
        (void)jit::make_jit(models[static_cast<std::size_t>(k)].tapes[0], {}, config);
        // The first entry is used again each time: it stays while older others go.
        CHECK(jit::compile_info(*jit::make_jit(models[0].tapes[0], {}, config))->cache == "hit");
    }
    std::uintmax_t total = 0;
    for (const fs::path& p : entries(dir.path)) total += fs::file_size(p);
    CHECK(total <= config.cache_max_bytes);
    CHECK(entries(dir.path).size() >= 3);
    CHECK(jit::compile_info(*jit::make_jit(models[5].tapes[0], {}, config))->cache == "hit");
    CHECK(jit::compile_info(*jit::make_jit(models[1].tapes[0], {}, config))->cache == "miss");
}
