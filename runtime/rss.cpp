#include "runtime/rss.hpp"

#include "support/huge_pages.hpp"

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/global_control.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>
#include <oneapi/tbb/task_group.h>
#include <thread>

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <unordered_map>
#include <utility>

namespace frac::rt {

namespace {

// The cell budget (RssOptions::max_cells): the growth of the levels is trusted once a level has this
// many undecided cells (before, every cell of a coarse level may be undecided).
constexpr std::size_t min_cells_for_growth = 4096;

std::string byte_text(double bytes) {
    if (bytes >= 1e12) return fmt::format("{:.3g} TB", bytes / 1e12);
    if (bytes >= 1e9) return fmt::format("{:.3g} GB", bytes / 1e9);
    return fmt::format("{:.3g} MB", bytes / 1e6);
}

using Clock = std::chrono::steady_clock;

// Position of a cell in the grid of its level, and the function it evaluates (0: the shape's, else
// a pruned one, Runner::variants_). The coordinates are those of Evaluator::eval_cells with a stride of
// pos_stride.
struct Pos {
    std::uint32_t ix, iy, iz;
    std::uint32_t variant = 0;
};
constexpr std::size_t pos_stride = sizeof(Pos) / sizeof(std::uint32_t);
static_assert(sizeof(Pos) == 4 * sizeof(std::uint32_t) && offsetof(Pos, iy) == 4 && offsetof(Pos, iz) == 8);

using ir::CellVerdict;
using ir::classify; // the header's rules

void validate(const ir::Evaluator& f, const std::vector<Interval>& root, const RssOptions& o) {
    const int d = static_cast<int>(root.size());
    if (d != 2 && d != 3)
        throw std::invalid_argument(fmt::format("subdivide: the root box has {} axes; it needs 2 or 3", d));
    if (f.dimension() != d)
        throw std::invalid_argument(fmt::format(
            "subdivide: the shape takes {} coordinates but the root box has {} axes", f.dimension(), d));
    for (int a = 0; a < d; ++a) {
        const Interval x = root[static_cast<std::size_t>(a)];
        if (!(std::isfinite(x.lo) && std::isfinite(x.hi) && x.lo < x.hi && std::isfinite(x.hi - x.lo)))
            throw std::invalid_argument(
                fmt::format("subdivide: root axis {} is [{}, {}]; it needs finite bounds with lo < hi, and a "
                            "width below the largest double",
                            a, x.lo, x.hi));
    }
    if (o.split < 2 || o.split > 4)
        throw std::invalid_argument(fmt::format("subdivide: split {} is out of range [2, 4]", o.split));
    const int max_depth = o.max_depth > 0 ? o.max_depth : d == 2 ? max_depth_2d : max_depth_3d;
    if (o.depth < 0 || o.depth > max_depth)
        throw std::invalid_argument(fmt::format(
            "subdivide: depth {} is out of range [0, {}] in {}D: lower --depth, or raise the limit with "
            "FRAC_MAX_DEPTH=N",
            o.depth, max_depth, d));
    if (grid::ipow(o.split, o.depth) > (std::uint64_t{1} << 32))
        throw std::invalid_argument(fmt::format(
            "subdivide: split^depth = {}^{} exceeds 2^32 cells per axis (cell positions are 32-bit)", o.split,
            o.depth));
    if (o.batch == 0) throw std::invalid_argument("subdivide: batch must be at least 1");
    if (o.threads < 0 || o.threads > 1024)
        throw std::invalid_argument("subdivide: threads must be in [0, 1024]");
}

// A function cells evaluate (Runner::variants_): the shape's or a pruned one, with an evaluator per thread.
struct Variant {
    std::shared_ptr<ir::Evaluator> function;
    std::vector<std::unique_ptr<ir::Evaluator>> owned;
    std::vector<ir::Evaluator*> workers; // one per thread
    double instructions = 0;             // of its function
    bool may_specialize = false;         // its function can be pruned further
    bool ask_this_level = false;         // ... and its evaluator may prune for this level's cells
    bool prune_in_chunks = false;        // ... by each thread's evaluator as it evaluates
};

// A chunk of a batch: cells [begin, end) of the batch.
struct Chunk {
    std::size_t begin, end;
    // What its cells gave: counts, and (from begin in Batch::undecided) its undecided cells; below
    // the depth also (from begin in Batch::cells, compacted) the undecided cells themselves, and (from
    // begin in Batch::rows) where rows of them start after the first.
    std::uint64_t inside = 0, outside = 0, undecided = 0, pruned_cells = 0, rows = 0;
    double instructions = 0; // of the functions its cells evaluated
};

// Cells [first, first + cells.size()) of a level, in row-major order, and what evaluating them gives.
struct Batch {
    std::uint64_t first = 0;
    std::vector<Pos> cells;               // made by the chunks
    std::vector<CellVerdict> verdicts;    // ... and what they gave
    std::vector<std::uint32_t> undecided; // each chunk's undecided cells, from its begin
    std::vector<std::uint32_t> rows;      // each chunk's row starts among them, from its begin
    // Pruned functions asked for by the chunks (for variants whose evaluators answer independently of
    // each other: the cells of a level ask on every thread at once).
    std::vector<std::shared_ptr<ir::Evaluator>> pruned;
    std::vector<Chunk> chunks;
    tbb::task_group group; // evaluating it in the background
    bool running = false;
};

// The children of one row of parents (in 3D: of one row, in child layer cz): `count` parents from
// parents_[parent] give count * split^2 consecutive cells of the level, from cell `first`.
struct ChildBlock {
    std::size_t parent;
    std::uint64_t count;
    std::uint32_t cz;
    std::uint64_t first;
};

// What a level's cells need of their variant, fixed for the level (pruning requests add variants for
// the next level while it runs).
struct LevelVariant {
    ir::Evaluator* const* workers; // one per thread
    bool prune;                    // undecided cells ask for pruned functions in the chunks
    double instructions;           // of its function
};

// Per-thread room: a chunk's cells sorted by variant (a chunk whose cells evaluate several), and the
// boxes and enclosures of cells evaluated box by box (pruning in the chunks, or no grid table).
struct ChunkScratch {
    std::vector<std::uint32_t> order;
    std::vector<Pos> cells;
    std::vector<CellVerdict> verdicts;
    std::vector<Interval> boxes, out;
};

ChunkScratch& scratch() {
    thread_local ChunkScratch s;
    return s;
}

// Batches of a level in flight on several threads: one filled while the others evaluate. The thread
// that takes a batch's verdicts waits only for the oldest, so the other threads have the newer ones
// to evaluate meanwhile (with two in flight they could run dry).
constexpr int batches_in_flight = 3;

// Buffers a run leaves to the next run on its thread (covers in a loop: benchmarks, tests, a library's
// caller), so that the next one neither allocates nor faults them in again; each up to
// kept_buffer_bytes, so that a deep cover does not hold its memory afterwards.
struct KeptBuffers {
    std::vector<Pos> frontiers[2];
    std::vector<Pos> cells[batches_in_flight];
    std::vector<CellVerdict> verdicts[batches_in_flight];
    std::vector<std::uint32_t> undecided[batches_in_flight];
    std::vector<std::uint32_t> rows[batches_in_flight];
};
constexpr std::size_t kept_buffer_bytes = std::size_t{16} << 20;

KeptBuffers& kept_buffers() {
    thread_local KeptBuffers k;
    return k;
}

template <class T>
void take_buffer(std::vector<T>& to, std::vector<T>& from) {
    to = std::move(from);
    from = {};
    to.clear();
}

template <class T>
void leave_buffer(std::vector<T>& to, std::vector<T>& from) {
    if (from.capacity() * sizeof(T) > kept_buffer_bytes) return;
    from.clear();
    to = std::move(from);
}

// One run of the subdivision. Holds the frontier of the current level (its undecided cells) and
// the batch being filled, nothing else unless keep_cells.
class Runner {
public:
    Runner(ir::Evaluator& f, RssResult& r)
        : f_(f), r_(r), d_(r.dimension()),
          threads_(r.options.threads > 0
                       ? r.options.threads
                       : std::max(1, static_cast<int>(std::thread::hardware_concurrency()))),
          arena_(threads_) {
        num::UpwardRounding up;
        for (const Interval& x : r_.root) width_.push_back(grid::width(x));
        for (int t = 1; t < threads_; ++t) clones_.push_back(f_.clone());
        variants_.emplace_back();
        variants_[0].workers.push_back(&f_);
        for (const auto& c : clones_) variants_[0].workers.push_back(c.get());
        variants_[0].instructions = static_cast<double>(f_.instruction_count());
        variants_[0].may_specialize = f_.may_specialize();
        variants_[0].prune_in_chunks = f_.may_specialize() && f_.specializes_independently();
        // Each thread gets a batch of its own per flush.
        flush_at_ = r_.options.batch * static_cast<std::size_t>(threads_);
        KeptBuffers& k = kept_buffers();
        take_buffer(next_, k.frontiers[0]);
        take_buffer(parents_, k.frontiers[1]);
        for (int i = 0; i < batches_in_flight; ++i) {
            take_buffer(batches_[i].cells, k.cells[i]);
            take_buffer(batches_[i].verdicts, k.verdicts[i]);
            take_buffer(batches_[i].undecided, k.undecided[i]);
            take_buffer(batches_[i].rows, k.rows[i]);
        }
    }

    ~Runner() {
        // A batch may still run when an exception (a limit, a failed evaluation) ends the run.
        for (Batch& b : batches_)
            if (b.running) {
                try {
                    arena_.execute([&] { b.group.wait(); });
                } catch (...) {
                }
            }
        for (const Variant& v : variants_) count_work(v);
        KeptBuffers& k = kept_buffers();
        leave_buffer(k.frontiers[0], next_);
        leave_buffer(k.frontiers[1], parents_);
        for (int i = 0; i < batches_in_flight; ++i) {
            leave_buffer(k.cells[i], batches_[i].cells);
            leave_buffer(k.verdicts[i], batches_[i].verdicts);
            leave_buffer(k.undecided[i], batches_[i].undecided);
            leave_buffer(k.rows[i], batches_[i].rows);
        }
    }

    void run() {
        const int depth = r_.depth;
        r_.levels.assign(static_cast<std::size_t>(depth) + 1, LevelCounts{});
        r_.prune_levels.assign(static_cast<std::size_t>(depth) + 1, PruneLevel{});
        last_progress_ = Clock::now();

        start_level(0);
        evaluate_level();
        for (int k = 1; k <= depth; ++k) {
            check_budget(k, next_.size());
            // The work left, once the growth is told by enough cells (an engine that waits to compile
            // compiles when that work repays it).
            if (next_.size() >= min_cells_for_growth) f_.foresee(cells_foreseen(k, next_.size()));
            // The two frontiers swap buffers: no level regrows (and faults in) a fresh one.
            parents_.swap(next_);
            next_.clear();
            parent_rows_.swap(next_rows_);
            next_rows_.clear();
            release_unused(parents_);
            start_level(k);
            // Room for the level's undecided cells at once (growing by doubling would copy and
            // fault in the frontier several times): the share undecided at the last level, plus 1/8.
            const LevelCounts& before = r_.levels[static_cast<std::size_t>(k - 1)];
            const double share =
                static_cast<double>(before.undecided) / static_cast<double>(before.evaluated);
            const double children = static_cast<double>(parents_.size()) * std::pow(r_.split, d_);
            const double foreseen_undecided = children * std::min(1.0, share * 1.125);
            if (k < depth) support::reserve_huge(next_, static_cast<std::size_t>(foreseen_undecided));
            // Kept cells: room for this level's and the next level's (foreseen the same way) at once,
            // and once the growth is told by enough cells, for all levels foreseen to the depth (plus
            // 1/8; at most the cell limit). Grown by doubling, the copy and the page faults of a
            // regrowth came all at once on this thread: 0.2 s of a depth-12 carpet cover (12.7 million
            // cells, 200 MB), on one thread or two; room for one level ahead still copied the cells kept
            // so far at every other level (5 ms a cover).
            const std::size_t kept_needed = r_.cells.size() + level_cells_;
            if (r_.options.keep_cells && r_.cells.capacity() < kept_needed) {
                double room = static_cast<double>(kept_needed) +
                              (k < depth ? foreseen_undecided * std::pow(r_.split, d_) : 0);
                if (parents_.size() >= min_cells_for_growth)
                    room = std::max(room, 1.125 * (static_cast<double>(r_.cells.size()) +
                                                   cells_foreseen(k, parents_.size())));
                const std::uint64_t limit =
                    r_.options.max_cells > 0 ? r_.options.max_cells : default_max_cells;
                room = std::min(room, static_cast<double>(std::max<std::uint64_t>(limit, kept_needed)));
                support::reserve_huge(r_.cells, static_cast<std::size_t>(room));
            }
            evaluate_level();
        }
        for (const LevelCounts& lc : r_.levels) {
            r_.inside += lc.inside;
            r_.outside += lc.outside;
        }
        r_.boundary = r_.levels[static_cast<std::size_t>(depth)].undecided;
        r_.subdivided = r_.evaluated - r_.inside - r_.outside - r_.boundary;
        r_.specializations = created_;
    }

private:
    // Before level k, whose `parents` undecided cells give exactly parents * split^d cells: refuses when
    // that passes max_cells, or when the growth of the last level, carried on to the depth, foretells a
    // total past max_cells. So a run stops before it has spent the memory, mostly after a few cheap
    // levels; a growth that slows down later makes the estimate high (raise the limit to go on).
    void check_budget(int k, std::size_t parents) const {
        const std::uint64_t limit = r_.options.max_cells;
        if (limit == 0) return;
        const double per_parent = std::pow(static_cast<double>(r_.split), d_);
        const double next = static_cast<double>(parents) * per_parent;
        const double done = static_cast<double>(r_.evaluated);
        const double estimate = done + cells_foreseen(k, parents);
        const bool exact = done + next > static_cast<double>(limit);
        const bool foretold = parents >= min_cells_for_growth && estimate > static_cast<double>(limit);
        if (!exact && !foretold) return;
        const double bytes =
            estimate * (r_.options.keep_cells ? sizeof(Cell) + sizeof(Pos) / 4.0 : sizeof(Pos) / 4.0);
        throw LimitError(fmt::format("depth {}: about {:.3g} cells to evaluate (about {}), more than the "
                                     "limit of {} cells (foreseen after level {} of {})",
                                     r_.depth, estimate, byte_text(bytes), limit, k - 1, r_.depth),
                         estimate, limit);
    }

    // The cells of levels k to the depth, from the `parents` undecided cells of level k - 1 and the
    // growth of the undecided cells per level over the last two levels (at least 1).
    double cells_foreseen(int k, std::size_t parents) const {
        const double per_parent = std::pow(static_cast<double>(r_.split), d_);
        const double before =
            k >= 2 ? static_cast<double>(r_.levels[static_cast<std::size_t>(k - 2)].undecided) : 1;
        const double growth =
            std::clamp(before > 0 ? static_cast<double>(parents) / before : per_parent, 1.0, per_parent);
        double cells = 0, frontier = static_cast<double>(parents);
        for (int j = k; j <= r_.depth; ++j, frontier *= growth) cells += frontier * per_parent;
        return cells;
    }

    void start_level(int k) {
        level_ = k;
        n_ = grid::ipow(r_.split, k);
        const int remaining = r_.depth - k;
        consider_pruning_ = remaining >= std::max(1, r_.options.prune_min_remaining);
        expected_descendants_ = expected_descendants(remaining);
        min_cells_per_chunk_ = min_cells_per_chunk(k);
        if (k == 0)
            level_cells_ = 1;
        else
            plan_children();
        // The evaluators' checkpoint (a tiered one may change engine here): the same cells evaluated,
        // whatever the threads.
        for (const Variant& v : variants_)
            for (ir::Evaluator* w : v.workers) w->checkpoint(r_.evaluated);
        // Whether to ask for pruned functions cell by cell this level: not where no cell's request could
        // be granted (a virtual call, a cell box and a rounding-mode switch per undecided cell).
        for (Variant& v : variants_)
            v.ask_this_level = v.may_specialize && v.workers[0]->may_specialize_now(expected_descendants_);
        level_variants_.clear();
        prune_in_chunks_ = false;
        for (const Variant& v : variants_) {
            const bool prune = consider_pruning_ && k < r_.depth && v.prune_in_chunks;
            level_variants_.push_back({v.workers.data(), prune, v.instructions});
            prune_in_chunks_ |= prune;
        }
        // Children of pruned parents evaluate their parent's function (a variant of their own).
        keep_siblings_ = prune_in_chunks_ || variants_.size() > 1;
        // The level's cells per axis, computed once (each cell would otherwise compute two grid points
        // per axis with three interval operations each): the same boxes as grid::cell. Evaluators build
        // the cells' boxes from it (Evaluator::eval_cells).
        table_ = n_ <= grid_table_limit;
        if (table_) grid::level_cells(r_.root, n_, grid_, points_);
    }

    // Outward box of cell i of the level along `axis` (grid::cell, from the level's table when it has one).
    Interval cell_interval(std::size_t axis, std::uint32_t i) const {
        if (!table_) return grid::cell(r_.root[axis], width_[axis], i, n_);
        return grid_.axis(static_cast<int>(axis))[i];
    }

    // Evaluates the level's cells, from the plan of start_level, batch by batch.
    void evaluate_level() {
        // The level's kept cells, written by the chunks in place (unwritten until then: CellList).
        kept_base_ = r_.cells.size();
        if (r_.options.keep_cells) r_.cells.resize(kept_base_ + level_cells_);
        for (std::uint64_t c = 0; c < level_cells_;) {
            std::uint64_t end = std::min<std::uint64_t>(c + flush_at_, level_cells_);
            if (keep_siblings_) end = sibling_cut(c, end);
            flush(c, static_cast<std::size_t>(end - c));
            c = end;
        }
        drain();
        if (r_.options.progress) r_.options.progress(level_, r_.evaluated);
        last_progress_ = Clock::now();
    }

    // The order of the level's cells: the children of the previous level's undecided cells (row-major)
    // in row-major order. The children of one parent row fill `split` child rows, each running over all
    // the parents of the row; likewise for slabs of constant iz in 3D. Linear in the rows (parent_rows_,
    // found as the parents were taken): a scan of the parents themselves, serial between two levels,
    // took 7-9 ms of a 0.25 s two-thread carpet cover at depth 12.
    void plan_children() {
        blocks_.clear();
        const std::uint64_t s = static_cast<std::uint64_t>(r_.split);
        const std::uint32_t sz = d_ == 3 ? static_cast<std::uint32_t>(s) : 1;
        const std::size_t rows = parent_rows_.size();
        const auto row_end = [&](std::size_t row) {
            return row + 1 < rows ? parent_rows_[row + 1] : parents_.size();
        };
        std::uint64_t first = 0;
        for (std::size_t slab = 0; slab < rows;) {
            const std::uint32_t iz = parents_[parent_rows_[slab]].iz;
            std::size_t slab_end = slab + 1;
            while (slab_end < rows && parents_[parent_rows_[slab_end]].iz == iz) ++slab_end;
            for (std::uint32_t cz = 0; cz < sz; ++cz)
                for (std::size_t row = slab; row < slab_end; ++row) {
                    const std::size_t begin = parent_rows_[row], count = row_end(row) - begin;
                    blocks_.push_back({begin, count, cz, first});
                    first += count * s * s;
                }
            slab = slab_end;
        }
        level_cells_ = first;
    }

    // Where a batch or chunk of the level's cells [begin, end) ends when they prune in the chunks or
    // evaluate pruned functions (keep_siblings_): at the start of the block (a parent row's children)
    // that `end` would cut, if it starts after `begin`. A parent's children then stay in one chunk, and
    // an interpreter evaluates them side by side and analyses their tape pushes together (a block
    // holds all of a parent's children in 2D, split^2 of them in 3D); cut between the child rows, each
    // parent of the row would evaluate and push in two halves. A block larger than a batch is cut.
    std::uint64_t sibling_cut(std::uint64_t begin, std::uint64_t end) const {
        if (level_ == 0 || end >= level_cells_) return end;
        const std::uint64_t start = block_of(end)->first;
        return start > begin ? start : end;
    }

    // Where a chunk of cells from `begin` ends, near `end`, when siblings are kept together: at the
    // start of the block that `end` falls in, if after `begin`; else, the chunk lying inside one block,
    // at the block's end (at most `limit`, the batch's end), since a parent's children lie in every
    // child row of its block: a block cut anywhere splits some parent's children.
    std::uint64_t chunk_end(std::uint64_t begin, std::uint64_t end, std::uint64_t limit) const {
        if (level_ == 0 || end >= level_cells_) return end;
        const auto block = block_of(end);
        if (block->first > begin) return block->first;
        const auto s = static_cast<std::uint64_t>(r_.split);
        return std::min(limit, block->first + block->count * s * s);
    }

    // The block (plan_children) that holds cell c of the level (level >= 1).
    std::vector<ChildBlock>::const_iterator block_of(std::uint64_t c) const {
        return std::upper_bound(blocks_.begin(), blocks_.end(), c,
                                [](std::uint64_t v, const ChildBlock& b) { return v < b.first; }) -
               1;
    }

    // Cells [c, c + n) of the level, in its order (plan_children; level 0 is the root). Returns whether
    // they all evaluate the same variant.
    bool children(std::uint64_t c, std::size_t n, Pos* out) const {
        if (level_ == 0) {
            std::fill_n(out, n, Pos{0, 0, 0, 0});
            return true;
        }
        const auto s = static_cast<std::uint32_t>(r_.split);
        const std::uint32_t sz = d_ == 3 ? s : 1;
        auto block = block_of(c);
        // Position in the block: child row cy, parent pi of the row, child column cx; then counted on.
        const std::uint64_t j = c - block->first, row = block->count * s;
        auto cy = static_cast<std::uint32_t>(j / row);
        std::uint64_t pi = (j % row) / s;
        auto cx = static_cast<std::uint32_t>((j % row) % s);
        const std::uint32_t v0 = parents_[block->parent + pi].variant;
        std::uint32_t differ = 0;
        for (std::size_t k = 0; k < n; ++k) {
            const Pos& p = parents_[block->parent + pi];
            out[k] = {p.ix * s + cx, p.iy * s + cy, p.iz * sz + block->cz, p.variant};
            differ |= p.variant ^ v0;
            if (++cx < s) continue;
            cx = 0;
            if (++pi < block->count) continue;
            pi = 0;
            if (++cy < s) continue;
            cy = 0;
            ++block;
        }
        return differ == 0;
    }

    // Evaluates cells [first, first + m) of the level and classifies them. With several threads the
    // batch runs in the background (each chunk makes its cells, their boxes, evaluates and classifies
    // them, writes them to their place among the kept cells, and asks for pruned functions of
    // interpreted variants: a tape push depends on nothing shared) while this thread takes the verdicts
    // of older batches: counts, the next frontier, pruning requests of JIT variants. The verdicts and
    // the pruned functions are taken batch by batch in the level's order, so the output does not
    // depend on the threads.
    void flush(std::uint64_t first, std::size_t m) {
        Batch& b = batches_[filling_];
        prepare(b, first, m);
        if (threads_ == 1 || b.chunks.size() == 1) {
            drain();
            for (Chunk& c : b.chunks) run_chunk(b, c, 0);
            take_verdicts(b);
            return;
        }
        arena_.execute([&] {
            b.group.run([this, &b] {
                tbb::parallel_for(std::size_t{0}, b.chunks.size(), [&](std::size_t i) {
                    const int slot = tbb::this_task_arena::current_thread_index();
                    if (slot < 0 || slot >= threads_)
                        throw std::logic_error("rss: a thread outside the subdivision's arena");
                    run_chunk(b, b.chunks[i], static_cast<std::size_t>(slot));
                });
            });
        });
        b.running = true;
        filling_ = (filling_ + 1) % batches_in_flight;
        drain_one(batches_[filling_]); // the oldest batch, if it still has verdicts to give
    }

    // Waits for a running batch and takes its verdicts.
    void drain_one(Batch& b) {
        if (!b.running) return;
        arena_.execute([&] { b.group.wait(); });
        b.running = false;
        take_verdicts(b);
    }

    // Every batch's verdicts taken, oldest first (the one to fill next is never running).
    void drain() {
        for (int i = 0; i < batches_in_flight; ++i) drain_one(batches_[(filling_ + i) % batches_in_flight]);
    }

    // Counts, frontier and pruning requests from a batch's chunks, in the level's order.
    void take_verdicts(Batch& b) {
        const bool last = level_ == r_.depth;
        LevelCounts& lc = r_.levels[static_cast<std::size_t>(level_)];
        PruneLevel& pl = r_.prune_levels[static_cast<std::size_t>(level_)];
        for (const Chunk& c : b.chunks) {
            lc.inside += c.inside;
            lc.outside += c.outside;
            lc.undecided += c.undecided;
            r_.pruned_evaluations += c.pruned_cells;
            pl.pruned_evaluations += c.pruned_cells;
            pl.instructions += c.instructions;
            if (last || c.undecided == 0) continue;
            // The chunk's undecided cells, compacted by run_chunk, and where their rows start.
            const Pos* cells = &b.cells[c.begin];
            const std::size_t base = next_.size();
            if (base == 0 || next_.back().iy != cells[0].iy || next_.back().iz != cells[0].iz)
                next_rows_.push_back(base); // a row starts (plan_children)
            for (std::size_t r = c.begin; r < c.begin + c.rows; ++r) next_rows_.push_back(base + b.rows[r]);
            next_.insert(next_.end(), cells, cells + c.undecided);
            if (!consider_pruning_) continue;
            for (std::size_t u = 0; u < c.undecided; ++u) {
                const Pos& p = cells[u];
                const Variant& v = variants_[p.variant];
                if (v.prune_in_chunks)
                    next_[base + u].variant = adopt(p.variant, std::move(b.pruned[b.undecided[c.begin + u]]));
                else if (v.ask_this_level)
                    next_[base + u].variant = pruned_variant(p);
            }
        }
        lc.evaluated += b.cells.size();
        r_.evaluated += b.cells.size();

        if (r_.options.progress && Clock::now() - last_progress_ >= std::chrono::seconds(1)) {
            r_.options.progress(level_, r_.evaluated);
            last_progress_ = Clock::now();
        }
    }

    // The box of a cell (outward: the grid's points are enclosures).
    void cell_box(const Pos& p, Interval* box) const {
        const std::uint32_t pos[3] = {p.ix, p.iy, p.iz};
        for (int a = 0; a < d_; ++a)
            box[a] = cell_interval(static_cast<std::size_t>(a), pos[static_cast<std::size_t>(a)]);
    }

    // The fewest cells a chunk of level k takes: min_chunk where a cell's function is short (a
    // chunk then runs long enough to repay handing it to a thread), fewer where it is long, by the
    // instructions per evaluation of the level before (the parents' functions: an upper bound on
    // their children's, which are pruned from them). The first levels of a large model have a few
    // cells that each evaluate tens of thousands of instructions and push tapes: as single chunks they
    // ran on one thread, about a seventh of the work of a depth-10 cover of 7000 clauses.
    std::size_t min_cells_per_chunk(int k) const {
        double per_cell = variants_[0].instructions;
        if (k > 0) {
            const auto before = static_cast<std::size_t>(k - 1);
            const double evaluated = static_cast<double>(r_.levels[before].evaluated);
            if (evaluated > 0) per_cell = r_.prune_levels[before].instructions / evaluated;
        }
        const double cells = std::ceil(min_chunk_instructions / std::max(1.0, per_cell));
        return static_cast<std::size_t>(std::clamp(cells, 1.0, static_cast<double>(min_chunk)));
    }

    // Sizes a batch for cells [first, first + m) and cuts it into up to chunks_per_thread chunks per
    // thread.
    void prepare(Batch& b, std::uint64_t first, std::size_t m) {
        b.first = first;
        b.cells.resize(m);
        b.verdicts.resize(m);
        b.undecided.resize(m);
        b.rows.resize(m);
        if (prune_in_chunks_) b.pruned.assign(m, nullptr);
        const auto k = std::max<std::size_t>(
            1,
            std::min<std::size_t>(threads_ == 1 ? 1 : chunks_per_thread * static_cast<std::size_t>(threads_),
                                  (m + min_cells_per_chunk_ - 1) / min_cells_per_chunk_));
        b.chunks.clear();
        for (std::size_t c = 0, begin = 0; c < k && begin < m; ++c) {
            std::size_t end = c + 1 == k ? m : std::max(begin, m * (c + 1) / k);
            if (keep_siblings_ && end < m)
                end = static_cast<std::size_t>(chunk_end(first + begin, first + end, first + m) - first);
            if (end == begin) continue;
            b.chunks.push_back({begin, end});
            begin = end;
        }
    }

    // A chunk runs on the evaluators of the thread that takes it (its slot in the arena), so no two
    // threads share an evaluator, and threads that finish early take more chunks (series stop after
    // different numbers of terms in different cells). Its cells are evaluated with one call per variant
    // they use. Results go by position, so the output does not depend on which thread did what.
    void run_chunk(Batch& b, Chunk& c, std::size_t worker) const {
        const std::size_t n = c.end - c.begin;
        const bool one_variant = children(b.first + c.begin, n, &b.cells[c.begin]);
        c.pruned_cells = 0;
        c.instructions = 0; // integers: the sum is exact in any order
        if (one_variant) {
            evaluate_run(b.cells[c.begin].variant, worker, &b.cells[c.begin], n, &b.verdicts[c.begin], b,
                         nullptr, c.begin, c);
        } else {
            ChunkScratch& s = scratch();
            s.order.resize(n);
            for (std::size_t i = 0; i < n; ++i) s.order[i] = static_cast<std::uint32_t>(c.begin + i);
            std::stable_sort(s.order.begin(), s.order.end(), [&](std::uint32_t x, std::uint32_t y) {
                return b.cells[x].variant < b.cells[y].variant;
            });
            s.cells.resize(n);
            s.verdicts.resize(n);
            for (std::size_t i = 0; i < n; ++i) s.cells[i] = b.cells[s.order[i]];
            for (std::size_t run = 0; run < n;) {
                const std::uint32_t v = s.cells[run].variant;
                std::size_t end = run;
                while (end < n && s.cells[end].variant == v) ++end;
                evaluate_run(v, worker, &s.cells[run], end - run, &s.verdicts[run], b, &s.order[run], 0, c);
                run = end;
            }
            for (std::size_t i = 0; i < n; ++i) b.verdicts[s.order[i]] = s.verdicts[i];
        }
        // Counts, kept cells and the undecided ones, in order: taking them is then a few copies.
        std::uint32_t* undecided = &b.undecided[c.begin];
        std::size_t u = 0, inside = 0;
        for (std::size_t i = c.begin; i < c.end; ++i) {
            const CellVerdict v = b.verdicts[i];
            undecided[u] = static_cast<std::uint32_t>(i); // kept when the cell is undecided
            u += v == CellVerdict::undecided;
            inside += v == CellVerdict::inside;
        }
        c.inside = inside;
        c.undecided = u;
        c.outside = n - u - inside;
        const bool last = level_ == r_.depth;
        if (r_.options.keep_cells) {
            // Straight to their place among the kept cells (sized for the level by evaluate_level).
            Cell* kept = &r_.cells[kept_base_ + b.first];
            for (std::size_t i = c.begin; i < c.end; ++i) {
                const Pos& p = b.cells[i];
                const CellVerdict v = b.verdicts[i];
                const CellClass cls = v == CellVerdict::inside    ? CellClass::inside
                                      : v == CellVerdict::outside ? CellClass::outside
                                      : last                      ? CellClass::boundary
                                                                  : CellClass::subdivided;
                kept[i] = {static_cast<std::uint8_t>(level_), cls, p.ix, p.iy, p.iz};
            }
        }
        if (last) return;
        // The undecided cells to the front of the chunk's cells (in place: the u-th lies at or after
        // begin + u), and where their rows start, so that taking them is one copy (take_verdicts).
        Pos* cells = &b.cells[c.begin];
        std::uint32_t* rows = &b.rows[c.begin];
        std::size_t r = 0;
        for (std::size_t k = 0; k < u; ++k) {
            const Pos p = b.cells[undecided[k]];
            if (k > 0 && (cells[k - 1].iy != p.iy || cells[k - 1].iz != p.iz))
                rows[r++] = static_cast<std::uint32_t>(k);
            cells[k] = p;
        }
        c.rows = r;
    }

    // Verdicts of n cells of variant `variant`, counted into the chunk. With the level's grid table and
    // no pruning in the chunks, the evaluator builds the boxes and classifies (Evaluator::eval_cells).
    // Else the boxes are built here; a variant that prunes in the chunks evaluates them in batches of
    // the boxes whose values it keeps, and an undecided cell asks for its pruned function from the values
    // its evaluation left (Evaluator::specialize_after_eval: no second evaluation). Cell k of the run is
    // cell index[k] (or first + k) of the batch.
    void evaluate_run(std::uint32_t variant, std::size_t worker, const Pos* cells, std::size_t n,
                      CellVerdict* verdicts, Batch& b, const std::uint32_t* index, std::size_t first,
                      Chunk& c) const {
        const LevelVariant& v = level_variants_[variant];
        c.instructions += static_cast<double>(n) * v.instructions;
        if (variant != 0) c.pruned_cells += n;
        ir::Evaluator& e = *v.workers[worker];
        const bool closed = r_.options.closed_inside;
        if (table_ && !v.prune) {
            e.eval_cells(grid_, &cells->ix, pos_stride, n, verdicts, closed);
            return;
        }
        const auto d = static_cast<std::size_t>(d_);
        const std::size_t group = v.prune ? std::max<std::size_t>(e.kept_evaluations(), 1) : n;
        ChunkScratch& s = scratch();
        s.boxes.resize(std::min(group, n) * d);
        s.out.resize(std::min(group, n));
        for (std::size_t k = 0; k < n; k += group) {
            const std::size_t m = std::min(group, n - k);
            {
                num::UpwardRounding up; // the cell boxes use the numeric core's directed rounding
                for (std::size_t j = 0; j < m; ++j) cell_box(cells[k + j], &s.boxes[j * d]);
            }
            e.eval_boxes(s.boxes.data(), m, s.out.data());
            for (std::size_t j = 0; j < m; ++j) {
                verdicts[k + j] = classify(s.out[j], closed);
                if (v.prune && verdicts[k + j] == CellVerdict::undecided)
                    b.pruned[index ? index[k + j] : first + k + j] =
                        e.specialize_after_eval(j, &s.boxes[j * d], expected_descendants_);
            }
        }
    }

    // Descendant evaluations of an undecided cell `remaining` levels above the depth, if the
    // boundary through it is a smooth curve or surface: split^d children, then split^(d-1) times
    // more cells per level.
    double expected_descendants(int remaining) const {
        const double s = r_.split;
        double per_level = std::pow(s, d_), total = 0;
        for (int j = 0; j < remaining; ++j, per_level *= std::pow(s, d_ - 1)) total += per_level;
        return total;
    }

    // The variant the children of the undecided cell p evaluate: a pruned function when its variant's
    // evaluator offers one (the same function always maps to the same variant).
    std::uint32_t pruned_variant(const Pos& p) {
        const std::uint32_t v = p.variant;
        ir::Evaluator& e = *variants_[v].workers[0];
        Interval box[3];
        {
            num::UpwardRounding up;
            cell_box(p, box);
        }
        return adopt(v, e.specialize(box, expected_descendants_));
    }

    // The variant of the pruned function a cell of variant v asked for (null: v), made when it is new;
    // the request is counted here, in queue order.
    std::uint32_t adopt(std::uint32_t v, std::shared_ptr<ir::Evaluator> pruned) {
        PruneLevel& pl = r_.prune_levels[static_cast<std::size_t>(level_)];
        ++pl.requests;
        if (!pruned) return v;
        ++pl.pruned;
        auto [it, added] =
            variant_of_.try_emplace(pruned.get(), static_cast<std::uint32_t>(variants_.size()));
        if (added) {
            Variant nv;
            nv.instructions = static_cast<double>(pruned->instruction_count());
            nv.may_specialize = pruned->may_specialize();
            nv.prune_in_chunks = nv.may_specialize && pruned->specializes_independently();
            nv.ask_this_level = nv.may_specialize && pruned->may_specialize_now(expected_descendants_);
            // An evaluator made for this cell alone (no cache holds it) serves the first thread itself.
            const bool own = pruned.use_count() == 1;
            for (int t = 0; t < threads_; ++t) {
                if (t == 0 && own) {
                    nv.workers.push_back(pruned.get());
                    continue;
                }
                nv.owned.push_back(pruned->clone());
                nv.workers.push_back(nv.owned.back().get());
            }
            nv.function = std::move(pruned);
            variants_.push_back(std::move(nv));
            ++created_;
        }
        return it->second;
    }

    // The work of a variant's evaluators counts as the caller's evaluator's.
    void count_work(const Variant& v) {
        for (ir::Evaluator* w : v.workers) {
            if (w == &f_) continue;
            f_.stats += w->stats;
            f_.specialize_stats += w->specialize_stats;
            w->stats = {};
            w->specialize_stats = {};
        }
    }

    // Frees the variants no cell of `frontier` evaluates any more (pruning makes one per pruned
    // cell), numbering the others densely in their old order (so the output does not change).
    void release_unused(std::vector<Pos>& frontier) {
        if (variants_.size() == 1) return;
        std::vector<std::uint32_t> renumber(variants_.size(), 0);
        for (const Pos& p : frontier) renumber[p.variant] = 1;
        renumber[0] = 1;
        std::uint32_t kept = 0;
        for (std::uint32_t v = 0; v < variants_.size(); ++v) {
            if (!renumber[v]) {
                count_work(variants_[v]);
                continue;
            }
            renumber[v] = kept;
            if (kept != v) variants_[kept] = std::move(variants_[v]);
            ++kept;
        }
        variants_.resize(kept);
        variant_of_.clear();
        for (std::uint32_t v = 1; v < kept; ++v) variant_of_.emplace(variants_[v].function.get(), v);
        for (Pos& p : frontier) p.variant = renumber[p.variant];
    }

    static constexpr std::size_t min_chunk = 256; // cells: below this a thread costs more than it saves...
    static constexpr double min_chunk_instructions = 256 * 64; // ... when they evaluate 64 instructions each
    static constexpr std::uint64_t grid_table_limit = 1 << 16; // cells per axis with a table of grid points
    static constexpr std::size_t chunks_per_thread = 8;        // dynamic balance between threads
    tbb::global_control worker_stack_{tbb::global_control::thread_stack_size, worker_stack_bytes};
    ir::Evaluator& f_;
    RssResult& r_;
    int d_;
    int threads_;
    tbb::task_arena arena_;
    std::vector<std::unique_ptr<ir::Evaluator>> clones_;
    // The functions cells evaluate: 0 is the shape's (f_ and its clones), the others pruned ones,
    // each with an evaluator per thread.
    std::vector<Variant> variants_;
    std::unordered_map<const ir::Evaluator*, std::uint32_t> variant_of_;
    std::size_t created_ = 0;    // pruned functions made (variants after the first)
    bool keep_siblings_ = false; // cut batches and chunks between parents (sibling_cut)
    std::size_t flush_at_ = 0;
    int level_ = 0;
    std::uint64_t n_ = 1;              // cells per axis at level_
    bool table_ = false;               // n_ <= grid_table_limit: the level's cells in grid_
    ir::CellGrid grid_;                // the level's cells per axis (when table_)
    std::vector<Interval> points_;     // ... computed from its grid points
    std::vector<Interval> width_;      // enclosure of the root's width per axis
    Batch batches_[batches_in_flight]; // one filling, the others maybe evaluating
    int filling_ = 0;
    std::vector<ChildBlock> blocks_; // the order of the level's cells (plan_children)
    std::uint64_t level_cells_ = 0;  // ... and their number
    std::size_t kept_base_ = 0;      // where the level's cells start among the kept cells
    std::size_t min_cells_per_chunk_ = min_chunk;
    std::vector<LevelVariant> level_variants_;
    bool prune_in_chunks_ = false;                     // some of the level's cells prune in the chunks
    bool consider_pruning_ = false;                    // the level's undecided cells ask for pruned functions
    double expected_descendants_ = 0;                  // ... for this many evaluations below each
    std::vector<Pos> next_;                            // undecided cells of level_, row-major
    std::vector<Pos> parents_;                         // ... of the level before
    std::vector<std::size_t> next_rows_, parent_rows_; // where each row (iy, iz) of each starts
    Clock::time_point last_progress_;
};

} // namespace

RssResult subdivide(ir::Evaluator& f, const std::vector<Interval>& root, const RssOptions& options) {
    validate(f, root, options);
    const auto start = Clock::now();
    RssResult r;
    r.root = root;
    r.depth = options.depth;
    r.split = options.split;
    r.options = options;
    Runner(f, r).run();
    r.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return r;
}

} // namespace frac::rt
