// frac compile end to end: the real binary compiles models, the system C compiler links them, and the
// results must equal the JIT's bit for bit (docs/c-abi.md).
#include "tests/unit/llvm/engines.hpp"

#include <cfenv>
#include <cstdio>
#include <cstdlib>
#include <dlfcn.h>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <sys/wait.h>
#include <thread>

namespace {

namespace fs = std::filesystem;
using frac::ir::Interval;
using frac::test::hex;
using frac::test::same;

struct Run {
    int status = -1;
    std::string out, err;
};

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// Runs a shell command line; stdout and stderr come back separately.
Run run(const std::string& command, const fs::path& dir) {
    const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
    const std::string line = command + " >" + out.string() + " 2>" + err.string();
    const int raw = std::system(line.c_str());
    Run r;
    r.status = raw != -1 && WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
}

fs::path work_dir(const std::string& name) {
    const fs::path d = fs::path(FRAC_TEST_WORK_DIR) / name;
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

std::string frac_compile(const std::string& args) {
    return std::string(FRAC_BINARY) + " compile " + args;
}

const std::string example_dir = std::string(FRAC_SOURCE_DIR) + "/examples/aot";

// JIT evaluators of every shape of a model file.
struct JitModel {
    std::unique_ptr<frac::front::Compilation> c;
    std::map<std::string, std::unique_ptr<frac::ir::Evaluator>> eval;
    std::map<std::string, const frac::front::ShapeInfo*> info;
};
JitModel jit_model(const std::string& path, const frac::ir::EvalOptions& options = {}) {
    JitModel m;
    m.c = frac::driver::compile_file(path);
    REQUIRE(m.c->ok());
    for (const frac::front::ShapeInfo& s : m.c->module.shapes) {
        m.eval[s.name] =
            frac::jit::make_jit(frac::ir::build_tape(m.c->module.graph, s.root, s.dimension), options);
        m.info[s.name] = &s;
    }
    return m;
}

// Checks each line of the example's output against the JIT: returns how many lines were checked.
std::size_t check_example_output(const std::string& output, JitModel& jit) {
    std::istringstream lines(output);
    std::string line;
    std::size_t checked = 0;
    while (std::getline(lines, line)) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream words(line.substr(0, line.find('#')));
        std::string kind, shape, w;
        words >> kind >> shape;
        std::vector<double> in, out;
        bool after = false;
        while (words >> w) {
            if (w == "=") {
                after = true;
                continue;
            }
            char* end = nullptr;
            const double v = std::strtod(w.c_str(), &end);
            INFO(line);
            REQUIRE(*end == '\0');
            (after ? out : in).push_back(v);
        }
        INFO(line);
        REQUIRE(jit.eval.count(shape) == 1);
        frac::ir::Evaluator& e = *jit.eval[shape];
        const auto d = static_cast<std::size_t>(e.dimension());
        if (kind == "point" || kind == "points") {
            REQUIRE(in.size() == d);
            REQUIRE(out.size() == 1);
            const double expected = e.eval_point(in.data());
            INFO("JIT " << hex(expected));
            CHECK(same(out[0], expected));
        } else {
            REQUIRE((kind == "box" || kind == "boxes"));
            REQUIRE(in.size() == 2 * d);
            REQUIRE(out.size() == 2);
            std::vector<Interval> box;
            for (std::size_t k = 0; k < d; ++k) box.push_back({in[2 * k], in[2 * k + 1]});
            const Interval expected = e.eval_box(box.data());
            INFO("JIT " << hex(expected));
            CHECK(same(Interval{out[0], out[1]}, expected));
        }
        ++checked;
    }
    return checked;
}

// The C ABI of one shape, looked up in a loaded library.
struct CShape {
    using Point = double (*)(const double*);
    using Points = void (*)(const double*, std::size_t, double*);
    using Box = Interval (*)(const Interval*);
    using Boxes = void (*)(const Interval*, std::size_t, Interval*);
    Point point;
    Points points;
    Box box;
    Boxes boxes;
    int (*dimension)();
    const Interval* (*default_box)();
};

template <class F>
F symbol(void* lib, const std::string& name) {
    void* p = dlsym(lib, name.c_str());
    INFO(name);
    REQUIRE(p != nullptr);
    return reinterpret_cast<F>(p);
}

CShape lookup(void* lib, const std::string& prefix, const std::string& shape) {
    const std::string s = prefix + shape + "_";
    return {
        symbol<CShape::Point>(lib, s + "eval_point"), symbol<CShape::Points>(lib, s + "eval_points"),
        symbol<CShape::Box>(lib, s + "eval_box"),     symbol<CShape::Boxes>(lib, s + "eval_boxes"),
        symbol<int (*)()>(lib, s + "dimension"),      symbol<const Interval* (*)()>(lib, s + "default_box")};
}

struct Library {
    explicit Library(const fs::path& p) : handle(dlopen(p.c_str(), RTLD_NOW | RTLD_LOCAL)) {
        INFO((handle ? "" : dlerror()));
        REQUIRE(handle != nullptr);
    }
    ~Library() {
        if (handle) dlclose(handle);
    }
    void* handle;
};

// Every shape of `model` compiled into a shared library against the JIT on random boxes and points,
// one by one and in batches, with the caller in a rounding mode other than the one the call needs.
// Returns the number of shapes compared.
std::size_t points_checked_against_enclosures = 0;

std::size_t compare_library(const fs::path& dir, const std::string& model, const std::string& flags,
                            const frac::ir::EvalOptions& options, std::uint64_t seed,
                            std::size_t enclosure_points = 0) {
    const fs::path so = dir / "model.so";
    const Run c = run(frac_compile(model + " -o " + so.string() + " " + flags), dir);
    INFO(c.err);
    REQUIRE(c.status == 0);
    Library lib(so);
    JitModel jit = jit_model(model, options);
    REQUIRE(!jit.eval.empty());
    for (auto& [name, e] : jit.eval) {
        INFO("shape " << name << ", frac compile " << flags);
        const CShape f = lookup(lib.handle, "frac_", name);
        const frac::front::ShapeInfo& s = *jit.info[name];
        const int d = s.dimension;
        REQUIRE(f.dimension() == d);
        for (int k = 0; k < d; ++k) CHECK(same(f.default_box()[k], s.box[static_cast<std::size_t>(k)]));
        frac::test::BoxMaker mk(seed);
        const std::size_t count = 400;
        std::vector<Interval> boxes, jit_boxes(count), c_boxes(count);
        std::vector<double> points, jit_points(count), c_points(count);
        std::vector<std::size_t> empty;
        for (std::size_t i = 0; i < count; ++i) {
            std::vector<Interval> b = mk.box(s.box);
            if (d > 0 && i % 37 == 5) {
                b[static_cast<std::size_t>(mk.pick(d))] = Interval::empty();
                empty.push_back(i);
            }
            boxes.insert(boxes.end(), b.begin(), b.end());
            const std::vector<double> p = mk.point(s.box);
            points.insert(points.end(), p.begin(), p.end());
        }
        e->eval_boxes(boxes.data(), count, jit_boxes.data());
        e->eval_points(points.data(), count, jit_points.data());
        std::size_t box_mismatches = 0, point_mismatches = 0;
        std::string first;
        const int modes[] = {FE_TONEAREST, FE_DOWNWARD, FE_UPWARD, FE_TOWARDZERO};
        for (std::size_t i = 0; i < count; ++i) {
            const int mode = modes[i % 4];
            std::fesetround(mode);
            const Interval r = f.box(&boxes[i * static_cast<std::size_t>(d)]);
            const double v = f.point(&points[i * static_cast<std::size_t>(d)]);
            const int after = std::fegetround();
            std::fesetround(FE_TONEAREST);
            REQUIRE(after == mode); // the caller's mode comes back
            const bool is_empty_box = std::find(empty.begin(), empty.end(), i) != empty.end();
            const Interval want = is_empty_box ? Interval::empty() : jit_boxes[i];
            if (!same(r, want)) {
                ++box_mismatches;
                if (first.empty())
                    first = "box " + frac::test::hex_box(&boxes[i * static_cast<std::size_t>(d)], d) +
                            ": compiled " + hex(r) + ", JIT " + hex(want);
            }
            if (!same(v, jit_points[i])) {
                ++point_mismatches;
                if (first.empty())
                    first =
                        "point " + std::to_string(i) + ": compiled " + hex(v) + ", JIT " + hex(jit_points[i]);
            }
        }
        std::fesetround(FE_DOWNWARD);
        f.boxes(boxes.data(), count, c_boxes.data());
        f.points(points.data(), count, c_points.data());
        REQUIRE(std::fegetround() == FE_DOWNWARD);
        std::fesetround(FE_TONEAREST);
        for (std::size_t i = 0; i < count; ++i) {
            const bool is_empty_box = std::find(empty.begin(), empty.end(), i) != empty.end();
            if (!same(c_boxes[i], is_empty_box ? Interval::empty() : jit_boxes[i])) ++box_mismatches;
            if (!same(c_points[i], jit_points[i])) ++point_mismatches;
        }
        // A compiled point value lies in the compiled enclosure of its point (NaN where it is empty),
        // at the points above and `enclosure_points` more.
        std::size_t outside = 0;
        for (std::size_t i = 0; i < count + enclosure_points; ++i) {
            const std::vector<double> p =
                i < count
                    ? std::vector<double>(
                          points.begin() + static_cast<std::ptrdiff_t>(i * static_cast<std::size_t>(d)),
                          points.begin() + static_cast<std::ptrdiff_t>((i + 1) * static_cast<std::size_t>(d)))
                    : mk.point(s.box);
            std::vector<Interval> thin(p.begin(), p.end());
            const Interval r = f.box(thin.data());
            const double v = f.point(p.data());
            ++points_checked_against_enclosures;
            const bool in = r.is_empty() ? std::isnan(v) : r.lo <= v && v <= r.hi;
            if (!in && ++outside == 1 && first.empty())
                first = "point " + std::to_string(i) + ": compiled " + hex(v) + " outside " + hex(r);
        }
        INFO(first);
        CHECK(box_mismatches == 0);
        CHECK(point_mismatches == 0);
        CHECK(outside == 0);
    }
    return jit.eval.size();
}

} // namespace

TEST_CASE(
    "the example C program linked with a compiled object and a shared library prints the JIT's results") {
    const fs::path dir = work_dir("example");
    const std::string model = example_dir + "/model.frac";
    for (const char* out : {"model.o", "model.so"}) {
        const Run r = run(
            frac_compile(model + " -o " + (dir / out).string() + " --header " + (dir / "model.h").string()),
            dir);
        INFO(r.err);
        REQUIRE(r.status == 0);
    }
    const std::string cc = std::string(FRAC_C_COMPILER) + " -std=c99 -Wall -Wextra -Werror -I" +
                           dir.string() + " " + example_dir + "/main.c ";
    Run build =
        run(cc + (dir / "model.o").string() + " -lstdc++ -lm -o " + (dir / "main_static").string(), dir);
    INFO(build.err);
    REQUIRE(build.status == 0);
    build = run(cc + (dir / "model.so").string() + " -Wl,-rpath," + dir.string() + " -o " +
                    (dir / "main_shared").string(),
                dir);
    INFO(build.err);
    REQUIRE(build.status == 0);

    const Run with_object = run((dir / "main_static").string(), dir);
    const Run with_library = run((dir / "main_shared").string(), dir);
    REQUIRE(with_object.status == 0);
    REQUIRE(with_library.status == 0);
    CHECK(with_object.out == with_library.out);

    JitModel jit = jit_model(model);
    const std::size_t checked = check_example_output(with_object.out, jit);
    const Run tests = run(std::string(FRAC_BINARY) + " test " + model, dir); // the model's own test block
    INFO(tests.out << tests.err);
    CHECK(tests.status == 0);
    CHECK(checked == 5 + 4 + 16 + 16 + 2 + 1 + 64); // every evaluation main.c makes
}

TEST_CASE("compiled standard-library shapes equal the JIT bit for bit") {
    std::uint64_t seed = 11;
    std::size_t shapes = 0, compared = 0;
    for (const std::string& name : frac::test::stdlib_files()) {
        const std::size_t n = frac::test::compile("import \"" + name + "\";").tapes.size();
        if (n == 0) continue; // a library of functions only
        shapes += n;
        const fs::path dir = work_dir("stdlib_" + name);
        const fs::path model = dir / (name + "_all.frac");
        std::ofstream(model) << "import \"" << name << "\";\n";
        compared += compare_library(dir, model.string(), "", {}, ++seed, 4000);
    }
    CHECK(shapes >= 10);
    CHECK(compared == shapes);
    CHECK(points_checked_against_enclosures >= 100000);
}

TEST_CASE("compiled code follows --max-terms and --cpu like the JIT") {
    frac::ir::EvalOptions few;
    few.max_terms = 3;
    compare_library(work_dir("max_terms"), example_dir + "/model.frac", "--max-terms 3", few, 5);
    compare_library(work_dir("native"), example_dir + "/model.frac", "--cpu=native", {}, 6);
    // AVX2 without AVX-512: constrained intrinsics, 4 boxes per vector (runs on this host too).
    if (__builtin_cpu_supports("avx2"))
        compare_library(work_dir("x86_64_v3"), example_dir + "/model.frac", "--cpu=x86-64-v3", {}, 7);
}

TEST_CASE("a compiled object exports only its functions: two models link into one program") {
    const fs::path dir = work_dir("two_models");
    const std::string model = example_dir + "/model.frac";
    for (const char* prefix : {"a_", "b_"}) {
        const Run r =
            run(frac_compile(model + " carpet -o " + (dir / (std::string(prefix) + "model.o")).string() +
                             " --prefix " + prefix + " --header " +
                             (dir / (std::string(prefix) + "model.h")).string()),
                dir);
        INFO(r.err);
        REQUIRE(r.status == 0);
        const Run nm = run("nm -g --defined-only " + (dir / (std::string(prefix) + "model.o")).string(), dir);
        REQUIRE(nm.status == 0);
        std::istringstream lines(nm.out);
        std::string line;
        int exported = 0;
        while (std::getline(lines, line)) {
            INFO(line);
            CHECK(line.find(std::string(" ") + prefix + "carpet_") != std::string::npos);
            ++exported;
        }
        CHECK(exported == 6);
    }
    std::ofstream(dir / "two.c")
        << "#include \"a_model.h\"\n#include \"b_model.h\"\n#include <stdio.h>\n"
           "int main(void) {\n"
           "    const double p[2] = {0.5, 0.5};\n"
           "    printf(\"%a %a\\n\", a_carpet_eval_point(p), b_carpet_eval_point(p));\n"
           "    return a_carpet_dimension() + b_carpet_dimension() == 4 ? 0 : 1;\n"
           "}\n";
    Run build = run(std::string(FRAC_C_COMPILER) + " -std=c99 -Wall -Werror -I" + dir.string() + " " +
                        (dir / "two.c").string() + " " + (dir / "a_model.o").string() + " " +
                        (dir / "b_model.o").string() + " -lstdc++ -lm -o " + (dir / "two").string(),
                    dir);
    INFO(build.err);
    REQUIRE(build.status == 0);
    const Run r = run((dir / "two").string(), dir);
    REQUIRE(r.status == 0);
    JitModel jit = jit_model(model);
    const double p[2] = {0.5, 0.5};
    const std::string v = hex(jit.eval["carpet"]->eval_point(p));
    CHECK(r.out == v + " " + v + "\n");
}

TEST_CASE("frac compile reports bad input clearly") {
    const fs::path dir = work_dir("errors");
    const std::string model = example_dir + "/model.frac";
    Run r = run(frac_compile(model + " no_such_shape -o " + (dir / "m.o").string()), dir);
    CHECK(r.status == 64); // a command-line mistake
    CHECK(r.err.find("no shape 'no_such_shape' in the model (shapes: carpet, wavy_ball)") !=
          std::string::npos);
    r = run(frac_compile(model + " -o " + (dir / "m.dll").string()), dir);
    CHECK(r.status == 64);
    CHECK(r.err.find("use .o (object), .so (shared library) or .ll (LLVM IR)") != std::string::npos);
    r = run(frac_compile(model + " -o " + (dir / "missing" / "m.so").string()), dir);
    CHECK(r.status == 64); // an output that cannot be written, found before the work
    CHECK(r.err.find("cannot write '" + (dir / "missing" / "m.so").string() + "'") != std::string::npos);
    r = run(frac_compile(model + " --cpu=no-such-cpu -o " + (dir / "m.o").string()), dir);
    CHECK(r.status == 1);
    CHECK(r.err.find("LLVM knows no CPU 'no-such-cpu'") != std::string::npos);
    CHECK(!fs::exists(dir / "m.o"));
    std::ofstream(dir / "bad.frac") << "shape s(x, y) over [0, 1] × [0, 1] = x +;\n";
    r = run(frac_compile((dir / "bad.frac").string() + " -o " + (dir / "m.o").string()), dir);
    CHECK(r.status == 65);
    CHECK(r.err.find("bad.frac:1:") != std::string::npos);
    CHECK(!fs::exists(dir / "m.o"));
    r = run(frac_compile(model + " -o " + (dir / "m.ll").string()), dir);
    CHECK(r.status == 0);
    CHECK(slurp(dir / "m.ll").find("define double @frac_carpet_eval_point(ptr") != std::string::npos);
}

TEST_CASE("compiled functions are reentrant: threads in different rounding modes at once") {
    const fs::path dir = work_dir("threads");
    const std::string model = example_dir + "/model.frac";
    const fs::path so = dir / "model.so";
    const Run c = run(frac_compile(model + " carpet -o " + so.string()), dir);
    INFO(c.err);
    REQUIRE(c.status == 0);
    Library lib(so);
    const CShape f = lookup(lib.handle, "frac_", "carpet");
    JitModel jit = jit_model(model);
    frac::test::BoxMaker mk(99);
    const std::vector<Interval> range = {{0, 1}, {0, 1}};
    const std::size_t count = 2000;
    std::vector<Interval> boxes, expected_boxes(count);
    std::vector<double> points, expected_points(count);
    for (std::size_t i = 0; i < count; ++i) {
        const std::vector<Interval> b = mk.box(range);
        boxes.insert(boxes.end(), b.begin(), b.end());
        const std::vector<double> p = mk.point(range);
        points.insert(points.end(), p.begin(), p.end());
    }
    jit.eval["carpet"]->eval_boxes(boxes.data(), count, expected_boxes.data());
    jit.eval["carpet"]->eval_points(points.data(), count, expected_points.data());
    const int modes[] = {FE_TONEAREST, FE_DOWNWARD, FE_UPWARD, FE_TOWARDZERO};
    std::vector<std::size_t> mismatches(4, 0);
    std::vector<int> modes_after(4, -1);
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t)
        threads.emplace_back([&, t] {
            std::fesetround(modes[t]);
            std::vector<Interval> out(count);
            std::vector<double> values(count);
            for (int round = 0; round < 20; ++round) {
                f.boxes(boxes.data(), count, out.data());
                f.points(points.data(), count, values.data());
                for (std::size_t i = 0; i < count; ++i)
                    mismatches[static_cast<std::size_t>(t)] +=
                        !same(out[i], expected_boxes[i]) + !same(values[i], expected_points[i]);
            }
            modes_after[static_cast<std::size_t>(t)] = std::fegetround();
        });
    for (std::thread& th : threads) th.join();
    for (int t = 0; t < 4; ++t) {
        INFO("thread " << t);
        CHECK(mismatches[static_cast<std::size_t>(t)] == 0);
        CHECK(modes_after[static_cast<std::size_t>(t)] == modes[t]);
    }
}

TEST_CASE("a compiled model that calls dist carries its automaton and gives the JIT's enclosures") {
    const fs::path dir = work_dir("dist");
    const fs::path model = dir / "dist.frac";
    // A euclidean IFS, one composed with a Rvachev shape by CSG, and a barycentric CIFS drawn through
    // its control points.
    std::ofstream(model)
        << "import \"ifs\";\nimport \"fractals\";\n"
           "shape ring(x, y) over [-0.25, 1.25] × [-0.25, 1.25] = dist((x, y), sierpinski) - "
           "0.01;\n"
           "shape fused(x, y) over [0, 1] × [0, 1] = dist((x, y), sierpinski) - 0.01 | carpet(x, "
           "y);\n"
           "shape curve(x, y) over [-1, 4] × [-1, 3] = dist((x, y), quadratic_bspline) - 0.05;\n";
    CHECK(compare_library(dir, model.string(), "", {}, 23, 100) >= 3); // and the imported shapes

    // The same object twice in one process: each library rebuilds its own automaton, and unloading one
    // leaves the other working.
    const fs::path so = dir / "model.so";
    Library first(so);
    const CShape f = lookup(first.handle, "frac_", "ring");
    // (0.5, 0.5) lies (0.5 - sqrt(3)/4) / 2 from the Sierpinski triangle
    // (tests/lang/automata/dist_test.frac).
    const double centre[2] = {0.5, 0.5};
    const double truth = (0.5 - std::sqrt(3.0) / 4) / 2 - 0.01;
    const Interval thin[2] = {Interval(0.5), Interval(0.5)};
    const Interval r = f.box(thin);
    CHECK(r.lo <= truth);
    CHECK(truth <= r.hi);
    CHECK(r.hi - r.lo < 2e-6);
    CHECK(std::fabs(f.point(centre) - truth) < 1e-6);
    {
        const fs::path copy = dir / "copy.so";
        fs::copy_file(so, copy);
        Library second(copy);
        CHECK(same(lookup(second.handle, "frac_", "ring").box(thin), r));
    }
    CHECK(same(f.box(thin), r));
}
