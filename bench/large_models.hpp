// Big, realistic 2D F-rep models written in the .frac language, as exporters of real scenes write
// them: text drawn with a stroke font (each stroke a capsule, the distance to a segment: clamp,
// squares written as products `u * u`, sqrt), architectural CSG (walls with windows cut out,
// columns, arches) and random smooth blends of disks and rectangles. Everything is inlined with
// numeric literals and grouped into a balanced tree of min (a glyph is the min of its strokes, a word
// of its glyphs, ...), so the tape has thousands of min/max instructions.
//
// A clause is one primitive of the model (a stroke, a wall, a window, a column, a blended pair): the
// generated model has exactly `clauses` of them. The output depends only on (clauses, seed).
#pragma once

#include <cstdint>
#include <string>

namespace frac::bench {

struct LargeModel {
    std::string name;   // of the shape (and the file's stem)
    std::string source; // a complete .frac file with one shape `name`
    int clauses = 0;
};

LargeModel large_model(int clauses, std::uint64_t seed = 1);

} // namespace frac::bench
