// The soup's UV map as a mesh (private to the UV solve): every soup triangle
// has three layout vertices, a vertex has one UV, and every triangle belongs
// to one island. Corners that share a vertex are continuous by construction;
// the stages of the UV solve (soup_uv_solve.h) only ever cut (give a corner
// its own vertex) or move vertices, so continuity is decided in one place.
#pragma once

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "soupuv/geometry/weld.h"
#include "soupuv/soup.h"
#include "soupuv/vec.h"

namespace soupuv::uvsolve::detail {

struct UvLayout {
  std::vector<std::array<uint32_t, 3>> corner_vertex;  // per soup triangle
  std::vector<Vec2> uv;                                 // per layout vertex
  std::vector<uint32_t> island;                         // per soup triangle
  uint32_t island_count = 0;
  // Per soup triangle: placed by the fold cut's unfolding rather than by
  // the transfer (empty: none); the overlap split gives these way.
  std::vector<uint8_t> unfolded;
};

// Twice the signed UV area of triangle t (positive: counter-clockwise in the
// soup's corner order).
double signed_area2(const UvLayout& layout, size_t t);

// Gives every (vertex, island) pair its own vertex, so no vertex is shared by
// two islands (an island's vertices can move without touching another's).
void split_vertices_by_island(UvLayout& layout);

// Components of the triangles with active[t] != 0 (all when active is null)
// that share an edge (two layout vertices); -> component per triangle
// (UINT32_MAX for inactive ones) and the count.
uint32_t edge_components(const std::vector<std::array<uint32_t, 3>>& corner_vertex,
                         const std::vector<uint8_t>* active, std::vector<uint32_t>& component);

// Island ids made dense again after islands were joined or emptied: ids
// numbered in the order of their first triangle, ids no triangle uses
// dropped; island_count updated.
void compact_island_ids(UvLayout& layout);

// Share of the weld's adjacent pairs whose two shared corners still share
// layout vertices: the continuity a layout keeps (cuts only lower it).
double kept_pair_share(const std::vector<geometry::AdjacentPair>& pairs, const UvLayout& layout);

// The triangles of each island, in soup order.
std::vector<std::vector<uint32_t>> island_triangles(const UvLayout& layout);

// The seams between islands: for each two islands that share welded pairs,
// the key (smaller id << 32 | larger id) and the pair count, the longest
// seam first (equal ones by key).
std::vector<std::pair<uint64_t, uint32_t>> seams_longest_first(const std::vector<geometry::AdjacentPair>& pairs,
                                                               const UvLayout& layout);

}  // namespace soupuv::uvsolve::detail
