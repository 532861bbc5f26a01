// Closed-form triangle field for the tracer (see tracer_closed_form.h). The
// log terms and their case split are those of triangle_integrals.cpp (the
// argument is rewritten per case so it never loses digits by cancellation).
#include "tracer_closed_form.h"

#include <algorithm>
#include <cmath>

namespace soupuv::field::tracer {

TriangleFrame triangle_frame(Vec3 a, Vec3 b, Vec3 c) {
  TriangleFrame t;
  t.v[0] = a;
  t.v[1] = b;
  t.v[2] = c;
  const Vec3 nn = cross(b - a, c - a);
  const double twice_area = norm(nn);
  const double scale = std::max({norm(b - a), norm(c - b), norm(a - c)});
  // The same degeneracy test as triangle_integrals.
  t.degenerate = !(twice_area > 1e-14 * scale * scale);
  if (t.degenerate) return t;
  t.n = nn / twice_area;
  for (int i = 0; i < 3; ++i) {
    const Vec3 e = t.v[(i + 1) % 3] - t.v[i];
    t.len[i] = norm(e);
    t.l[i] = e / t.len[i];
    t.m[i] = cross(t.l[i], t.n);
  }
  return t;
}

Vec3 closed_form_field(const TriangleFrame& t, Vec3 x) {
  if (t.degenerate) return {0, 0, 0};
  const Vec3 r[3] = {t.v[0] - x, t.v[1] - x, t.v[2] - x};
  const double R[3] = {norm(r[0]), norm(r[1]), norm(r[2])};
  const double h = -dot(r[0], t.n);
  Vec3 sum_mf{0, 0, 0};
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    const double sm = dot(r[i], t.l[i]), sp = dot(r[j], t.l[i]);
    const double t0 = dot(r[i], t.m[i]);
    const double R0sq = t0 * t0 + h * h;
    const double R0sq_floor = 1e-28 * t.len[i] * t.len[i];
    double f;
    if (sm >= 0) f = std::log((R[j] + sp) / (R[i] + sm));
    else if (sp <= 0) f = std::log((R[i] - sm) / (R[j] - sp));
    else f = std::log((R[j] + sp) * (R[i] - sm) / std::max(R0sq, R0sq_floor));
    sum_mf += f * t.m[i];
  }
  if (h == 0) return sum_mf;
  // |solid angle| from one atan2; its sign is the side of the plane.
  const double det = std::fabs(dot(r[0], cross(r[1], r[2])));
  const double den = R[0] * R[1] * R[2] + dot(r[0], r[1]) * R[2] + dot(r[0], r[2]) * R[1] + dot(r[1], r[2]) * R[0];
  const double omega = 2 * std::atan2(det, den);
  return (h > 0 ? omega : -omega) * t.n + sum_mf;
}

}  // namespace soupuv::field::tracer
