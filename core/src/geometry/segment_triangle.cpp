// Segment against triangle (see soupuv/geometry/segment_triangle.h).
#include "soupuv/geometry/segment_triangle.h"

#include <cmath>

namespace soupuv::geometry {

bool segment_crosses_triangle(Vec3 p, Vec3 q, Vec3 a, Vec3 b, Vec3 c) {
  auto vol = [](Vec3 u, Vec3 v, Vec3 w, Vec3 z) { return dot(cross(v - u, w - u), z - u); };
  double sp = vol(a, b, c, p), sq = vol(a, b, c, q);
  if ((sp > 0 && sq > 0) || (sp < 0 && sq < 0) || (sp == 0 && sq == 0)) return false;
  // The segment's line must pass through the triangle: the three edge volumes
  // seen from the segment agree in sign.
  double s1 = vol(p, q, a, b), s2 = vol(p, q, b, c), s3 = vol(p, q, c, a);
  bool neg = s1 < 0 || s2 < 0 || s3 < 0;
  bool pos = s1 > 0 || s2 > 0 || s3 > 0;
  return !(neg && pos);
}

bool segment_triangle_hit(Vec3 a, Vec3 b, Vec3 p0, Vec3 p1, Vec3 p2, double& t,
                          std::array<double, 3>& bary) {
  Vec3 d = b - a;
  Vec3 e1 = p1 - p0, e2 = p2 - p0;
  Vec3 h = cross(d, e2);
  double det = dot(e1, h);
  // Relative threshold: parallel segments cannot cross the plane properly.
  if (std::abs(det) <= 1e-14 * norm(d) * norm(e1) * norm(e2)) return false;
  double inv = 1.0 / det;
  Vec3 s = a - p0;
  double u = inv * dot(s, h);
  if (u < 0 || u > 1) return false;
  Vec3 q = cross(s, e1);
  double v = inv * dot(d, q);
  if (v < 0 || u + v > 1) return false;
  double tt = inv * dot(e2, q);
  if (tt < 0 || tt > 1) return false;
  t = tt;
  bary = {1 - u - v, u, v};
  return true;
}

}  // namespace soupuv::geometry
