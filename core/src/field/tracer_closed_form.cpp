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

namespace {
// Edge i's log term f (the case split of triangle_integrals) and its
// in-plane distance t0 to x, from r[k] = v[k] - x, R[k] = |r[k]|.
double edge_log(const TriangleFrame& t, const Vec3 r[3], const double R[3], double h, int i, double& t0) {
  const int j = (i + 1) % 3;
  const double sm = dot(r[i], t.l[i]), sp = dot(r[j], t.l[i]);
  t0 = dot(r[i], t.m[i]);
  const double R0sq = t0 * t0 + h * h;
  const double R0sq_floor = 1e-28 * t.len[i] * t.len[i];
  if (sm >= 0) return std::log((R[j] + sp) / (R[i] + sm));
  if (sp <= 0) return std::log((R[i] - sm) / (R[j] - sp));
  return std::log((R[j] + sp) * (R[i] - sm) / std::max(R0sq, R0sq_floor));
}

// |solid angle| of the triangle seen from x, by one atan2.
double solid_angle(const Vec3 r[3], const double R[3]) {
  const double det = std::fabs(dot(r[0], cross(r[1], r[2])));
  const double den = R[0] * R[1] * R[2] + dot(r[0], r[1]) * R[2] + dot(r[0], r[2]) * R[1] + dot(r[1], r[2]) * R[0];
  return 2 * std::atan2(det, den);
}
}  // namespace

Vec3 closed_form_field(const TriangleFrame& t, Vec3 x) {
  if (t.degenerate) return {0, 0, 0};
  const Vec3 r[3] = {t.v[0] - x, t.v[1] - x, t.v[2] - x};
  const double R[3] = {norm(r[0]), norm(r[1]), norm(r[2])};
  const double h = -dot(r[0], t.n);
  Vec3 sum_mf{0, 0, 0};
  double t0 = 0;
  for (int i = 0; i < 3; ++i) sum_mf += edge_log(t, r, R, h, i, t0) * t.m[i];
  if (h == 0) return sum_mf;
  // Its sign is the side of the plane.
  const double omega = solid_angle(r, R);
  return (h > 0 ? omega : -omega) * t.n + sum_mf;
}

double closed_form_potential(const TriangleFrame& t, Vec3 x) {
  if (t.degenerate) return 0;
  const Vec3 r[3] = {t.v[0] - x, t.v[1] - x, t.v[2] - x};
  const double R[3] = {norm(r[0]), norm(r[1]), norm(r[2])};
  const double h = -dot(r[0], t.n);
  double sum_tf = 0, t0 = 0;
  for (int i = 0; i < 3; ++i) {
    const double f = edge_log(t, r, R, h, i, t0);
    sum_tf += t0 * f;
  }
  if (h == 0) return sum_tf;
  return sum_tf - std::fabs(h) * solid_angle(r, R);
}

}  // namespace soupuv::field::tracer
