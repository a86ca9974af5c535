// Sampled surfaces for fitting (seed 003 sec. 4): a grid of heights z(x, y), read from a CSV grid or a
// grey PNG (8-bit: a grey image, 16-bit: heights), or generated (the elliptic paraboloid of sec. 4.3).
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

namespace frac::rt::fit {

// Malformed data: the file, and where in it (line and column of a CSV grid, 0 when the whole file is
// at fault); `source_line` is the offending line of a text file, for the caret.
struct DataError : std::runtime_error {
    std::string file, source_line;
    std::size_t line = 0, column = 0;
    DataError(std::string file, std::size_t line, std::size_t column, const std::string& message,
              std::string source_line = {});
};

struct HeightGrid {
    std::size_t width = 0, height = 0; // samples along x (columns) and y (rows)
    std::vector<double> z;             // z[y * width + x]
    // The peak value of the PSNR: 255 for an 8-bit image, else the range of the data (max - min).
    double peak = 1;
    int bits = 0; // 8 or 16 for PNG data (the size of the original, for the compression ratio); 0: CSV
    double at(std::size_t x, std::size_t y) const { return z[y * width + x]; }
};

// A CSV grid: one row of heights per line, separated by commas (spaces around them allowed); blank
// lines and lines starting with '#' are skipped. Every row has the same number of values; a value
// that is not a finite number is a DataError at its line and column.
HeightGrid read_csv_grid(const std::string& path);
// A grey PNG, 8 bits (an image, peak 255) or 16 bits (heights, peak 65535). Another colour type or
// bit depth, or a file that is not a PNG, is a DataError naming the file.
HeightGrid read_png_grid(const std::string& path);
// By the file's extension: .csv, else .png.
HeightGrid read_height_grid(const std::string& path);

// z = z0 - ((x - x0) / sx)^2 - ((y - y0) / sy)^2 on the grid x, y in [0, 1] (width x height samples),
// the synthetic ground truth of seed 003 sec. 4.3.
HeightGrid elliptic_paraboloid(std::size_t width, std::size_t height, double x0 = 0.5, double y0 = 0.5,
                               double sx = 1.0, double sy = 0.7, double z0 = 1.0);

// The error of an approximation against the data, over all samples.
struct ErrorStats {
    double max_error = 0, mse = 0, psnr = 0; // psnr in dB against grid.peak (infinite when exact)
};
ErrorStats error_stats(const HeightGrid& grid, const std::vector<double>& approximation);

} // namespace frac::rt::fit
