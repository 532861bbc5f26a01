// Which triangles carry the area-weighted L2 stretch figure, and why.
//
// The L2 figure is sqrt(sum A_t s_t^2 / sum A_t): one triangle whose UV
// collapsed while its 3D area is ordinary can carry most of the sum. This
// lists the triangles that carry the top `share` of the squared sum and puts
// each down to one class (first match wins):
//   sliver_3d     the 3D triangle itself is a needle or cap (shortest
//                 altitude < sliver_aspect x longest edge): its UV shape is
//                 decided by landing noise, not by the map;
//   missed        a corner's field line missed the proxy (fallback placed it);
//   split         corners first landed on different charts (§8 chose one);
//   corrected     one chart at first, but §8 moved a corner to another;
//   chart_border  one chart throughout, and a corner's welded vertex also
//                 lies on another chart (the triangle touches a seam or an
//                 open border of its chart);
//   converged     one chart, inside it: the field lines themselves converged.
// plus a flag per listed triangle: it is flipped.
//
// Input : the soup, final corner UVs (the scale is uv_metrics' own for
//         stretch_l2: sqrt(total UV area / total 3D area)), per corner what the transfer saw (CornerLanding), and per triangle
//         flags: on a chart border.
// Output: counts and squared-sum shares per class, and the worst triangles
//         with their figures (for the diagnostics and the bench).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "soupuv/quality/discontinuity.h"
#include "soupuv/quality/uv_metrics.h"
#include "soupuv/soup.h"

namespace soupuv::quality {

struct StretchTailOptions {
  double share = 0.5;          // list triangles until they carry this share of the sum
  size_t max_listed = 200;     // ... or this many
  size_t max_detailed = 10;    // the first ones with their figures in the JSON
  double sliver_aspect = 0.02; // shortest altitude / longest edge of a 3D sliver
};

struct TailTriangle {
  uint32_t triangle = 0;
  std::string cls;
  double share = 0;        // of the squared L2 sum
  double stretch = 0;      // per-triangle L2 stretch at the metric's scale
  double area_ratio = 0;   // UV area / (3D area x scale^2), signed by the dominant orientation
  double aspect_3d = 0;    // shortest altitude / longest edge
  bool flipped = false;
};

struct StretchTail {
  size_t listed = 0;
  double listed_share = 0;
  std::vector<std::string> classes;           // class names, in order
  std::vector<size_t> class_count;            // per class
  std::vector<double> class_share;            // per class, share of the squared sum
  std::vector<TailTriangle> worst;            // first max_detailed
  nlohmann::json to_json() const;
};

struct TailFlags {
  std::vector<uint8_t> chart_border;  // per triangle (may be empty)
};

StretchTail stretch_tail(const Soup& soup, const CornerUvs& uvs, const CornerLanding& landing,
                         const TailFlags& flags,
                         const StretchTailOptions& options = {});

// Shortest altitude / longest edge of a 3D triangle (0 for a degenerate one).
double triangle_aspect(Vec3 a, Vec3 b, Vec3 c);

}  // namespace soupuv::quality
