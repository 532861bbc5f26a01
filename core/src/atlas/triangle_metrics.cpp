#include "atlas/triangle_metrics.h"

#include <cmath>

namespace soupuv::atlas {

std::array<Vec2, 3> flatten_triangle(const std::array<Vec3, 3>& q) {
  Vec3 e1 = q[1] - q[0], e2 = q[2] - q[0];
  double l1 = norm(e1);
  if (l1 <= 0) return {Vec2{0, 0}, Vec2{0, 0}, Vec2{norm(e2), 0}};
  return {Vec2{0, 0}, Vec2{l1, 0}, Vec2{dot(e2, e1) / l1, norm(cross(e1, e2)) / l1}};
}

TriangleStretch triangle_stretch(const std::array<Vec3, 3>& q, const std::array<Vec2, 3>& p) {
  TriangleStretch r;
  r.area3d = 0.5 * norm(cross(q[1] - q[0], q[2] - q[0]));
  r.area_uv = 0.5 * cross(p[1] - p[0], p[2] - p[0]);
  if (r.area_uv <= 0) return r;
  const double s1 = p[0].x, s2 = p[1].x, s3 = p[2].x;
  const double t1 = p[0].y, t2 = p[1].y, t3 = p[2].y;
  const double two_a = 2 * r.area_uv;
  Vec3 ss = (q[0] * (t2 - t3) + q[1] * (t3 - t1) + q[2] * (t1 - t2)) / two_a;
  Vec3 st = (q[0] * (s3 - s2) + q[1] * (s1 - s3) + q[2] * (s2 - s1)) / two_a;
  double a = dot(ss, ss), b = dot(ss, st), c = dot(st, st);
  r.l2_squared = 0.5 * (a + c);
  r.gamma_max = std::sqrt(0.5 * (a + c + std::sqrt((a - c) * (a - c) + 4 * b * b)));
  return r;
}

}  // namespace soupuv::atlas
