// The plane of a triangle, as a unit normal and an offset.
//
//   plane_of(t) -> {n, d}: n the unit normal (right-handed over t's corners),
//                  at(x) = n . x - d the signed distance of x to the plane.
//                  A zero-area triangle gives a zero normal (at(x) = 0).
#pragma once

#include <array>

#include "soupuv/vec.h"

namespace soupuv::geometry {

struct Plane {
  Vec3 n;      // unit normal
  double d;    // n . x - d = signed distance
  double at(Vec3 x) const { return dot(n, x) - d; }
};

inline Plane plane_of(const std::array<Vec3, 3>& t) {
  const Vec3 n = normalized(cross(t[1] - t[0], t[2] - t[0]));
  return {n, dot(n, t[0])};
}

}  // namespace soupuv::geometry
