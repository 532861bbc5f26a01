// How much of the texture a map uses, and how much of it twice: the
// definitions of eval/uvmetrics.py, so the diagnostics and the yardstick
// agree (a test holds them together).
//
// Input : one UV per triangle corner; which triangles count (include[t] != 0;
//         uvmetrics.py counts the non-degenerate triangles with UVs inside
//         [0,1]^2); the raster size (uvmetrics.py: 512).
// Output: utilisation = sum of |UV area| of the counted triangles (overlaps
//         not removed); overlap = share of rasterised triangle area (pixel
//         centres of a raster x raster grid, half-open edges by the top-left
//         rule, every triangle turned counter-clockwise) on pixels covered by
//         two triangles or more.
// Cost  : O(raster^2) memory, O(pixels in the triangles' boxes) time.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "soupuv/vec.h"

namespace soupuv::quality {

struct UvOverlap {
  double utilisation = 0;
  double overlap = 0;
};

// Whether the point (cx, cy) belongs to the counter-clockwise triangle q by
// the raster's rule (for_each_pixel_centre below).
inline bool pixel_centre_inside(const std::array<Vec2, 3>& q, double cx, double cy) {
  for (int e = 0; e < 3; ++e) {
    const Vec2 a = q[e], b = q[(e + 1) % 3];
    // The edge function from the edge's lower endpoint, negated for the
    // other direction: the two triangles sharing an edge compute the
    // same value with opposite signs, so a centre exactly on the edge
    // goes to exactly one of them (rounding in either order could give
    // it to both).
    const bool forward = a.x < b.x || (a.x == b.x && a.y < b.y);
    const Vec2 s = forward ? a : b, t = forward ? b : a;
    const double w0 = (t.x - s.x) * (cy - s.y) - (t.y - s.y) * (cx - s.x);
    const double w = forward ? w0 : -w0;
    const double dx = b.x - a.x, dy = b.y - a.y;
    const bool top_left = dy < 0 || (dy == 0 && dx > 0);
    if (!(w > 0 || (w == 0 && top_left))) return false;
  }
  return true;
}

// Calls f(ix, iy) for every sample point (ix + 1/2, iy + 1/2) of a width x
// height grid strictly inside the counter-clockwise triangle q (grid
// units), an edge's own points belonging to the triangle on its top or left
// side only, so two triangles side by side never share a sample: the rule
// of eval/uvmetrics.py's raster, shared with the UV solve's overlap split.
template <class F>
void for_each_pixel_centre(const std::array<Vec2, 3>& q, int width, int height, F&& f) {
  const double x0 = std::min({q[0].x, q[1].x, q[2].x}), x1 = std::max({q[0].x, q[1].x, q[2].x});
  const double y0 = std::min({q[0].y, q[1].y, q[2].y}), y1 = std::max({q[0].y, q[1].y, q[2].y});
  const int i0 = std::max(0, int(std::ceil(x0 - 0.5))), i1 = std::min(width - 1, int(std::floor(x1 - 0.5)));
  const int j0 = std::max(0, int(std::ceil(y0 - 0.5))), j1 = std::min(height - 1, int(std::floor(y1 - 0.5)));
  for (int j = j0; j <= j1; ++j) {
    // The row's inside centres lie between the triangle's crossings of its
    // centre line: only those (and a pixel either side, for rounding) are
    // tested, the exact test below still decides. A sliver's box holds
    // several times its centres (the UV solve's overlap samples: 6x on
    // table, 3x on beast; docs/tuning.md, session 35).
    int lo = i0, hi = i1;
    {
      const double cy = j + 0.5;
      double xl = INFINITY, xr = -INFINITY;
      for (int e = 0; e < 3; ++e) {
        const Vec2 a = q[e], b = q[(e + 1) % 3];
        if (!((a.y <= cy && cy <= b.y) || (b.y <= cy && cy <= a.y))) continue;
        if (a.y == b.y) {
          xl = std::min({xl, a.x, b.x});
          xr = std::max({xr, a.x, b.x});
        } else {
          const double x = a.x + (cy - a.y) * (b.x - a.x) / (b.y - a.y);
          xl = std::min(xl, x);
          xr = std::max(xr, x);
        }
      }
      if (xl <= xr) {
        lo = std::max(i0, int(std::floor(xl - 0.5)) - 1);
        hi = std::min(i1, int(std::ceil(xr - 0.5)) + 1);
      }
    }
    for (int i = lo; i <= hi; ++i) {
      if (pixel_centre_inside(q, i + 0.5, j + 0.5)) f(i, j);
    }
  }
}

UvOverlap uv_overlap(const std::vector<std::array<Vec2, 3>>& uvs, const std::vector<uint8_t>& include,
                     int raster = 512);

}  // namespace soupuv::quality
