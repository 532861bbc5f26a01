#include "transfer/uv_overlap.h"

#include <algorithm>
#include <cmath>

namespace soupuv::transfer::detail {

OverlapGrid::OverlapGrid(int size) : size_(size), count_(size_t(size) * size_t(size), 0) {}

template <class F>
void OverlapGrid::for_each_texel(const std::array<Vec2, 3>& uv, F&& f) const {
  const double area2 = cross(uv[1] - uv[0], uv[2] - uv[0]);
  if (!(std::abs(area2) > 0)) return;
  double lo_x = std::min({uv[0].x, uv[1].x, uv[2].x}), hi_x = std::max({uv[0].x, uv[1].x, uv[2].x});
  double lo_y = std::min({uv[0].y, uv[1].y, uv[2].y}), hi_y = std::max({uv[0].y, uv[1].y, uv[2].y});
  if (!std::isfinite(lo_x + hi_x + lo_y + hi_y)) return;
  // Texel i's centre is at (i + 0.5) / size.
  const int x0 = std::max(0, int(std::ceil(lo_x * size_ - 0.5))),
            x1 = std::min(size_ - 1, int(std::floor(hi_x * size_ - 0.5)));
  const int y0 = std::max(0, int(std::ceil(lo_y * size_ - 0.5))),
            y1 = std::min(size_ - 1, int(std::floor(hi_y * size_ - 0.5)));
  const double sign = area2 > 0 ? 1 : -1;
  for (int y = y0; y <= y1; ++y) {
    const double py = (y + 0.5) / size_;
    for (int x = x0; x <= x1; ++x) {
      const Vec2 p{(x + 0.5) / size_, py};
      if (sign * cross(uv[1] - uv[0], p - uv[0]) > 0 && sign * cross(uv[2] - uv[1], p - uv[1]) > 0 &&
          sign * cross(uv[0] - uv[2], p - uv[2]) > 0)
        f(uint32_t(y) * uint32_t(size_) + uint32_t(x));
    }
  }
}

void OverlapGrid::add(const std::array<Vec2, 3>& uv, int delta) {
  for_each_texel(uv, [&](uint32_t i) {
    uint16_t& c = count_[i];
    if (delta > 0) {
      if (c >= 1) ++excess_;
      if (c < UINT16_MAX) ++c;
    } else if (c > 0) {
      --c;
      if (c >= 1) --excess_;
    }
  });
}

}  // namespace soupuv::transfer::detail
