// Welding soup corners by position, and the edge adjacency that welding
// reveals: the soup's topology, which the field branch (shared seeds, traced
// sides: field/orient), the transfer's §8 neighbours, the UV solve and the
// continuity metrics all need (so it lives below all of them, in geometry/).
//
// Input : a soup, a weld tolerance (absolute length; 0 = exact equality).
// Output: a vertex id per soup corner (triangle*3 + k) such that corners within
//         the tolerance of each other (transitively) share an id, and the list
//         of triangle pairs sharing an edge of welded vertices.
// Cost  : O(n) expected with a uniform hash grid (cells of half the tolerance).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "soupuv/soup.h"

namespace soupuv::geometry {

// Corner id per soup corner (size 3 * triangles); ids are 0 .. count-1.
struct Weld {
  std::vector<uint32_t> corner_vertex;
  uint32_t vertex_count = 0;
};

// Welds go nearest pair first and never join two corners of one triangle,
// even transitively. edge_fraction > 0 additionally refuses to weld two corners farther apart
// than edge_fraction times the shortest edge of either corner's triangle, so
// a tolerance close to the edge length cannot collapse whole regions.
Weld weld_corners(const Soup& soup, double tolerance, double edge_fraction = 0);

// Welds through matched edges instead (geometry/edge_weld.cpp): two triangle
// edges whose endpoints lie within `tolerance` of each other's, matched for
// the least total distance (geometry/pair_matching.h), each edge matched
// once, never two corners of one triangle joined.
// On noisy soups whose noise reaches the shortest edges it joins fewer
// distinct vertices than weld_corners (teapot soup vs its original, 4e-3 vs
// 2e-3 of the diagonal: 257 vs 409 corners on a wrong vertex, 134 vs 430
// false neighbour pairs, 203 vs 284 missed; suzanne, fandisk: none false
// either way). An edge is left unmatched when its second-closest partner is
// within ambiguity_ratio x the closest's cost (1 = off; 2 on the teapot: 10
// false pairs but 837 missed). Corners that share no edge with another
// triangle stay unwelded.
// flipped_neighbours = false matches only edges that run back (consistent
// winding): where the noise reaches the shortest edges a sliver's long edge
// lies near both long edges of its neighbour's side, and a match with the
// one running the same way joins a corner to the wrong vertex; a layout
// built from such a weld has no flat map there (docs/tuning.md, "The edge
// weld's winding"). The pipeline welds this way for the UV stage and the
// field's shared seeds; extend_weld still joins a flipped part's copies by
// distance.
Weld weld_by_edges(const Soup& soup, double tolerance, double ambiguity_ratio = 1,
                   bool flipped_neighbours = true);

// Names weld_by_edges's algorithm in the cache keys of what is computed
// from its result (the UV stage's weld, the field lines' seeds): changes
// whenever the same inputs would weld differently.
inline constexpr const char* kEdgeWeldAlgorithm = "edges-least-cost-matching";

// weld_corners, but starting from the groups of `start` (a weld of the same
// soup, e.g. weld_by_edges): its groups stay joined, and further corners join
// them nearest pair first under the same rules. Where the edge weld left
// copies of a vertex apart (an edge with no clear partner), distance still
// joins them; where it did join, distance cannot split. A start group that
// already holds two corners of one triangle stays as it is.
Weld extend_weld(const Soup& soup, const Weld& start, double tolerance, double edge_fraction = 0);

// Two triangles that share an edge: corner a_corner[i] of triangle a and
// corner b_corner[i] of triangle b are the same welded vertex (i = 0, 1).
struct AdjacentPair {
  uint32_t a = 0, b = 0;
  std::array<uint8_t, 2> a_corner{}, b_corner{};
};

// Edge adjacency of the welded soup. An edge used by more than two triangles
// (non-manifold) pairs every two of them. Degenerate triangles (two corners
// welded together) contribute no edges.
std::vector<AdjacentPair> edge_adjacency(const Weld& weld, size_t triangle_count);

}  // namespace soupuv::geometry
