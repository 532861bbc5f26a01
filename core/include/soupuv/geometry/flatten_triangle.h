// A 3D triangle laid flat in its own plane, isometrically.
//
//   flatten_triangle(q) -> its corners in 2D: q[0] at the origin, q[1] on the
//                          +x axis, q[2] above it (counter-clockwise); a
//                          triangle whose first edge has no length gets
//                          q[2] on the x axis at |q[2] - q[0]|.
#pragma once

#include <array>

#include "soupuv/vec.h"

namespace soupuv::geometry {

inline std::array<Vec2, 3> flatten_triangle(const std::array<Vec3, 3>& q) {
  const Vec3 e1 = q[1] - q[0], e2 = q[2] - q[0];
  const double l1 = norm(e1);
  if (l1 <= 0) return {Vec2{0, 0}, Vec2{0, 0}, Vec2{norm(e2), 0}};
  return {Vec2{0, 0}, Vec2{l1, 0}, Vec2{dot(e2, e1) / l1, norm(cross(e1, e2)) / l1}};
}

}  // namespace soupuv::geometry
