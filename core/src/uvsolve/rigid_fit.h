// The rotation and shift that best carry one set of UV points onto another
// (2D Procrustes without scale or mirror; private to the UV solve: the seam
// merge and the attachment move an island rigidly onto its neighbour).
//
// Input : pairs (p, q): a point of the island that moves and the point of
//         the fixed island it should land on.
// Output: the motion x -> R (x - from) + to minimising sum |R (p - from) +
//         to - q|^2, R a rotation: from and to are the two centroids, R's
//         angle atan2(sum cross, sum dot) of the centred pairs (0 when they
//         are all at their centroids).
#pragma once

#include <cmath>
#include <utility>
#include <vector>

#include "soupuv/vec.h"

namespace soupuv::uvsolve::detail {

struct RigidMotion {
  Vec2 from{0, 0}, to{0, 0};
  double cos = 1, sin = 0;
  Vec2 operator()(Vec2 x) const {
    const Vec2 a = x - from;
    return Vec2{cos * a.x - sin * a.y, sin * a.x + cos * a.y} + to;
  }
};

inline RigidMotion fit_rigid_motion(const std::vector<std::pair<Vec2, Vec2>>& moving_to_fixed) {
  RigidMotion m;
  if (moving_to_fixed.empty()) return m;
  for (const auto& [p, q] : moving_to_fixed) m.from = m.from + p, m.to = m.to + q;
  const double inv = 1.0 / double(moving_to_fixed.size());
  m.from = inv * m.from;
  m.to = inv * m.to;
  double sd = 0, sc = 0;
  for (const auto& [p, q] : moving_to_fixed) {
    const Vec2 a = p - m.from, b = q - m.to;
    sd += dot(a, b);
    sc += cross(a, b);
  }
  const double angle = std::atan2(sc, sd);
  m.cos = std::cos(angle);
  m.sin = std::sin(angle);
  return m;
}

}  // namespace soupuv::uvsolve::detail
