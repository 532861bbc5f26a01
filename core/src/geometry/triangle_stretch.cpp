// Sander stretch from the UV -> 3D Jacobian (see soupuv/geometry/triangle_stretch.h).
#include "soupuv/geometry/triangle_stretch.h"

#include <algorithm>
#include <cmath>

namespace soupuv::geometry {

bool uv_jacobian(Vec3 p0, Vec3 p1, Vec3 p2, const std::array<Vec2, 3>& uv, UvJacobian& j) {
  const double area2 = cross(uv[1] - uv[0], uv[2] - uv[0]);  // 2 x the signed UV area
  if (!(std::abs(area2) > 0)) return false;
  const double s1 = uv[0].x, s2 = uv[1].x, s3 = uv[2].x;
  const double t1 = uv[0].y, t2 = uv[1].y, t3 = uv[2].y;
  j.ds = (p0 * (t2 - t3) + p1 * (t3 - t1) + p2 * (t1 - t2)) / area2;
  j.dt = (p0 * (s3 - s2) + p1 * (s1 - s3) + p2 * (s2 - s1)) / area2;
  return true;
}

bool sander_stretch(Vec3 p0, Vec3 p1, Vec3 p2, const std::array<Vec2, 3>& uv, SanderStretch& s) {
  UvJacobian j;
  if (!uv_jacobian(p0, p1, p2, uv, j)) return false;
  // The eigenvalues of J^T J = [a b; b c] are the squared singular values.
  const double a = dot(j.ds, j.ds), b = dot(j.ds, j.dt), c = dot(j.dt, j.dt);
  const double root = std::sqrt(std::max(0.0, (a - c) * (a - c) + 4 * b * b));
  s.big = std::sqrt(std::max(0.0, 0.5 * (a + c + root)));
  s.small = std::sqrt(std::max(0.0, 0.5 * (a + c - root)));
  s.l2_squared = 0.5 * (a + c);
  return std::isfinite(s.big) && std::isfinite(s.small);
}

TriangleStretch triangle_stretch(const std::array<Vec3, 3>& q, const std::array<Vec2, 3>& p) {
  TriangleStretch r;
  r.area3d = 0.5 * norm(cross(q[1] - q[0], q[2] - q[0]));
  r.area_uv = 0.5 * cross(p[1] - p[0], p[2] - p[0]);
  if (r.area_uv <= 0) return r;
  SanderStretch s;
  sander_stretch(q[0], q[1], q[2], p, s);
  r.l2_squared = s.l2_squared;
  r.gamma_max = s.big;
  return r;
}

}  // namespace soupuv::geometry
