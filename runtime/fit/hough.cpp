#include "runtime/fit/hough.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <fmt/format.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

namespace frac::rt::fit {

namespace {

// One axis of a histogram: n bins over [lo, hi).
struct Axis {
    double lo, hi;
    int n;
    double step() const { return (hi - lo) / n; }
    double scale; // n / (hi - lo)
    int bin(double v) const {
        const double f = (v - lo) * scale;
        return f >= 0 && f < n ? int(f) : -1;
    }
    double centre(int i) const { return lo + (i + 0.5) * step(); }
};

struct Axes {
    Axis a, b, c, d, e;
};

Axes parameter_box(const Samples& s, const HoughOptions& o) {
    const auto [x_lo, x_hi] = std::minmax_element(s.x.begin(), s.x.end());
    const double t_span = s.t.back() - s.t.front(), x_span = std::max(*x_hi - *x_lo, 1e-300);
    const double t_top = std::max(std::abs(s.t.front()), std::abs(s.t.back()));
    const double x_top = std::max(std::abs(*x_lo), std::abs(*x_hi));
    // b is a slope of x against t: the graph's own slope bounds the useful ones. d = t' - a t and
    // e = x' - b t - c x follow from |a|, |c| < 1 and the boxes of t and x.
    const double b_max = 2 * x_span / t_span, e_max = 2 * x_top + b_max * t_top;
    auto axis = [](double lo, double hi, int n) { return Axis{lo, hi, n, n / (hi - lo)}; };
    return {axis(-1, 1, o.abc_bins), axis(-b_max, b_max, o.abc_bins), axis(-1, 1, o.abc_bins),
            axis(s.t.front() - t_top, s.t.back() + t_top, o.de_bins), axis(-e_max, e_max, o.de_bins)};
}

// The inverses of [[t_i, x_i, 1], [t_j, x_j, 1], [t_k, x_k, 1]] (eq. 14) for every i < j < k, grouped by
// (i, k); NaN where the three samples are collinear.
class TripleInverses {
public:
    explicit TripleInverses(const Samples& s) : n_(s.size()), start_(n_ * n_, 0) {
        std::size_t at = 0;
        for (std::size_t i = 0; i < n_; ++i)
            for (std::size_t k = i + 2; k < n_; ++k) {
                start_[i * n_ + k] = at;
                at += k - i - 1;
            }
        inv_.resize(at);
        for (std::size_t i = 0; i < n_; ++i)
            for (std::size_t k = i + 2; k < n_; ++k)
                for (std::size_t j = i + 1; j < k; ++j) {
                    const double m[3][3] = {{s.t[i], s.x[i], 1}, {s.t[j], s.x[j], 1}, {s.t[k], s.x[k], 1}};
                    auto& r = inv_[start_[i * n_ + k] + (j - i - 1)];
                    const double c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1];
                    const double c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2];
                    const double c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
                    const double det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
                    const double scale = std::abs(m[1][0] - m[0][0]) *
                                         (std::abs(m[0][1]) + std::abs(m[1][1]) + std::abs(m[2][1]) + 1e-300);
                    if (!(std::abs(det) > 1e-12 * scale)) {
                        r.fill(std::nan(""));
                        continue;
                    }
                    const double inv_det = 1 / det;
                    r = {c00 * inv_det,
                         (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * inv_det,
                         (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * inv_det,
                         c01 * inv_det,
                         (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * inv_det,
                         (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * inv_det,
                         c02 * inv_det,
                         (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * inv_det,
                         (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * inv_det};
                }
    }
    // Row-major inverse for (i, j, k).
    const std::array<double, 9>& operator()(std::size_t i, std::size_t j, std::size_t k) const {
        return inv_[start_[i * n_ + k] + (j - i - 1)];
    }

private:
    std::size_t n_;
    std::vector<std::size_t> start_;
    std::vector<std::array<double, 9>> inv_;
};

struct Counts {
    std::uint64_t maps = 0, valid = 0;
};

// A map's bins on the five axes.
struct Bins {
    int a, b, c, d, e;
};

// Calls visit(bins) for every valid map of the enumeration, in parallel over i. `wanted(a_bin)` says whether
// maps of that bin of a are wanted at all: a is fixed by (i, k, l, n), so the samples j between i and k are
// not visited for the others. Stops early (and returns false) past the deadline.
template <class Wanted, class Visit>
bool enumerate_maps(const Samples& s, const TripleInverses& inv, const Axes& box, double min_scaling,
                    std::chrono::steady_clock::time_point deadline, bool timed, Counts& total,
                    Wanted&& wanted, Visit&& visit) {
    const std::size_t n = s.size();
    std::atomic<bool> late{false};
    std::atomic<std::uint64_t> maps{0}, valid{0};
    const double* t = s.t.data();
    const double* x = s.x.data();
    tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) {
        if (late.load(std::memory_order_relaxed)) return;
        if (timed && std::chrono::steady_clock::now() > deadline) {
            late = true;
            return;
        }
        std::uint64_t my_maps = 0, my_valid = 0;
        for (std::size_t k = i + 2; k < n; ++k) {
            const double span = t[k] - t[i];
            const std::array<double, 9>* rows = &inv(i, i + 1, k) - 1; // rows[j - i]: the inverse for j
            for (std::size_t l = 0; l + 2 < n; ++l)
                for (std::size_t m_end = l + 2; m_end < n && t[m_end] - t[l] < span; ++m_end) {
                    my_maps += 2 * (k - i - 1);
                    for (int orientation = 0; orientation < 2; ++orientation) {
                        const double a = (orientation == 0 ? 1 : -1) * (t[m_end] - t[l]) / span;
                        const double d = t[l] - a * (orientation == 0 ? t[i] : t[k]);
                        const int bin_a = box.a.bin(a), bin_d = box.d.bin(d);
                        if (bin_a < 0 || bin_d < 0 || !wanted(bin_a)) continue;
                        const double yi = orientation == 0 ? x[l] : x[m_end];
                        const double yk = orientation == 0 ? x[m_end] : x[l];
                        // The sample between l and m_end nearest the image of t_j: the images move
                        // monotonically with j, so the nearest one does too.
                        std::size_t m = orientation == 0 ? l + 1 : m_end - 1;
                        for (std::size_t j = i + 1; j < k; ++j) {
                            const double image = a * t[j] + d;
                            if (orientation == 0)
                                while (m + 1 < m_end && std::abs(t[m + 1] - image) <= std::abs(t[m] - image))
                                    ++m;
                            else
                                while (m - 1 > l && std::abs(t[m - 1] - image) <= std::abs(t[m] - image)) --m;
                            const auto& r = rows[j - i];
                            const double ym = x[m];
                            const double c = r[3] * yi + r[4] * ym + r[5] * yk;
                            if (!(std::abs(c) < 1) || std::abs(c) < min_scaling) continue; // NaN: collinear
                            const double b = r[0] * yi + r[1] * ym + r[2] * yk;
                            const double e = r[6] * yi + r[7] * ym + r[8] * yk;
                            const Bins bins{bin_a, box.b.bin(b), box.c.bin(c), bin_d, box.e.bin(e)};
                            if (bins.b < 0 || bins.c < 0 || bins.e < 0) continue;
                            ++my_valid;
                            visit(bins);
                        }
                    }
                }
        }
        maps += my_maps;
        valid += my_valid;
    });
    total.maps = maps;
    total.valid = valid;
    return !late;
}

// Indices of the local maxima of a histogram over a grid of `dims` (each bin compared with its 3^D - 1
// neighbours; ties go to the bin of lower index), most popular first.
std::vector<std::size_t> local_maxima(const std::vector<std::uint32_t>& h, const std::vector<int>& dims,
                                      std::size_t keep) {
    std::vector<std::size_t> peaks;
    const std::size_t total = h.size();
    const int rank = int(dims.size());
    std::vector<int> at(rank);
    for (std::size_t index = 0; index < total; ++index) {
        const std::uint32_t v = h[index];
        if (v == 0) continue;
        std::size_t rest = index;
        for (int r = rank - 1; r >= 0; --r) {
            at[r] = int(rest % dims[r]);
            rest /= dims[r];
        }
        bool peak = true;
        const int neighbours = rank == 3 ? 27 : 9;
        for (int q = 0; q < neighbours && peak; ++q) {
            int code = q;
            std::size_t other = 0;
            bool inside = true;
            for (int r = 0; r < rank; ++r) {
                const int p = at[r] + code % 3 - 1;
                code /= 3;
                inside = inside && p >= 0 && p < dims[r];
                other = other * dims[r] + std::size_t(std::clamp(p, 0, dims[r] - 1));
            }
            if (!inside || other == index) continue;
            if (h[other] > v || (h[other] == v && other < index)) peak = false;
        }
        if (peak) peaks.push_back(index);
    }
    std::stable_sort(peaks.begin(), peaks.end(), [&](std::size_t p, std::size_t q) { return h[p] > h[q]; });
    if (peaks.size() > keep) peaks.resize(keep);
    return peaks;
}

bool near(const Shear& p, const Shear& q, const HoughSteps& st) {
    return std::abs(p.a - q.a) <= 1.5 * st.a && std::abs(p.b[0] - q.b[0]) <= 1.5 * st.b &&
           std::abs(p.c[0][0] - q.c[0][0]) <= 1.5 * st.c && std::abs(p.d - q.d) <= 1.5 * st.d &&
           std::abs(p.e[0] - q.e[0]) <= 1.5 * st.e;
}

} // namespace

HoughResult hough_recover(const Samples& s, const HoughOptions& o) {
    if (s.curve()) throw std::invalid_argument("the Hough recovery takes the graph of a function (t, x)");
    using clock = std::chrono::steady_clock;
    const auto deadline = clock::now() + std::chrono::duration_cast<clock::duration>(
                                             std::chrono::duration<double>(std::max(o.seconds, 0.0)));
    const bool timed = o.seconds > 0;
    auto say = [&](const std::string& line) {
        if (o.progress) o.progress(line);
    };
    const Axes box = parameter_box(s, o);
    const TripleInverses inv(s);
    HoughResult result;
    result.steps = {box.a.step(), box.b.step(), box.c.step(), box.d.step(), box.e.step()};

    // First pass: (a, b, c).
    const std::size_t abc_size = std::size_t(o.abc_bins) * o.abc_bins * o.abc_bins;
    tbb::enumerable_thread_specific<std::vector<std::uint32_t>> abc_local(
        [&] { return std::vector<std::uint32_t>(abc_size, 0); });
    auto abc_index = [&](const Bins& q) {
        return (std::size_t(q.a) * o.abc_bins + std::size_t(q.b)) * o.abc_bins + std::size_t(q.c);
    };
    Counts counts;
    if (!enumerate_maps(
            s, inv, box, o.min_scaling, deadline, timed, counts, [](int) { return true; },
            [&](const Bins& q) { ++abc_local.local()[abc_index(q)]; }))
        throw BudgetExceeded(
            fmt::format("the Hough transform ran past its budget of {} s in its first pass", o.seconds));
    std::vector<std::uint32_t> abc(abc_size, 0);
    for (const auto& h : abc_local)
        for (std::size_t q = 0; q < abc_size; ++q) abc[q] += h[q];
    abc_local.clear();
    result.maps = counts.maps;
    result.valid = counts.valid;
    const std::vector<std::size_t> peaks =
        local_maxima(abc, {o.abc_bins, o.abc_bins, o.abc_bins}, std::size_t(o.abc_clusters));
    say(fmt::format("hough: pass 1: {} maps, {} valid, {} (a, b, c) clusters kept", counts.maps, counts.valid,
                    peaks.size()));

    // Each bin next to a peak belongs to the most popular such peak: its maps are the peak's spill-over.
    std::vector<std::int16_t> owner(abc_size, -1);
    std::vector<char> a_owned(std::size_t(o.abc_bins), 0);
    for (std::size_t p = 0; p < peaks.size(); ++p) {
        const int ia = int(peaks[p] / (std::size_t(o.abc_bins) * o.abc_bins));
        const int ib = int(peaks[p] / o.abc_bins % o.abc_bins), ic = int(peaks[p] % o.abc_bins);
        for (int da = -1; da <= 1; ++da) {
            if (ia + da >= 0 && ia + da < o.abc_bins) a_owned[std::size_t(ia + da)] = 1;
            for (int db = -1; db <= 1; ++db)
                for (int dc = -1; dc <= 1; ++dc) {
                    const int qa = ia + da, qb = ib + db, qc = ic + dc;
                    if (qa < 0 || qb < 0 || qc < 0 || qa >= o.abc_bins || qb >= o.abc_bins ||
                        qc >= o.abc_bins)
                        continue;
                    auto& w = owner[(std::size_t(qa) * o.abc_bins + qb) * o.abc_bins + qc];
                    if (w < 0) w = std::int16_t(p);
                }
        }
    }

    // Second pass: (d, e) for the maps of the kept clusters.
    const std::size_t de_size = std::size_t(o.de_bins) * o.de_bins;
    tbb::enumerable_thread_specific<std::vector<std::uint32_t>> de_local(
        [&] { return std::vector<std::uint32_t>(de_size * peaks.size(), 0); });
    if (!enumerate_maps(
            s, inv, box, o.min_scaling, deadline, timed, counts,
            [&](int a_bin) { return a_owned[std::size_t(a_bin)] != 0; },
            [&](const Bins& q) {
                const int w = owner[abc_index(q)];
                if (w >= 0)
                    ++de_local.local()[std::size_t(w) * de_size + std::size_t(q.d) * o.de_bins +
                                       std::size_t(q.e)];
            }))
        throw BudgetExceeded(
            fmt::format("the Hough transform ran past its budget of {} s in its second pass", o.seconds));
    std::vector<HoughCluster> candidates;
    for (std::size_t p = 0; p < peaks.size(); ++p) {
        std::vector<std::uint32_t> de(de_size, 0);
        for (const auto& h : de_local)
            for (std::size_t q = 0; q < de_size; ++q) de[q] += h[p * de_size + q];
        const std::size_t ia = peaks[p] / (std::size_t(o.abc_bins) * o.abc_bins);
        const std::size_t ib = peaks[p] / o.abc_bins % o.abc_bins, ic = peaks[p] % o.abc_bins;
        for (std::size_t q : local_maxima(de, {o.de_bins, o.de_bins}, std::size_t(o.results))) {
            HoughCluster cl;
            cl.hits = de[q];
            cl.map.a = box.a.centre(int(ia));
            cl.map.b[0] = box.b.centre(int(ib));
            cl.map.c[0][0] = box.c.centre(int(ic));
            cl.map.d = box.d.centre(int(q / o.de_bins));
            cl.map.e[0] = box.e.centre(int(q % o.de_bins));
            candidates.push_back(cl);
        }
    }
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const HoughCluster& p, const HoughCluster& q) { return p.hits > q.hits; });
    std::size_t echoes = 0;
    for (const HoughCluster& cand : candidates) {
        if (result.clusters.size() >= std::size_t(o.results)) break;
        bool echo = false;
        if (o.remove_echoes)
            for (const HoughCluster& p : result.clusters)
                for (const HoughCluster& q : result.clusters)
                    echo = echo || near(p.map.after(q.map), cand.map, result.steps);
        if (echo)
            ++echoes;
        else
            result.clusters.push_back(cand);
    }
    say(fmt::format("hough: pass 2: {} clusters, {} echoes of more popular maps dropped",
                    result.clusters.size(), echoes));
    return result;
}

double join_tolerance(const HoughResult& result, const Samples& s) {
    // A map's range is known to a few steps of d (and of a, times the interval).
    return 2 * result.steps.d + result.steps.a * (s.t.back() - s.t.front());
}

FractalFunction fif_from_clusters(const HoughResult& result, const Samples& s, std::size_t count) {
    if (result.clusters.size() < count)
        throw std::runtime_error(
            fmt::format("the Hough transform found {} clusters, fewer than the {} maps asked for",
                        result.clusters.size(), count));
    FractalFunction f;
    f.t0 = s.t.front();
    f.t1 = s.t.back();
    for (std::size_t i = 0; i < count; ++i) f.pieces.push_back({result.clusters[i].map, f.t0, f.t1, 0, 0});
    const std::string why = make_consistent(f, join_tolerance(result, s));
    if (!why.empty())
        throw std::runtime_error(fmt::format("the {} most popular maps do not make a FIF: {}", count, why));
    return f;
}

} // namespace frac::rt::fit
