// Small islands attached to a neighbouring island (private to the UV solve).
//
// Input : the soup, its weld's adjacent pairs (geometry::edge_adjacency), a
//         layout whose islands are oriented, flattened and overlap-free, the
//         rest scale (UV units per 3D length), the collapse ratio
//         (untangle.h), a stretch budget and the largest island area
//         attached (UV units squared).
// Output: every island of at most that area (and kMaxTriangles) that shares
//         welded edges with another island is tried against those islands,
//         most shared edges first: it is turned and moved rigidly onto the
//         host (2D Procrustes on the shared corners, the host does not move),
//         its shared corners become the host's vertices, and the attachment
//         is kept only if none of its triangles folds or collapses, its L2
//         stretch against its soup triangles stays within the budget, and
//         none of its triangles overlaps a triangle of the host (exact
//         triangle tests against the host's triangles near it, found in a
//         grid of the layout). Smallest islands first; an island that
//         attached is part of its host for the islands after it.
// Why   : each island costs the packing its padding on every side. On the
//         noisy scans most islands are one or two triangles finer than a
//         few texels, and their padding, not their area, filled the
//         texture (docs/tuning.md). Larger islands are left alone: joined
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
};

AttachFigures attach_small_islands(const Soup& soup, const std::vector<geometry::AdjacentPair>& pairs,
                                   double uv_per_length, double collapse_ratio, double max_stretch,
                                   double max_area, UvLayout& layout);

}  // namespace soupuv::uvsolve::detail
