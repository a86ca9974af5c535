// Projected-IFS fitting (seed 003 sec. 4, runtime/fit): speed of the exact Jacobian against seed 003's
// finite differences, and compression against JPEG at equal size, all in one run.
//
//   bench_fit [REPEATS] [OUTPUT_DIR]
//
// 1. The elliptic paraboloid of sec. 4.3 on (3^4 + 1)^2 = 82 x 82 samples, 3 x 3 sub-patches, 4 x 4
//    control points: the time the Levenberg-Marquardt fit takes to reach the paper's 26.6 dB and a higher
//    level, with exact derivatives and with forward differences (one residual evaluation a parameter),
//    the two interleaved, REPEATS times each (medians).
// 2. Compression: the paraboloid as an 8-bit image, and a real grey image (xplanet-images' earth.jpg,
//    made grey and cut to its central square, averaged down to 82 x 82), each fitted, stored with 16-bit
//    and 8-bit parameters, against JPEG (libjpeg, optimised Huffman tables, no JFIF header) at the
//    best quality whose file is no larger than the model. The data are written to OUTPUT_DIR for
//    `frac fit`: paraboloid_82.csv (the generated ground truth) and earth_82.png.
#include "bench/bench_common.hpp"
#include "runtime/fit/least_squares.hpp"
#include "runtime/fit/projected_ifs.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <vector>

#include <fmt/format.h>
#include <jpeglib.h>
#include <png.h>
#include <zlib.h>

namespace {

using namespace frac;
using namespace frac::rt::fit;

constexpr double paper_psnr = 26.6; // seed 003 Table 1, the projected IFS model with 16-bit parameters
constexpr double high_psnr = 39.0;  // a level near where the paraboloid fit settles
// The real grey image: xplanet-images' map of the earth, made grey and cut to its central square (the
// package's sun map is uniform there).
constexpr const char* real_images[][2] = {{"/usr/share/xplanet/images/earth.jpg", "earth_82.png"}};
// Real rough data from python-matplotlib-data: a digital elevation model (Jacksboro fault, 344 x 403
// int16 heights in an .npz archive) and an EEG recording (800 x 4 float64, channel 0 used).
constexpr const char* sample_data = "/usr/share/matplotlib/mpl-data/sample_data/";

struct SpeedRun {
    double to_paper = -1, to_high = -1, seconds = 0;
    int iterations = 0;
};

SpeedRun time_fit(const HeightGrid& data, Derivatives derivatives) {
    FitOptions options;
    options.derivatives = derivatives;
    options.max_iterations = 80;
    options.target_psnr = high_psnr;
    SpeedRun run;
    options.progress = [&](int, double psnr, double seconds) {
        if (psnr >= paper_psnr && run.to_paper < 0) run.to_paper = seconds;
    };
    const FitResult r = fit_patch(data, options);
    run.to_high = r.seconds_to_target;
    run.seconds = r.seconds;
    run.iterations = r.iterations;
    return run;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? -1 : v[v.size() / 2];
}

// ---- JPEG in memory (libjpeg) ----

std::vector<unsigned char> jpeg_encode(const std::vector<unsigned char>& grey, std::size_t w, std::size_t h,
                                       int quality) {
    jpeg_compress_struct cinfo;
    jpeg_error_mgr jerr;
    cinfo.err = jpeg_std_error(&jerr);
    jpeg_create_compress(&cinfo);
    unsigned char* buffer = nullptr;
    unsigned long size = 0;
    jpeg_mem_dest(&cinfo, &buffer, &size);
    cinfo.image_width = static_cast<JDIMENSION>(w);
    cinfo.image_height = static_cast<JDIMENSION>(h);
    cinfo.input_components = 1;
    cinfo.in_color_space = JCS_GRAYSCALE;
    jpeg_set_defaults(&cinfo);
    jpeg_set_quality(&cinfo, quality, TRUE);
    cinfo.optimize_coding = TRUE;
    cinfo.write_JFIF_header = FALSE;
    jpeg_start_compress(&cinfo, TRUE);
    while (cinfo.next_scanline < cinfo.image_height) {
        JSAMPROW row = const_cast<unsigned char*>(&grey[cinfo.next_scanline * w]);
        jpeg_write_scanlines(&cinfo, &row, 1);
    }
    jpeg_finish_compress(&cinfo);
    std::vector<unsigned char> out(buffer, buffer + size);
    jpeg_destroy_compress(&cinfo);
    std::free(buffer);
    return out;
}

// Grey pixels of a JPEG (colour ones converted by libjpeg), width and height.
std::vector<unsigned char> jpeg_decode(const unsigned char* data, std::size_t size, std::size_t& w,
                                       std::size_t& h) {
    jpeg_decompress_struct cinfo;
    jpeg_error_mgr jerr;
    cinfo.err = jpeg_std_error(&jerr);
    jpeg_create_decompress(&cinfo);
    jpeg_mem_src(&cinfo, data, static_cast<unsigned long>(size));
    jpeg_read_header(&cinfo, TRUE);
    cinfo.out_color_space = JCS_GRAYSCALE;
    jpeg_start_decompress(&cinfo);
    w = cinfo.output_width;
    h = cinfo.output_height;
    std::vector<unsigned char> grey(w * h);
    while (cinfo.output_scanline < cinfo.output_height) {
        JSAMPROW row = &grey[cinfo.output_scanline * w];
        jpeg_read_scanlines(&cinfo, &row, 1);
    }
    jpeg_finish_decompress(&cinfo);
    jpeg_destroy_decompress(&cinfo);
    return grey;
}

HeightGrid grey_grid(const std::vector<unsigned char>& grey, std::size_t w, std::size_t h) {
    HeightGrid g;
    g.width = w;
    g.height = h;
    g.bits = 8;
    g.peak = 255;
    g.z.assign(grey.begin(), grey.end());
    return g;
}

std::vector<unsigned char> to_bytes(const std::vector<double>& v) {
    std::vector<unsigned char> out(v.size());
    for (std::size_t i = 0; i < v.size(); ++i)
        out[i] = static_cast<unsigned char>(std::clamp(std::lround(v[i]), 0L, 255L));
    return out;
}

// A real test image made grey, its central square averaged down to side x side.
bool real_image(const char* path, std::size_t side, HeightGrid& out) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return false;
    const std::vector<unsigned char> file((std::istreambuf_iterator<char>(in)),
                                          std::istreambuf_iterator<char>());
    std::size_t w = 0, h = 0;
    const auto grey = jpeg_decode(file.data(), file.size(), w, h);
    const std::size_t square = std::min(w, h), x0 = (w - square) / 2, y0 = (h - square) / 2;
    std::vector<double> z(side * side, 0.0), n(side * side, 0.0);
    for (std::size_t y = 0; y < square; ++y)
        for (std::size_t x = 0; x < square; ++x) {
            const std::size_t i = (y * side / square) * side + x * side / square;
            z[i] += grey[(y0 + y) * w + x0 + x];
            n[i] += 1;
        }
    for (std::size_t i = 0; i < z.size(); ++i) z[i] /= n[i];
    out = grey_grid(to_bytes(z), side, side);
    return true;
}

void write_grey_png(const HeightGrid& g, const std::string& path) {
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    png.width = static_cast<png_uint_32>(g.width);
    png.height = static_cast<png_uint_32>(g.height);
    png.format = PNG_FORMAT_GRAY;
    const auto bytes = to_bytes(g.z);
    if (!png_image_write_to_file(&png, path.c_str(), 0, bytes.data(), 0, nullptr))
        fmt::print(stderr, "cannot write {}\n", path);
}

// ---- matplotlib's sample data ----

std::vector<unsigned char> read_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::uint32_t little(const unsigned char* p, int bytes) {
    std::uint32_t v = 0;
    for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | p[i];
    return v;
}

// One member of a zip archive (stored or deflated), or empty.
std::vector<unsigned char> zip_member(const std::vector<unsigned char>& zip, const std::string& name) {
    std::size_t at = 0;
    while (at + 30 <= zip.size() && little(&zip[at], 4) == 0x04034b50) {
        const std::uint32_t method = little(&zip[at + 8], 2), packed = little(&zip[at + 18], 4),
                            size = little(&zip[at + 22], 4), name_length = little(&zip[at + 26], 2),
                            extra = little(&zip[at + 28], 2);
        const std::size_t data = at + 30 + name_length + extra;
        if (data + packed > zip.size()) break;
        const std::string member(zip.begin() + static_cast<long>(at + 30),
                                 zip.begin() + static_cast<long>(at + 30 + name_length));
        if (member == name) {
            std::vector<unsigned char> out(size);
            if (method == 0) {
                std::copy_n(zip.begin() + static_cast<long>(data), size, out.begin());
                return out;
            }
            z_stream z{};
            if (method != 8 || inflateInit2(&z, -MAX_WBITS) != Z_OK) return {};
            z.next_in = const_cast<unsigned char*>(&zip[data]);
            z.avail_in = packed;
            z.next_out = out.data();
            z.avail_out = size;
            const int status = inflate(&z, Z_FINISH);
            inflateEnd(&z);
            return status == Z_STREAM_END ? out : std::vector<unsigned char>{};
        }
        at = data + packed;
    }
    return {};
}

// A 2-D little-endian int16 .npy array (C order) as a height grid.
bool npy_int16_grid(const std::vector<unsigned char>& npy, HeightGrid& out) {
    if (npy.size() < 10 || npy[0] != 0x93 || npy[6] != 1) return false;
    const std::size_t header = little(&npy[8], 2);
    const std::string dict(npy.begin() + 10, npy.begin() + static_cast<long>(10 + header));
    std::size_t rows = 0, cols = 0;
    if (dict.find("'<i2'") == std::string::npos || dict.find("'fortran_order': False") == std::string::npos ||
        std::sscanf(dict.c_str() + dict.find("'shape'"), "'shape': (%zu, %zu)", &rows, &cols) != 2 ||
        npy.size() < 10 + header + 2 * rows * cols)
        return false;
    out.width = cols;
    out.height = rows;
    out.z.resize(rows * cols);
    for (std::size_t i = 0; i < rows * cols; ++i)
        out.z[i] = static_cast<std::int16_t>(little(&npy[10 + header + 2 * i], 2));
    return true;
}

// The central square of a grid averaged down to side x side, scaled to 8 bits over its range.
HeightGrid central_square_8bit(const HeightGrid& g, std::size_t side) {
    const std::size_t square = std::min(g.width, g.height), x0 = (g.width - square) / 2,
                      y0 = (g.height - square) / 2;
    std::vector<double> z(side * side, 0.0), n(side * side, 0.0);
    for (std::size_t y = 0; y < square; ++y)
        for (std::size_t x = 0; x < square; ++x) {
            const std::size_t i = (y * side / square) * side + x * side / square;
            z[i] += g.z[(y0 + y) * g.width + x0 + x];
            n[i] += 1;
        }
    for (std::size_t i = 0; i < z.size(); ++i) z[i] /= n[i];
    const auto [lo, hi] = std::minmax_element(z.begin(), z.end());
    const double low = *lo, span = *hi - *lo;
    for (double& v : z) v = std::round((v - low) / span * 255.0);
    return grey_grid(to_bytes(z), side, side);
}

// Least-squares PFIF and RFIF fits of a rough 1-D signal: errors before and after 8-bit quantisation
// of the parameters, model size and ratio against the samples stored as 16-bit integers.
void signal_table(const std::string& title, const Samples& data) {
    fmt::print("\n{} ({} samples)\n", title, data.size());
    fmt::print("  {:<14} {:>10} {:>9} {:>10} {:>9} {:>6} {:>6} {:>8}\n", "model", "max error", "PSNR dB",
               "max (8-bit)", "PSNR 8-bit", "bytes", "ratio", "seconds");
    struct Run {
        bool recurrent;
        int maps, grid;
    };
    for (const Run& run : {Run{false, 8, 48}, Run{false, 16, 48}, Run{true, 8, 0}, Run{true, 16, 0},
                           Run{true, 32, 0}, Run{true, 64, 0}}) {
        LeastSquaresOptions options;
        options.maps = run.maps;
        options.recurrent = run.recurrent;
        if (run.grid) options.grid = run.grid;
        const auto start = std::chrono::steady_clock::now();
        FractalFunction f = fit_least_squares(data, options);
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const FitError raw = measure(f, data);
        quantize8(f, data);
        const FitError e = measure(f, data);
        const std::size_t bytes = f.parameter_count(); // 8-bit parameters
        fmt::print("  {:<14} {:>10.4g} {:>9.2f} {:>10.4g} {:>9.2f} {:>6} {:>6.1f} {:>8.2f}\n",
                   fmt::format("{} {} maps", run.recurrent ? "RFIF" : "PFIF", run.maps), raw.max_error,
                   raw.psnr, e.max_error, e.psnr, bytes,
                   2.0 * static_cast<double>(data.size()) / static_cast<double>(bytes), seconds);
    }
}

void compression_table(const std::string& title, const HeightGrid& data) {
    FitOptions options;
    options.max_iterations = 60;
    const FitResult fit = fit_patch(data, options);
    const PatchParameters layout(options.shape);
    const PatchEvaluator evaluator(layout, data);
    const double data_bytes = static_cast<double>(data.z.size());
    fmt::print("\n{} ({} x {} grey, 8 bits, {} bytes); fit: {} parameters, {} iterations, {:.1f} s\n", title,
               data.width, data.height, data.z.size(), layout.count(), fit.iterations, fit.seconds);
    fmt::print("  {:<34} {:>9} {:>7} {:>8}\n", "coding", "PSNR (dB)", "bytes", "ratio");
    const auto original = to_bytes(data.z);
    for (const int bits : {16, 8}) {
        const QuantizedModel model = quantize(layout, fit.params, bits);
        // The reconstruction is an image too: its values rounded to 8 bits.
        auto approx = evaluator.approximation(model.params);
        for (double& v : approx) v = std::clamp(std::round(v), 0.0, 255.0);
        const ErrorStats s = error_stats(data, approx);
        fmt::print("  {:<34} {:>9.2f} {:>7} {:>8.2f}\n",
                   fmt::format("projected IFS, {}-bit parameters", bits), s.psnr, model.bytes,
                   data_bytes / static_cast<double>(model.bytes));
        // JPEG at the best quality whose file is no larger than the model.
        std::vector<unsigned char> best;
        int best_quality = 0;
        for (int q = 1; q <= 100; ++q) {
            auto jpg = jpeg_encode(original, data.width, data.height, q);
            if (jpg.size() <= model.bytes) best = std::move(jpg), best_quality = q;
        }
        if (best.empty()) {
            const auto smallest = jpeg_encode(original, data.width, data.height, 1);
            fmt::print("  {:<34} {:>9} {:>7} {:>8}  (quality 1 takes {} bytes)\n", "JPEG at this size", "-",
                       "-", "-", smallest.size());
            continue;
        }
        std::size_t w = 0, h = 0;
        const auto decoded = jpeg_decode(best.data(), best.size(), w, h);
        const ErrorStats js = error_stats(data, std::vector<double>(decoded.begin(), decoded.end()));
        fmt::print("  {:<34} {:>9.2f} {:>7} {:>8.2f}\n", fmt::format("JPEG quality {}", best_quality),
                   js.psnr, best.size(), data_bytes / static_cast<double>(best.size()));
    }
}

} // namespace

int main(int argc, char** argv) {
    const int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 3;
    const std::string out_dir = argc > 2 ? argv[2] : ".";
    const std::size_t side = 82; // 3^4 + 1: seed 003's tabulation at depth 4
    const HeightGrid paraboloid = elliptic_paraboloid(side, side);
    {
        std::ofstream csv(out_dir + "/paraboloid_82.csv");
        csv << "# z = 1 - (x - 0.5)^2 - ((y - 0.5) / 0.7)^2 on [0, 1]^2 (seed 003 sec. 4.3)\n";
        for (std::size_t y = 0; y < side; ++y)
            for (std::size_t x = 0; x < side; ++x)
                csv << fmt::format("{:.9g}{}", paraboloid.at(x, y), x + 1 < side ? ", " : "\n");
    }

    fmt::print(
        "Projected-IFS fit of the elliptic paraboloid, {} x {} samples, 3 x 3 sub-patches, 4 x 4 control "
        "points (Ceres Levenberg-Marquardt, dense normal equations)\n",
        side, side);
    std::vector<double> exact_paper, exact_high, fd_paper, fd_high, exact_iter, fd_iter;
    int exact_its = 0, fd_its = 0;
    for (int r = 0; r < repeats; ++r) {
        const SpeedRun e = time_fit(paraboloid, Derivatives::exact);
        const SpeedRun f = time_fit(paraboloid, Derivatives::finite_differences);
        exact_paper.push_back(e.to_paper), exact_high.push_back(e.to_high);
        fd_paper.push_back(f.to_paper), fd_high.push_back(f.to_high);
        exact_iter.push_back(e.seconds / std::max(1, e.iterations));
        fd_iter.push_back(f.seconds / std::max(1, f.iterations));
        exact_its = e.iterations, fd_its = f.iterations;
    }
    fmt::print("  {:<22} {:>14} {:>14} {:>11} {:>14}\n", "derivatives", fmt::format("s to {} dB", paper_psnr),
               fmt::format("s to {} dB", high_psnr), "iterations", "s / iteration");
    fmt::print("  {:<22} {:>14.3f} {:>14.3f} {:>11} {:>14.4f}\n", "exact (analytic)", median(exact_paper),
               median(exact_high), exact_its, median(exact_iter));
    fmt::print("  {:<22} {:>14.3f} {:>14.3f} {:>11} {:>14.4f}\n", "forward differences", median(fd_paper),
               median(fd_high), fd_its, median(fd_iter));
    fmt::print(
        "  speed-up of the exact Jacobian (medians of {}): {:.1f}x to {} dB, {:.1f}x to {} dB, {:.1f}x per "
        "iteration\n",
        repeats, median(fd_paper) / median(exact_paper), paper_psnr, median(fd_high) / median(exact_high),
        high_psnr, median(fd_iter) / median(exact_iter));

    HeightGrid paraboloid8 = paraboloid;
    const auto [lo, hi] = std::minmax_element(paraboloid.z.begin(), paraboloid.z.end());
    for (double& v : paraboloid8.z) v = std::round((v - *lo) / (*hi - *lo) * 255.0);
    paraboloid8.peak = 255;
    paraboloid8.bits = 8;
    compression_table("The elliptic paraboloid as an 8-bit image", paraboloid8);
    for (const auto& [path, png] : real_images) {
        HeightGrid image;
        if (!real_image(path, side, image)) {
            fmt::print("\n{} is missing (xplanet-images, scripts/install-deps.sh): not compared\n", path);
            continue;
        }
        write_grey_png(image, out_dir + "/" + png);
        compression_table(fmt::format("{}, central square averaged down", path), image);
    }

    // Real rough data shipped by Debian (python-matplotlib-data).
    const std::string dem_path = std::string(sample_data) + "jacksboro_fault_dem.npz";
    HeightGrid dem;
    if (!npy_int16_grid(zip_member(read_bytes(dem_path), "elevation.npy"), dem)) {
        fmt::print("\n{} is missing or unreadable (python-matplotlib-data, scripts/install-deps.sh)\n",
                   dem_path);
    } else {
        const HeightGrid dem8 = central_square_8bit(dem, side);
        write_grey_png(dem8, out_dir + "/dem_82.png");
        compression_table(fmt::format("{} (elevation {} x {}), central square averaged down", dem_path,
                                      dem.height, dem.width),
                          dem8);
    }
    const std::string eeg_path = std::string(sample_data) + "eeg.dat";
    const std::vector<unsigned char> eeg = read_bytes(eeg_path);
    if (eeg.size() != 800 * 4 * sizeof(double)) {
        fmt::print("\n{} is missing (python-matplotlib-data, scripts/install-deps.sh)\n", eeg_path);
    } else {
        Samples signal;
        std::ofstream csv(out_dir + "/eeg_channel0.csv");
        csv << "t,x\n";
        for (std::size_t i = 0; i < 800; ++i) {
            double v = 0;
            std::memcpy(&v, &eeg[i * 4 * sizeof(double)], sizeof v);
            signal.t.push_back(static_cast<double>(i) / 799.0);
            signal.x.push_back(v);
            csv << fmt::format("{},{}\n", signal.t.back(), v);
        }
        signal_table(fmt::format("{}, channel 0", eeg_path), signal);
    }
    return 0;
}
