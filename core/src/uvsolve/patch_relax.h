// Relaxes a patch of one island around a few of its vertices, the patch's
// outer vertices held (private to the UV solve; seam_smooth.h uses it).
//
// Input : the soup, the rest scale (UV units per 3D length), the layout,
//         every layout vertex's triangles (VertexTriangles), the seed
//         vertices (all of one island), how many vertex rings around them
//         the patch takes, and SLIM's iteration count.
// Output: the patch: the island's triangles within `rings` rings of the
//         seeds, its free vertices (those whose every triangle is in the
//         patch) and their UVs after SLIM (transfer/slim.h) on the
//         symmetric Dirichlet energy against each soup triangle's own shape,
//         every other patch vertex fixed. `relaxed` is false when no vertex
//         is free or a patch triangle starts flipped or degenerate (SLIM's
//         barrier needs a valid start). The layout is not changed.
// Why   : a triangle joining an island across a seam (seam_smooth.h) takes
//         the island's vertices as they are, and the notch it fills was
//         flattened without it: often too narrow or too wide for it. Moving
//         the few vertices around the notch lets it fit without touching
//         the rest of the island.
// Cost  : O(patch) to gather it and per SLIM iteration one sparse
//         factorisation of the patch.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "soupuv/soup.h"
#include "uvsolve/uv_layout.h"

namespace soupuv::uvsolve::detail {

// Per layout vertex, the triangles whose corners use it.
struct VertexTriangles {
  std::vector<std::vector<uint32_t>> of;
  explicit VertexTriangles(const UvLayout& layout);
  void add(uint32_t t, const std::array<uint32_t, 3>& corners);
  void remove(uint32_t t, const std::array<uint32_t, 3>& corners);
};

struct RelaxedPatch {
  std::vector<uint32_t> triangles;  // soup triangles of the patch
  std::vector<uint32_t> vertices;   // free layout vertices
  std::vector<Vec2> uv;             // their UVs after the relaxation
  bool relaxed = false;
};

RelaxedPatch relax_patch(const Soup& soup, double uv_per_length, const UvLayout& layout,
                         const VertexTriangles& incidence, const std::vector<uint32_t>& seeds, int rings,
                         int iterations);

}  // namespace soupuv::uvsolve::detail
