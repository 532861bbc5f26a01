// Seams between two islands moved to their shortest course (private to the
// UV solve).
//
// Input : the soup, the rest scale (UV units per 3D length), the weld's
//         adjacent pairs (geometry::edge_adjacency), the overlap sample
//         spacing (overlap_split.h), the stretch budget and SLIM iterations
//         of piece_flatten.h, the thread count, and a layout whose islands
//         share no vertex (split_vertices_by_island).
// Output: for each two islands sharing at least kMinSeam welded pairs
//         (the longest seam first), the triangles of both within a band of
//         rings of welded triangles around their seam (three, then one:
//         kBandRings) are divided again between them by a minimum cut of
//         the welded pairs (atlas::FlowGraph; the triangles beyond the
//         band, or the band's farthest ones where an island lies wholly
//         inside it, hold their sides; among the shortest cuts the one
//         moving the fewest triangles). Where that cut is shorter than the
//         seam by at least kMinGain pairs, the triangles that change island
//         are joined onto their new island's map as it stands
//         (local_join.h), or, where that is refused and the budget allows,
//         the island is flattened anew from its own shape
//         (piece_flatten.h); the division is kept only when both islands
//         are one edge-connected piece and kept so (no flip, within the
//         stretch budget, no lap), else the narrower band's is tried.
//         Island ids are kept.
// Why   : the transfer cuts a seam where the proxy's charts meet, and a
//         chart border crosses the soup's triangles at an angle: the seam
//         zigzags, cutting up to twice the pairs of the shortest course
//         between the same two islands, and on closed parts the union
//         merge cannot close it (the union is closed too). The instanced
//         spheres at new seeds kept 0.92-0.94 of their edges (their
//         hemispheres' seams cut 20-24 pairs where the equator cuts 16;
//         docs/tuning.md, session 44). Run before the union merge, whose
//         unions then join along straighter seams.
// Cost  : per seam a breadth-first band and a max-flow on it (serial: both
//         are small), then per shortened seam the joins, all within a
//         budget of kStraightenBudget times the soup's triangles (a join
//         counts the moved triangles' flatten_cost and a kJudgeShare-th of
//         the two islands, for the test; a whole flattening its
//         flatten_cost); seams of disjoint islands are joined on `threads`
//         threads in rounds, so the result does not depend on the thread
//         count.
#pragma once

#include <cstddef>
#include <vector>

#include "soupuv/geometry/weld.h"
#include "uvsolve/uv_layout.h"

namespace soupuv::uvsolve::detail {

struct SeamStraightenFigures {
  size_t seams = 0;      // seams of at least kMinSeam pairs
  size_t shorter = 0;    // of them, with a cut shorter by kMinGain pairs or more
  size_t straightened = 0;  // of those, kept (both islands flattened)
  size_t pairs_gained = 0;  // seam pairs closed by the kept ones
  size_t refused = 0;       // shorter cuts whose flattenings were not both kept
  size_t over_budget = 0;   // shorter cuts not flattened for the budget
};

SeamStraightenFigures straighten_seams(const Soup& soup, double uv_per_length,
                                       const std::vector<geometry::AdjacentPair>& pairs, double cell,
                                       double max_stretch, int solve_iterations, int threads, UvLayout& layout);

}  // namespace soupuv::uvsolve::detail
