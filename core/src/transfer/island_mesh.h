// The UV islands of a map as meshes (private to the transfer module; the
// island relaxation works on them).
//
// Input : one or two welds (corner -> welded vertex), corner UVs, the soup (for the
//         copies' 3D distance), the continuity test's texel and scale.
// Output: island vertices — the corners of one welded vertex whose UVs are
//         within texel + 2 x (3D distance) x uv_per_length of each other,
//         transitively (the continuity metric's test), one vertex each,
//         placed at their corners' mean UV — and islands: components of
//         triangles sharing an island vertex, largest first.
// Cost  : O(corners + sum over welded vertices of copies^2).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "soupuv/quality/weld.h"
#include "soupuv/soup.h"

namespace soupuv::transfer::detail {

struct IslandMeshes {
  std::vector<uint32_t> vertex_of_corner;  // corner -> island vertex
  std::vector<Vec2> vertex_uv;             // mean of its corners' UVs
  std::vector<std::vector<uint32_t>> islands;  // soup triangles, largest island first
  size_t snapped_corners = 0;  // corners whose UV differs from their vertex's
};

// `also` (may be null): a second weld of the same soup whose groups are
// tested too (a copy one weld missed, the other may join).
IslandMeshes island_meshes(const Soup& soup, const quality::Weld& weld, const quality::Weld* also,
                           const std::vector<std::array<Vec2, 3>>& corner_uvs, double texel,
                           double uv_per_length);

}  // namespace soupuv::transfer::detail
