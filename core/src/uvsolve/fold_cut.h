// Cuts where the transferred image folds (private to the UV solve).
//
// Input : the soup, its UV layout (uv_mesh.h), the rest scale (UV units per
//         3D length) and collapse_ratio.
//         Its islands are already oriented (untangle.h: orient_islands).
// Output: the layout with every triangle of positive UV area (in the soup's
//         corner order), so a locally injective solve (SLIM) can start:
//         1. a triangle still flipped, or collapsed (UV area below
//            collapse_ratio x its rest area), is cut out of its island;
//         2. each cut triangle is unfolded back onto a placed neighbour
//            across their shared edge (its third corner placed by its own 3D
//            shape, similar to it: positive by construction; the corner gets
//            a new vertex), breadth first from the islands, so a folded
//            region is re-grown from its borders instead of becoming
//            singletons; cut triangles with no placed neighbour seed a new
//            island at their rest shape.
// Cost  : O(triangles log triangles).
#pragma once

#include <cstddef>

#include "uvsolve/uv_layout.h"

namespace soupuv::uvsolve::detail {

struct FoldCutFigures {
  size_t cut_triangles = 0;     // flipped or collapsed in the transferred map
  size_t unfolded_triangles = 0;  // of those, re-attached to a neighbour
  size_t seeded_islands = 0;    // new islands started from a cut triangle
};

FoldCutFigures cut_folds(const Soup& soup, double uv_per_length, double collapse_ratio,
                         UvLayout& layout);

}  // namespace soupuv::uvsolve::detail
