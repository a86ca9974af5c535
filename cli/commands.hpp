// The frac subcommands; each returns the process exit code.
#pragma once

#include "cli/session.hpp"
#include "runtime/mesh.hpp"
#include "runtime/picture.hpp"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace frac::cli {

// Limits on the cells of a subdivision and the triangles of a mesh (runtime/limits.hpp): --max-cells and
// --max-triangles, else FRAC_MAX_CELLS and FRAC_MAX_TRIANGLES, else the defaults; 0 here: not given.
struct WorkLimits {
    std::uint64_t cells = 0, triangles = 0;
};
inline constexpr std::uint64_t default_max_triangles = std::uint64_t{1} << 26; // about 1.5 GB with vertices
// A work limit: the flag when given (not 0), else the environment variable `env`, else `fallback`.
std::uint64_t limit_of(std::uint64_t flag, const char* env, std::uint64_t fallback);
// The RunError of a run refused by its cell limit (rt::LimitError): its message, and how to raise the limit.
RunError cell_limit_error(const std::exception& e);

struct RenderOptions {
    std::string shape, box, output, kind = "both", ascii, slice, method;
    int depth = 8, split = 2, size = 512;
    bool force = false; // write an SVG over the size limit
    WorkLimits limits;
};

// --emit=STAGE prints what a stage of the pipeline produced (driver/pipeline.hpp); --time-passes runs
// every stage and prints the time of each on stderr.
int run_check(const std::string& file, const std::string& emit, const std::string& shape, bool time_passes);
int run_eval(const std::string& file, const std::string& shape, const std::string& at, const std::string& box,
             const EngineOptions& engine);
// Largest file `render` and `mesh` write without --force (an estimate, checked before writing).
inline constexpr double output_size_limit = 100e6;
// Refuses (RunError) an output whose estimated size exceeds the limit unless forced.
void check_output_size(const std::string& path, double bytes, bool force);
// --slice AXIS=VALUE (x, y or z; VALUE a constant expression); axis -1 when `text` is empty. Throws
// UsageError when it is malformed.
struct SliceRequest {
    int axis = -1;
    double value = 0;
};
SliceRequest parse_slice(const std::string& text);
// UsageError, quoting `text`, when the plane misses `box`.
void check_slice_within(const SliceRequest& plane, const std::vector<ir::Interval>& box,
                        const std::string& text);
// The 2D section of a 3D cover by the plane (UsageError, quoting `text`, when it misses the cover's box).
rt::Cover section_of(const rt::Cover& cover, const SliceRequest& plane, const std::string& text);
// Writes the SVG picture of a cover after the size check.
void write_cover_svg(const rt::Cover& cover, const std::string& path, rt::PictureKind kind, bool force);
// Writes a mesh (format by extension) after the size check, and says so on stderr.
void write_mesh_file(const rt::Mesh& mesh, const std::string& path, bool force);

int run_render(const std::string& file, const RenderOptions& options, const EngineOptions& engine);
struct MeshOptions {
    std::string shape, box, output, select = "inside";
    std::string layout, cells; // automata: "NxM" or "N" (a curve), and the initial state's arcs in cell order
    int depth = 4, split = 2;
    bool force = false; // write a mesh over the size limit
    WorkLimits limits;
};
int run_mesh(const std::string& file, const MeshOptions& options, const EngineOptions& engine);
int run_dimension(const std::string& file, const std::string& shape, int from, int to, int split,
                  const WorkLimits& limits, const EngineOptions& engine);
struct CompileOptions {
    std::vector<std::string> shapes; // none: every shape of the model
    std::string output, header, cpu = "generic", prefix = "frac_";
    bool emit_llvm = false;
    int max_terms = ir::EvalOptions{}.max_terms;
};
// "" when `path` names an output frac compile can write (.o, .so, .ll), else why not.
std::string check_compile_output(const std::string& path);
int run_compile(const std::string& file, const CompileOptions& options);
// ---- automata (cli/automata.cpp) ----
struct TreeOptions {
    std::string name, output; // no output: the text dump of the tree
    int depth = 3, size = 1024;
    bool matrices = true; // the dump shows each node's composite operator
    bool force = false;   // write an SVG over the size limit
    WorkLimits limits;    // cells: the tree's nodes (default rt::default_max_tree_nodes)
};
// frac tree FILE NAME --depth n [-o FILE.png|FILE.svg]: the evaluation tree, one colour per state.
int run_tree(const std::string& file, const TreeOptions& options);
// frac solve: every bcifs's operators with exact entries and named free parameters (or only `name`'s).
int run_solve(const std::string& file, const std::string& name);
struct ChaosCommandOptions {
    std::string name, output;
    std::uint64_t points = 1'000'000, seed = 1;
    int threads = 1, size = 512;
};
// frac chaos FILE NAME -n POINTS -o FILE.png: the chaos game's density, seeded and reproducible.
int run_chaos(const std::string& file, const ChaosCommandOptions& options);
const front::AutomatonInfo& find_automaton(const front::Compilation& c, const std::string& name);
// Runs `job`, a command on the automaton `info`: an attractor past the range of doubles (rt::RangeError)
// is reported at the automaton (file:line:col, the line and a caret) with exit code 1.
int on_automaton(const front::Compilation& c, const front::AutomatonInfo& info,
                 const std::function<int()>& job);
// frac mesh of an ifs or cifs: its quad patch tessellated (.stl, .obj, .ply) or its curve as a polyline
// (.svg, .obj).
int mesh_automaton(const front::AutomatonInfo& a, const MeshOptions& options);
// The similarity dimension with its proven bracket, or box counting of the chaos-game cover.
int automaton_dimension(const front::AutomatonInfo& a, int from, int to);

// frac analyze FILE NAME: the verified spectrum of every subdivision operator (an arc from a barycentric
// state to itself), the behaviour at its fixed point, and the junctions between pieces.
int run_analyze(const std::string& file, const std::string& name);

// frac render for an ifs or cifs (--method tree, chaos or cover).
int render_automaton(const front::AutomatonInfo& a, const RenderOptions& options);
// frac render for a map of the plane (fn henon(p) = ...): the cell-graph cover of its attractor in --box.
int render_map(front::Compilation& c, const front::Item& map, const RenderOptions& options,
               const EngineOptions& engine);

// Runs the print statements (when `prints`) and the tests of each file; prints "N passed, N failed".
int run_tests(const std::vector<std::string>& files, bool prints, const EngineOptions& engine);

// ---- fit of surfaces and images (cli/fit_surface.cpp) ----
struct FitSurfaceOptions {
    std::string data, output, method = "lm", patches = "3x3", name = "fitted";
    int controls = 4, depth = 0, iterations = 100, bits = 16; // depth 0: chosen from the data's size
    double seconds = 0, target_psnr = 0;
    bool fit_positions = false; // --fit-xy: the control points' x, y are parameters too (3-D residuals)
};
// The surface fit's own options (the data file, -o, --method, --quantize and --name are the command's).
void add_fit_surface_options(CLI::App* fit, FitSurfaceOptions& options);
// Whether `frac fit` without --method takes `path` for a surface: a PNG, or a CSV whose first row has more
// than 3 fields (a grid of heights; samples of a function or curve have 2 or 3).
bool is_surface_data(const std::string& path);
// frac fit DATA -o MODEL.frac --method lm: a projected IFS fitted to a height grid or a grey image.
int run_fit_surface(const FitSurfaceOptions& options);

} // namespace frac::cli
