// Closest point of a triangle to a point, and the distance between them: the
// one implementation every stage uses (proxy distance field, field tracer's
// near-surface tests, transfer's closest-point fallback).
//
//   closest_point_on_triangle(p, a, b, c) -> {point, bary}
//     p        the query point
//     a, b, c  the triangle's corners (any shape, degenerate ones too)
//     point    the point of the closed triangle closest to p
//     bary     its barycentric coordinates (point = bary[0] a + bary[1] b + bary[2] c)
//   point_triangle_distance2(p, a, b, c) -> |p - point|^2
//   point_triangle_distance(p, a, b, c)  -> |p - point|
//
// Method: Ericson, Real-Time Collision Detection §5.1.5 (written from the
// description): the Voronoi regions of the vertices, edges and face are tested
// in turn with six dot products. In an edge region the point is the edge's
// own projection (dot / squared length, clamped), not Ericson's ratio of the
// region products: the same value up to rounding, and the proxy's distance
// field was tuned and tested with it. A triangle with no interior region
// (zero area) falls back to the closest point of its three edges. Inline: the
// proxy's narrow band calls it in its innermost loop.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

#include "soupuv/vec.h"

namespace soupuv::geometry {

struct ClosestPoint {
  Vec3 point;
  std::array<double, 3> bary{};
};

// Closest point of the segment ab to p, as the parameter t along it.
inline double closest_on_segment(Vec3 p, Vec3 a, Vec3 b) {
  const Vec3 ab = b - a;
  const double len2 = dot(ab, ab);
  return len2 > 0 ? std::clamp(dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
}

inline ClosestPoint closest_point_on_triangle(Vec3 p, Vec3 a, Vec3 b, Vec3 c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return {a, {1, 0, 0}};
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return {b, {0, 1, 0}};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = closest_on_segment(p, a, b);
    return {a + v * ab, {1 - v, v, 0}};
  }
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return {c, {0, 0, 1}};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = closest_on_segment(p, a, c);
    return {a + w * ac, {1 - w, 0, w}};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = closest_on_segment(p, b, c);
    return {b + w * (c - b), {0, 1 - w, w}};
  }
  const double denom = va + vb + vc;
  if (!(denom > 0)) {
    // No interior region (zero area): the closest point of the three edges.
    const double tab = closest_on_segment(p, a, b), tbc = closest_on_segment(p, b, c),
                 tac = closest_on_segment(p, a, c);
    const ClosestPoint on[3] = {{a + tab * (b - a), {1 - tab, tab, 0}},
                                {b + tbc * (c - b), {0, 1 - tbc, tbc}},
                                {a + tac * (c - a), {1 - tac, 0, tac}}};
    int best = 0;
    for (int i = 1; i < 3; ++i)
      if (norm2(p - on[i].point) < norm2(p - on[best].point)) best = i;
    return on[best];
  }
  const double v = vb / denom, w = vc / denom;
  return {a + v * ab + w * ac, {1 - v - w, v, w}};
}

inline double point_triangle_distance2(Vec3 p, Vec3 a, Vec3 b, Vec3 c) {
  return norm2(p - closest_point_on_triangle(p, a, b, c).point);
}

inline double point_triangle_distance(Vec3 p, Vec3 a, Vec3 b, Vec3 c) {
  return std::sqrt(point_triangle_distance2(p, a, b, c));
}

}  // namespace soupuv::geometry
