// The transferred map as a UV layout (private to the UV solve).
//
// Input : the soup, a weld of its corners (geometry::Weld), the transferred
//         corner UVs, each corner's landing chart, the continuity tolerance
//         (texel: UV units; uv_per_length: UV units per 3D length).
// Output: a UvLayout whose vertices join the corners of one welded vertex
//         that landed on the same chart within texel + 2 x (their 3D
//         distance) x uv_per_length of each other (the continuity metric's
//         test, eval/uvmetrics.py), at their mean UV; islands = components
//         joined through shared edges. Corners that miss the test get their
//         own vertex: the transfer's discontinuities become cuts.
// Cost  : O(corners x copies per welded vertex).
#pragma once

#include <array>
#include <vector>

#include "soupuv/geometry/weld.h"
#include "uvsolve/uv_layout.h"

namespace soupuv::uvsolve::detail {

UvLayout build_uv_mesh(const Soup& soup, const geometry::Weld& weld,
                       const std::vector<std::array<Vec2, 3>>& corner_uvs,
                       const std::vector<int>& corner_chart, double texel, double uv_per_length);

}  // namespace soupuv::uvsolve::detail
