// A segment against a triangle, in the two forms the stages need.
//
//   segment_crosses_triangle(p, q, a, b, c) -> bool
//     Does the closed segment pq meet the closed triangle abc? Signed
//     volumes only (no division): a segment lying in the triangle's plane
//     does not count. The field tracer asks it of every step near the soup
//     (a step through the conductor is redone), so its answer must follow
//     the signs alone, with no tolerance to tune.
//   segment_triangle_hit(a, b, p0, p1, p2, t, bary) -> bool
//     Where the segment a -> b crosses the triangle p0 p1 p2, two-sided
//     (Moller-Trumbore): true with the segment parameter t in [0, 1] and the
//     hit's barycentrics. A segment parallel to the plane (|det| below 1e-14
//     of the lengths' product) misses. The transfer lands field lines with it.
#pragma once

#include <array>

#include "soupuv/vec.h"

namespace soupuv::geometry {

bool segment_crosses_triangle(Vec3 p, Vec3 q, Vec3 a, Vec3 b, Vec3 c);

bool segment_triangle_hit(Vec3 a, Vec3 b, Vec3 p0, Vec3 p1, Vec3 p2, double& t,
                          std::array<double, 3>& bary);

}  // namespace soupuv::geometry
