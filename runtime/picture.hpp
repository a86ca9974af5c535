// Pictures of a 2D subdivision, as in the paper's figures 2-7: on the left the recursive subdivision
// process, on the right the cover.
//
//  - process: every evaluated cell drawn as an outlined square, filled by class: inside dark grey,
//    outside white, boundary red. A subdivided cell is filled like a boundary cell (it was undecided
//    at its level); its children are drawn over it.
//  - cover: only the leaves; boundary cells black on white, inside cells light grey.
//  - both: process on the left, cover on the right, separated by a white gap (max(2, pixels/64)
//    pixels in PNG, 16 units in SVG).
//
// The x axis runs to the right and the y axis up, as in math. A panel keeps the aspect ratio of the
// root box; its longer side is `pixels` long (1024 units in SVG). Pictures use the exact grid
// geometry of the cells, not the outward-rounded boxes (which differ by ulps).
//
// All functions need a 2D result computed with keep_cells; they throw std::invalid_argument
// otherwise ("pictures need a 2D cover; use slices" for 3D).
#pragma once

#include "runtime/cover.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace frac::rt {

enum class PictureKind { process, cover, both };

// An 8-bit RGB image, rows top to bottom.
struct Image {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgb; // width * height * 3 bytes
};

// Raster rendering, `pixels` in [1, 16384] being the longer side of one panel. A pixel takes the
// colour of the most important class among the leaves that meet it with positive area (boundary over
// inside over outside), so a cover never loses a boundary cell however small. Outlines are drawn
// only for cells at least 4 pixels wide; finer cells would merge into solid black.
Image render(const Cover& r, PictureKind kind, int pixels);

// PNG files (libpng). Throw std::runtime_error naming the path and the reason on I/O failure.
void write_png(const Image& image, const std::string& path);
void write_png(const Cover& r, const std::string& path, PictureKind kind, int pixels);

// Plain SVG, one rect per drawn cell, grouped by level and class. The process picture skips the
// levels whose cells are smaller than 0.3 units of its 1024-unit panel (their undecided parents
// already show the region in the boundary colour); the cover picture draws every inside and
// boundary leaf (outside leaves are the white background). Throws std::runtime_error on I/O failure.
void write_svg(const Cover& r, const std::string& path, PictureKind kind);

// A coarse rendering for golden tests: `rows` lines of `columns` characters, each ended by '\n',
// top line = highest y. Each character covers an equal part of the root box and shows the leaves
// that meet that part with positive area: '+' if one is a boundary cell, else ':' if there are both
// inside and outside cells, '#' if all are inside, '.' if all are outside. columns and rows in
// [1, 4096].
std::string ascii_picture(const Cover& r, int columns, int rows);

} // namespace frac::rt
