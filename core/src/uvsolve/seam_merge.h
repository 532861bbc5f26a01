// Joins islands across the seams between them (private to the UV solve).
//
// Input : the soup, its weld's adjacent pairs (geometry::edge_adjacency), a
//         layout whose islands are flattened and overlap-free, the sample
//         spacing of overlap_split.h, the collapse ratio (untangle.h), the
//         stretch budget of piece_flatten.h and an attempt budget.
// Output: islands joined where the transfer or the splits cut a seam that a
//         flat map can close: for each pair of islands that share welded
//         edges (longest shared seam first), the smaller is turned and moved
//         rigidly onto the larger (2D Procrustes on the shared corners), the
//         shared corners become one vertex at their mean (where that folds a
//         triangle, joined islands of at most max_relax_triangles are relaxed
//         as rigidly as possible, untangle.h), and the join is kept only if
//         no triangle of the two folds or collapses and the joined island
//         covers no sample twice, and its L2 stretch against its soup
//         triangles (piece_flatten.h's rest_stretch_l2) is within the
//         stretch budget or no worse than the two islands' together before.
//         A later solve (island_solve.h) smooths the stretch the join left
//         along the seam.
// Cost  : per attempt O(the two islands' triangles + their samples).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "soupuv/geometry/weld.h"
#include "uvsolve/uv_layout.h"

namespace soupuv::uvsolve::detail {

struct SeamMergeFigures {
  size_t attempts = 0;
  size_t joined = 0;
  size_t refused_fold = 0, refused_overlap = 0, refused_stretch = 0;
  std::vector<uint8_t> joined_island;  // per island after the merge: 1 if a join made it
};

SeamMergeFigures merge_seams(const Soup& soup, const std::vector<geometry::AdjacentPair>& pairs,
                             double cell, double uv_per_length, double collapse_ratio, double max_stretch,
                             size_t max_attempts, size_t max_relax_triangles, UvLayout& layout);

}  // namespace soupuv::uvsolve::detail
