// Conservative rasterisation of a chart outline into texel rows, for the
// bitmap packer.
//
// Inputs:  outline  a simple closed polygon (a disk chart's boundary loop) in
//                   texel units, already turned and scaled; every point must
//                   have x, y >= 0.
// Output:  RowMask  per texel row j (the strip j <= y < j + 1) the sorted,
//                   disjoint, non-adjacent inclusive texel intervals [a, b]
//                   of every texel [i, i+1) x [j, j+1) that holds a point of
//                   the polygon (boundary or interior).
//
// Method: a texel is touched either by the boundary (each segment, clipped to
// a row strip, marks the texels of its x-range) or lies wholly inside, and
// then its centre is inside (even-odd crossings of the row's centre line).
// dilate() grows a mask by r texels in the Chebyshev metric (a square of side
// 2r + 1): two masks, one dilated by r, that share no texel keep more than r
// texels of index apart along x or y, so their polygons stay at least r
// texels apart.
#pragma once

#include <array>
#include <vector>

#include "soupuv/vec.h"

namespace soupuv::atlas {

struct Interval {
  int a, b;  // inclusive texel columns
};

// Rows stored flat: row r's intervals are spans[first[r] .. first[r+1]).
struct RowMask {
  int width = 0;   // 1 + largest column used
  int height = 0;  // rows; row 0 is the strip 0 <= y < 1
  std::vector<int> first;
  std::vector<Interval> spans;
  long long texels = 0;
};

RowMask rasterize_outline(const std::vector<Vec2>& outline);

// The same for a region bounded by any set of segments (points[a] to
// points[b]): the boundary edges of a UV island that need not be a disk
// (holes, several loops). The region is what the even-odd rule puts inside,
// which for an island without overlap is exactly its triangles.
RowMask rasterize_segments(const std::vector<Vec2>& points,
                           const std::vector<std::array<int, 2>>& segments);

// The mask grown by r texels on every side; the result's row/column 0 is the
// input's -r.
RowMask dilate(const RowMask& mask, int r);

}  // namespace soupuv::atlas
