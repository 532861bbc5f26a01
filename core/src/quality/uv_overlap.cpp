#include "soupuv/quality/uv_overlap.h"

#include <algorithm>
#include <cmath>

namespace soupuv::quality {

UvOverlap uv_overlap(const std::vector<std::array<Vec2, 3>>& uvs, const std::vector<uint8_t>& include,
                     int raster) {
  UvOverlap r;
  const int R = raster;
  std::vector<uint32_t> count(size_t(R) * R, 0);
  for (size_t t = 0; t < uvs.size(); ++t) {
    if (!include[t]) continue;
    std::array<Vec2, 3> p;
    for (int k = 0; k < 3; ++k) p[k] = double(R) * uvs[t][k];
    const double a = 0.5 * cross(p[1] - p[0], p[2] - p[0]);
    r.utilisation += std::abs(a) / (double(R) * R);
    if (a < 0) std::swap(p[1], p[2]);
    const double xmin = std::min({p[0].x, p[1].x, p[2].x}), xmax = std::max({p[0].x, p[1].x, p[2].x});
    const double ymin = std::min({p[0].y, p[1].y, p[2].y}), ymax = std::max({p[0].y, p[1].y, p[2].y});
    const int x0 = std::clamp(int(std::ceil(xmin - 0.5)), 0, R - 1), x1 = std::clamp(int(std::floor(xmax - 0.5)), -1, R - 1);
    const int y0 = std::clamp(int(std::ceil(ymin - 0.5)), 0, R - 1), y1 = std::clamp(int(std::floor(ymax - 0.5)), -1, R - 1);
    for (int iy = y0; iy <= y1; ++iy)
      for (int ix = x0; ix <= x1; ++ix) {
        const double cx = ix + 0.5, cy = iy + 0.5;
        bool inside = true;
        for (int e = 0; e < 3 && inside; ++e) {
          const Vec2 u = p[e], v = p[(e + 1) % 3];
          const double dx = v.x - u.x, dy = v.y - u.y;
          const double w = dx * (cy - u.y) - dy * (cx - u.x);
          const bool top_left = dy < 0 || (dy == 0 && dx > 0);
          inside = w > 0 || (w == 0 && top_left);
        }
        if (inside) ++count[size_t(iy) * R + ix];
      }
  }
  double total = 0, over = 0;
  for (uint32_t c : count) {
    total += c;
    if (c >= 2) over += c;
  }
  r.overlap = total > 0 ? over / total : 0;
  return r;
}

}  // namespace soupuv::quality
