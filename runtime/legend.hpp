// A legend under a picture of a cover: a swatch and a word for each cell colour of each panel
// (process: inside, boundary, outside; cover: inside, boundary), drawn with a small built-in bitmap
// font so that pictures explain themselves without a caption.
#pragma once

#include "runtime/picture.hpp"

namespace frac::rt {

// `image` (as render() drew it for `kind`) with a legend strip added below it.
Image with_legend(const Image& image, PictureKind kind);

} // namespace frac::rt
