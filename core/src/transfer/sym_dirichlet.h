// The symmetric Dirichlet energy of one triangle's map into UV, and its
// gradient with respect to one corner's UV (SLIM and the UV solve's steps use it).
//
// Input : the 3D triangle, the texel scale s (UV units per 3D length) and the
//         wanted UV orientation (+1 or -1).
// Output: E = A (|J|^2 + |J^-1|^2), where J maps the triangle, flattened and
//         scaled by s, onto its UV triangle, and A is its rest area. E is 4A
//         for an isometry at scale s, grows without bound as the UV triangle
//         collapses, and is +inf once it is flipped: the barrier that keeps a
//         line search injective.
#pragma once

#include <array>
#include <cmath>
#include <limits>

#include "soupuv/vec.h"

namespace soupuv::transfer::detail {

struct RestTriangle {
  // J = sum_k uv_k g_k^T (g_k: gradient of corner k's barycentric function).
  std::array<Vec2, 3> g{};
  std::array<Vec2, 3> x{};  // flattened corners at scale, wanted orientation
  double area = 0;   // rest area, in UV units^2
  bool valid = false;
};

inline RestTriangle rest_triangle(Vec3 p0, Vec3 p1, Vec3 p2, double scale, double orientation) {
  RestTriangle r;
  const Vec3 e1 = p1 - p0, e2 = p2 - p0;
  const double l1 = norm(e1), twice_area = norm(cross(e1, e2));
  if (!(l1 > 0) || !(twice_area > 1e-14 * l1 * l1)) return r;
  // Flattened corners: x0 = 0, x1 = (l1, 0), x2 with the wanted orientation.
  const double a = scale * l1, b = scale * dot(e1, e2) / l1,
               c = orientation * scale * twice_area / l1;
  r.x = {Vec2{0, 0}, Vec2{a, 0}, Vec2{b, c}};
  const double det = a * c;  // det [x1 x2]
  // Rows of [x1 x2]^-1 are the gradients of the barycentrics of corners 1, 2.
  r.g[1] = {c / det, -b / det};
  r.g[2] = {0, a / det};
  r.g[0] = {-(r.g[1].x + r.g[2].x), -(r.g[1].y + r.g[2].y)};
  r.area = 0.5 * std::abs(det);
  r.valid = true;
  return r;
}

struct Jacobian {
  double j00, j01, j10, j11;
  double det() const { return j00 * j11 - j01 * j10; }
  double frobenius2() const { return j00 * j00 + j01 * j01 + j10 * j10 + j11 * j11; }
};

inline Jacobian jacobian(const RestTriangle& r, const std::array<Vec2, 3>& uv) {
  Jacobian J{0, 0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    J.j00 += uv[k].x * r.g[k].x;
    J.j01 += uv[k].x * r.g[k].y;
    J.j10 += uv[k].y * r.g[k].x;
    J.j11 += uv[k].y * r.g[k].y;
  }
  return J;
}

inline double energy(const RestTriangle& r, const std::array<Vec2, 3>& uv) {
  const Jacobian J = jacobian(r, uv);
  const double d = J.det();
  if (!(d > 0)) return std::numeric_limits<double>::infinity();
  const double f = J.frobenius2();
  return r.area * (f + f / (d * d));
}

// dE/d uv_k, and a positive curvature estimate along it (the Hessian's
// dominant diagonal term) to scale a descent step.
inline void gradient(const RestTriangle& r, const std::array<Vec2, 3>& uv, int k, Vec2& grad,
                     double& curvature) {
  const Jacobian J = jacobian(r, uv);
  const double d = J.det(), f = J.frobenius2();
  const Vec2 g = r.g[k];
  const Vec2 Jg{J.j00 * g.x + J.j01 * g.y, J.j10 * g.x + J.j11 * g.y};
  // Cofactor matrix of J (d det / dJ) times g.
  const Vec2 Cg{J.j11 * g.x - J.j10 * g.y, -J.j01 * g.x + J.j00 * g.y};
  const double w = 1 + 1 / (d * d);
  grad = {r.area * (2 * w * Jg.x - 2 * f / (d * d * d) * Cg.x),
          r.area * (2 * w * Jg.y - 2 * f / (d * d * d) * Cg.y)};
  curvature = r.area * 2 * w * dot(g, g) * (1 + 3 * f / (d * d));
}

}  // namespace soupuv::transfer::detail
