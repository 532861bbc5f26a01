// Chart-boundary correction (paper §8).
//
// Input : the soup, the proxy landing point of each corner, proxy + atlas.
// Output: corrected corner UVs for every triangle whose corners landed on
//         different charts: for each candidate chart (one of the corners'
//         charts) the corners on other charts move to their closest point on
//         that chart; the chart whose UV triangle area, at the atlas's global
//         texel scale, differs least from the 3D area wins. Unlike the paper,
//         a moved corner takes the UV of the closest boundary face's linear
//         map extended to its landing point (within four face sizes), not
//         the boundary point's own UV: the triangle keeps its shape instead
//         of being squashed against the seam.
//         The area measure is |log(UV area / 3D area)| (a collapsed candidate
//         costs ~14); a candidate whose UV orientation flips pays 4 more.
//         With the soup's near-neighbour graph, the choice also weighs the
//         neighbours' charts (iterated conditional modes: cost = area measure
//         + 1 per neighbour labelled with another chart), so the cut in
//         the texture follows soup edges rather than zig-zagging; without it,
//         each triangle chooses alone as in the paper.
// Cost  : one BVH per chart, built once: O(n log n); O(log n) per moved corner.
#pragma once

#include <array>
#include <vector>

#include "soupuv/atlas/atlas.h"
#include "soupuv/progress.h"
#include "soupuv/proxy/proxy_mesh.h"
#include "soupuv/geometry/weld.h"
#include "soupuv/soup.h"
#include "soupuv/geometry/surface_hit_bvh.h"

namespace soupuv::transfer {

struct ChartFixResult {
  size_t multi_chart_triangles = 0;
  size_t corrected_triangles = 0;  // triangles whose UVs changed
};

// Updates corner_uvs (and landing) in place.
ChartFixResult fix_chart_boundaries(const Soup& soup, const proxy::ProxyMesh& proxy,
                                    const atlas::Atlas& atlas,
                                    std::vector<geometry::SurfacePoint>& landing,
                                    std::vector<std::array<Vec2, 3>>& corner_uvs,
                                    Progress& progress,
                                    const std::vector<geometry::AdjacentPair>* neighbours = nullptr);

}  // namespace soupuv::transfer
