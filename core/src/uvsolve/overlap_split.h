// Cuts islands whose image laps over itself (private to the UV solve).
//
// Input : a layout with positively oriented triangles (after the solve) and
//         the sample spacing `cell` in UV units (finer than the texels the
//         map will be judged and baked at).
// Output: islands split until none covers a sample point twice: each island
//         is re-grown breadth first (through shared edges) from the triangle
//         nearest its area centroid, a triangle joining only if none of the
//         sample points strictly inside it (half-open edges, so two triangles
//         side by side never share one) is taken; what is left seeds further
//         pieces the same way. Pieces become islands (their shared vertices
//         split), which the packer keeps apart. Overlaps thinner than a
//         cell are not seen.
// Cost  : O(triangles + sample points covered) per island.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "uvsolve/uv_layout.h"

namespace soupuv::uvsolve::detail {

struct OverlapSplitFigures {
  size_t overlapping_islands = 0;  // islands that had to be split
  size_t pieces_added = 0;
  size_t singleton_pieces = 0;     // pieces of one triangle
  size_t unfolded_singletons = 0;  // of those, triangles the fold cut unfolded
  double cell = 0;
};

// The share of an island's samples it may cover twice (a noisy scan's
// sliver folds; the overlap target is 1 % of the covered area).
constexpr double kLapShare = 0.002;

// Sample points (the same rule, spacing `cell`) covered twice or more by
// the triangles `tris` (counter-clockwise): 0 when they do not overlap.
size_t overlap_samples(const UvLayout& layout, const std::vector<uint32_t>& tris, double cell);
size_t overlap_samples(const std::vector<std::array<Vec2, 3>>& triangles, double cell);

OverlapSplitFigures split_overlaps(double cell, int threads, UvLayout& layout);

}  // namespace soupuv::uvsolve::detail
