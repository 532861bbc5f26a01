// A chart's UVs turned about the origin by an angle (no mirror, no scale),
// with the turned bounding box: the one rotation both packers try charts in
// (pack.cpp's poses, raster_pack.cpp's turns).
//
//   turn_chart(uv, angle) -> {uv turned counter-clockwise by angle (radians),
//                             lo, hi: their bounding box}
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "soupuv/vec.h"

namespace soupuv::atlas {

struct TurnedChart {
  std::vector<Vec2> uv;
  Vec2 lo, hi;
};

inline TurnedChart turn_chart(const std::vector<Vec2>& uv, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  TurnedChart t;
  t.uv.reserve(uv.size());
  t.lo = {INFINITY, INFINITY};
  t.hi = {-INFINITY, -INFINITY};
  for (Vec2 p : uv) {
    Vec2 q{c * p.x - s * p.y, s * p.x + c * p.y};
    t.lo = {std::min(t.lo.x, q.x), std::min(t.lo.y, q.y)};
    t.hi = {std::max(t.hi.x, q.x), std::max(t.hi.y, q.y)};
    t.uv.push_back(q);
  }
  return t;
}

}  // namespace soupuv::atlas
