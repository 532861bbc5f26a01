// Triangles that zigzag across a seam change sides (private to the UV
// solve).
//
// Input : the soup, its weld's adjacent pairs, a layout whose islands are
//         oriented, flattened and overlap-free, the rest scale (UV units per
//         3D length), the collapse ratio (untangle.h), a stretch budget and
//         the largest area a moved triangle may lap over its new island (UV
//         units squared).
// Output: a triangle welded along two or three of its edges to one other
//         island, all three of its corners to that island's vertices, joins
//         it: its corners take those vertices (no vertex moves), where its
//         image there neither folds nor collapses, its L2 stretch against its
//         soup triangle is within the budget, and it laps the island's
//         triangles by at most the lap budget (island_grid.h). Where its
//         image there fails one of these, the island's vertices within two
//         rings of it are relaxed with it (patch_relax.h: SLIM, the patch's
//         outline held) and it joins if then nothing in the patch folds, it
//         and the patch together are within the budget (or within the
//         patch's own stretch before) and the patch laps within the lap
//         budget.
//         Repeated until nothing moves (a move can make a neighbour a
//         candidate); islands left empty are dropped.
// Why   : where the transfer cut along a seam, triangles whose corners
//         landed on both sides went to one side each, and the seam zigzags
//         across a row of them; the teeth are welded to the other side on
//         two edges and to their own on one. Each move closes two welded
//         pairs and opens at most one, and straightens the islands'
//         outlines the packer must keep apart. The other side's notch was
//         flattened without the tooth, often too narrow or folded shut:
//         relaxed around it, most teeth fit (suzanne: 7 of 11 tried).
// Cost  : O(n) for the grid and the candidates, then per move the island's
//         triangles near it; per relaxed candidate one small SLIM.
#pragma once

#include <cstddef>
#include <vector>

#include "soupuv/geometry/weld.h"
#include "uvsolve/uv_layout.h"

namespace soupuv::uvsolve::detail {

struct SeamSmoothFigures {
  size_t candidates = 0;  // triangle-island pairs tried
  size_t moved = 0;
  size_t relaxed = 0;  // of the moved: with the island's vertices around them relaxed
  size_t refused_fold = 0, refused_stretch = 0, refused_overlap = 0;
  size_t passes = 0;
};

SeamSmoothFigures smooth_seams(const Soup& soup, const std::vector<geometry::AdjacentPair>& pairs,
                               double uv_per_length, double collapse_ratio, double max_stretch,
                               double max_lap_area, UvLayout& layout);

}  // namespace soupuv::uvsolve::detail
