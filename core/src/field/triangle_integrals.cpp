// Closed-form single-layer integrals over a flat triangle, written edge by
// edge: with h the signed height of x over the plane and, per edge, s± the
// positions of its end points along the edge and t0 the in-plane distance of
// the foot of x to the edge line,
//   ∫ 1/R       = Σ t0·f − |h|·Σ β
//   ∫ (x−y)/R³  = sign(h)·n·Σ β + Σ m·f
// where f = ln((R⁺ + s⁺)/(R⁻ + s⁻)), β the edge's share of the solid angle,
// m the outward in-plane edge normal. The log argument is rewritten per case
// so it never loses digits through cancellation.
#include "soupuv/field/triangle_integrals.h"

#include <algorithm>
#include <cmath>

namespace soupuv::field {

TriangleIntegrals triangle_integrals(Vec3 a, Vec3 b, Vec3 c, Vec3 x) {
  TriangleIntegrals out;
  Vec3 nn = cross(b - a, c - a);
  double twice_area = norm(nn);
  double scale = std::max({norm(b - a), norm(c - b), norm(a - c)});
  if (!(twice_area > 1e-14 * scale * scale)) return out;
  Vec3 n = nn / twice_area;
  double h = dot(x - a, n);
  double ah = std::fabs(h);
  double sign_h = h > 0 ? 1.0 : (h < 0 ? -1.0 : 0.0);
  const Vec3 v[3] = {a, b, c};
  double sum_tf = 0, sum_beta = 0;
  Vec3 sum_mf{0, 0, 0};
  for (int i = 0; i < 3; ++i) {
    Vec3 pm = v[i], pp = v[(i + 1) % 3];
    Vec3 e = pp - pm;
    double len = norm(e);
    Vec3 l = e / len;
    Vec3 m = cross(l, n);  // outward, in plane
    Vec3 dm = pm - x, dp = pp - x;
    double sm = dot(dm, l), sp = dot(dp, l);
    double t0 = dot(dm, m);
    double Rm = norm(dm), Rp = norm(dp);
    double R0sq = t0 * t0 + h * h;
    // Where the edge line passes within a rounding error of x, the log term
    // only matters through t0·f (→ 0) or as the physical edge singularity;
    // keep it finite.
    double R0sq_floor = 1e-28 * len * len;
    double f;
    if (sm >= 0) {
      f = std::log((Rp + sp) / (Rm + sm));
    } else if (sp <= 0) {
      f = std::log((Rm - sm) / (Rp - sp));
    } else {
      f = std::log((Rp + sp) * (Rm - sm) / std::max(R0sq, R0sq_floor));
    }
    // beta = atan2(y1, x1) - atan2(y2, x2) as one atan2 (half the calls; the
    // x's are >= 0, so both angles lie in [-pi/2, pi/2] and the difference
    // needs no wrap).
    const double y1 = t0 * sp, x1 = R0sq + ah * Rp, y2 = t0 * sm, x2 = R0sq + ah * Rm;
    double beta = std::atan2(y1 * x2 - x1 * y2, x1 * x2 + y1 * y2);
    sum_tf += t0 * f;
    sum_beta += beta;
    sum_mf += m * f;
  }
  out.potential = sum_tf - ah * sum_beta;
  out.field = sign_h * sum_beta * n + sum_mf;
  return out;
}

}  // namespace soupuv::field
