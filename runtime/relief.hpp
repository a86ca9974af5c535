// A shaded depth image (relief) of a 3D cover seen from above (+z), as libfive and Fidget render 3D
// shapes as heightmaps with normals: each pixel takes the top of the highest inside or boundary leaf
// over it; normals from the height differences of neighbouring pixels light it from the upper left.
// Boundary cells are tinted, so the undecided shell shows where the cover is not yet resolved.
#pragma once

#include "runtime/cover.hpp"
#include "runtime/picture.hpp"

namespace frac::rt {

// The relief of a 3D result computed with keep_cells; `pixels` in [16, 16384] is the longer side (the
// image has the x:y aspect of the root box). Throws std::invalid_argument for a 2D result or one
// without cells.
Image relief_image(const Cover& r, int pixels);

} // namespace frac::rt
