// Slices of 3D covers: the cells of a 3D subdivision that meet an axis-aligned plane, as a 2D cover
// that the picture code draws (PNG, SVG, ASCII: see picture.hpp).
//
// A cell meets the plane axis = value when its outward box (Cover::cell_interval) contains the
// value: the slice never misses a cell whose exact box touches the plane, and a value on a grid
// plane takes the cells of both sides. The slice keeps the 3D classes (inside, outside, boundary,
// subdivided) and levels; where the two sides of a grid plane give one 2D square two different
// classes, both cells are kept and the pictures show the more important one (boundary over inside
// over outside), as for any overlapping leaves.
#pragma once

#include "runtime/cover.hpp"
#include "runtime/picture.hpp"

#include <string>

namespace frac::rt {

// The 2D cover of the cells of `r` meeting the plane axis = value (axis 0, 1, 2 for x, y, z). Its
// axes are the other two in increasing order: (x, y) for a z slice, (x, z) for y, (y, z) for x;
// root, depth and split follow `r`; cells are ordered by level, then (iy, ix), counts recomputed
// over the slice's cells. Needs a 3D result computed with keep_cells; throws
// std::invalid_argument otherwise, for an axis outside 0..2, or a value outside the root box.
Cover slice(const Cover& r, double value, int axis = 2);

// write_png(slice(r, value, axis), path, kind, pixels).
void write_slice_png(const Cover& r, double value, const std::string& path,
                     PictureKind kind = PictureKind::cover, int pixels = 1024, int axis = 2);

} // namespace frac::rt
