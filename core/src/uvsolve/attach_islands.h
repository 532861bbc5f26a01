// Small islands attached to a neighbouring island (private to the UV solve).
//
// Input : the soup, its weld's adjacent pairs (geometry::edge_adjacency), a
//         layout whose islands are oriented, flattened and overlap-free, the
//         rest scale (UV units per 3D length), the collapse ratio
//         (untangle.h), a stretch budget, the largest island area
//         attached and the largest area an attached island may lap over
//         its host (both UV units squared).
// Output: every island of at most that area (and kMaxTriangles) that shares
//         welded edges with another island is tried against those islands,
//         most shared edges first: it is turned and moved rigidly onto the
//         host (2D Procrustes on the shared corners, the host does not move),
//         its shared corners become the host's vertices, and the attachment
//         is kept only if none of its triangles folds or collapses, its L2
//         stretch against its soup triangles stays within the budget, none
//         of its triangles overlaps another of its own, and the area its
//         triangles lap over the host's is at most the lap budget (exact
//         triangle intersections against the host's triangles near it,
//         found in a grid of the layout). Smallest islands first; an island that
//         attached is part of its host for the islands after it.
// Why   : each island costs the packing its padding on every side. On the
//         noisy scans most islands are one or two triangles finer than a
//         few texels, and their padding, not their area, filled the
//         texture (docs/tuning.md). Noise leaves most of them lapping
//         their host by a sliver: a lap of a fraction of a texel is
//         below what a bake resolves, a padding of two texels a side is
//         not. Larger islands are left alone: joined
//         rigidly they make shapes that pack worse (a cube's faces in an L).
// Cost  : O(n) to build the grid, then per attempt O(island + the host's
//         triangles within reach).
#pragma once

#include <cstddef>
#include <vector>

#include "soupuv/geometry/weld.h"
#include "uvsolve/uv_layout.h"

namespace soupuv::uvsolve::detail {

struct AttachFigures {
  size_t candidates = 0;  // small islands with a neighbour
  size_t attempts = 0;
  size_t attached = 0;
  size_t refused_fold = 0, refused_stretch = 0, refused_overlap = 0;
  size_t attached_with_lap = 0;  // kept with a lap within the budget
  double lapped_area = 0;        // their laps' sum, UV units squared
};

AttachFigures attach_small_islands(const Soup& soup, const std::vector<geometry::AdjacentPair>& pairs,
                                   double uv_per_length, double collapse_ratio, double max_stretch,
                                   double max_area, double max_lap_area, UvLayout& layout);

}  // namespace soupuv::uvsolve::detail
