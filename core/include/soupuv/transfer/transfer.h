// Transfer (paper §7.6, §8): where each soup corner's field line first meets
// the proxy, and the atlas UV there; then the chart-boundary correction.
//
// Input : the soup, its traced field lines (one per corner, any subset), the
//         proxy mesh and its atlas.
// Output: three UVs per soup triangle, the proxy point each corner landed on,
//         hit / fallback counts and the number of triangles the chart-boundary
//         correction changed.
//
// Fallback for a line that never crosses the proxy (trapped inside a closed
// part, step limit, stalled): first a ray from its last point along its last
// direction (a line cut short by the step limit is still heading outward);
// if that misses too, the proxy point closest to the corner itself. A line
// that ended trapped (it crawled along the soup) goes to the closest point
// at once: its last direction is tangent to the surface. A corner
// without a line gets the closest proxy point. Both are counted.
#pragma once

#include <array>
#include <vector>

#include <nlohmann/json.hpp>

#include "soupuv/atlas/atlas.h"
#include "soupuv/field/field_lines.h"
#include "soupuv/progress.h"
#include "soupuv/proxy/proxy_mesh.h"
#include "soupuv/geometry/weld.h"
#include "soupuv/soup.h"
#include "soupuv/geometry/surface_hit_bvh.h"

namespace soupuv::transfer {

struct TransferOptions {
  bool fix_chart_boundaries = true;  // §8
  // The soup's near-neighbour graph (a weld's edge adjacency) for the §8
  // choice, so neighbours pick the same chart (chart_fix.h); nullptr: each
  // triangle alone. Must outlive the call.
  const std::vector<geometry::AdjacentPair>* neighbours = nullptr;
  int threads = 0;                   // OpenMP threads; 0 = default
};

struct TransferResult {
  std::vector<std::array<Vec2, 3>> corner_uvs;  // per soup triangle
  std::vector<geometry::SurfacePoint> landing;            // per corner (triangle*3+k): proxy face, bary
  // Per corner, for the discontinuity breakdown: its line missed the proxy
  // (a fallback placed it), and the chart it landed on before the §8 correction.
  std::vector<uint8_t> missed;
  std::vector<int> first_chart;
  size_t lines = 0;
  size_t hits = 0;              // lines whose polyline crosses the proxy
  size_t fallback_ray = 0;      // missed; the extended last direction hit
  size_t fallback_closest = 0;  // missed everything (or no line): closest proxy point
  size_t untraced_corners = 0;  // corners without a line (part of fallback_closest)
  size_t multi_chart_triangles = 0;  // corners landed on more than one chart
  size_t corrected_triangles = 0;    // ... and the §8 correction moved corners
  double seconds = 0;
  double hit_fraction() const { return lines ? double(hits) / double(lines) : 0.0; }
  nlohmann::json diagnostics() const;
};

TransferResult transfer_uvs(const Soup& soup, const field::FieldLines& lines,
                            const proxy::ProxyMesh& proxy, const atlas::Atlas& atlas,
                            const TransferOptions& options = {},
                            Progress& progress = Progress::none());

// Same, when lines are shared: line_of_corner[c] is the line of soup corner c
// (UINT32_MAX: none, the closest-point fallback); each line lands once.
TransferResult transfer_uvs(const Soup& soup, const field::FieldLines& lines,
                            const std::vector<uint32_t>& line_of_corner,
                            const proxy::ProxyMesh& proxy, const atlas::Atlas& atlas,
                            const TransferOptions& options = {},
                            Progress& progress = Progress::none());

// UV of a proxy surface point: barycentric mix of its face's atlas corner UVs.
Vec2 atlas_uv(const atlas::Atlas& atlas, const geometry::SurfacePoint& p);

}  // namespace soupuv::transfer
