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
    for_each_pixel_centre(p, R, R, [&](int ix, int iy) { ++count[size_t(iy) * R + ix]; });
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
