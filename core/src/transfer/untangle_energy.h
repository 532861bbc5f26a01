// The untangling energy of Garanzha et al., "Foldover-free maps in 50 lines
// of code" (SIGGRAPH 2021), for one triangle, and its gradient with respect
// to one corner's UV (private to uv_repair.cpp).
//
// Input : the rest triangle (sym_dirichlet.h: flattened at the global scale,
//         so an isometry has J = I), corner UVs, and the regularisation eps.
// Output: E_eps = A ((1 - theta) |J|^2 + theta (det^2 + 1)) / chi(det, eps),
//         chi(d, eps) = (d + sqrt(eps^2 + d^2)) / 2.
// Why   : unlike the symmetric Dirichlet energy it is finite and smooth for
//         folded triangles, so a descent can start from a tangled placement
//         (an open chart border, a concave ring, where neither Tutte nor the
//         copies' mean is flip-free); as eps falls, chi -> max(det, 0) and
//         the minimiser's triangles all turn positive when the fixed ring
//         admits that at all.
#pragma once

#include <array>
#include <cmath>

#include "transfer/sym_dirichlet.h"

namespace soupuv::transfer::detail {

constexpr double kUntangleTheta = 0.5;  // weight of the area term

inline double chi(double d, double eps) { return 0.5 * (d + std::sqrt(eps * eps + d * d)); }

inline double untangle_energy(const RestTriangle& r, const std::array<Vec2, 3>& uv, double eps) {
  const Jacobian J = jacobian(r, uv);
  const double d = J.det();
  return r.area * ((1 - kUntangleTheta) * J.frobenius2() + kUntangleTheta * (d * d + 1)) /
         chi(d, eps);
}

inline Vec2 untangle_gradient(const RestTriangle& r, const std::array<Vec2, 3>& uv, int k,
                              double eps) {
  const Jacobian J = jacobian(r, uv);
  const double d = J.det(), f = J.frobenius2();
  const double c = chi(d, eps), dc = 0.5 * (1 + d / std::sqrt(eps * eps + d * d));
  const double numerator = (1 - kUntangleTheta) * f + kUntangleTheta * (d * d + 1);
  // dE/dJ = A [ (1-theta) 2J / c + (theta 2 d / c - numerator dc / c^2) Cof(J) ]
  const double a = r.area * (1 - kUntangleTheta) * 2 / c;
  const double b = r.area * (kUntangleTheta * 2 * d / c - numerator * dc / (c * c));
  const Vec2 g = r.g[k];
  const Vec2 Jg{J.j00 * g.x + J.j01 * g.y, J.j10 * g.x + J.j11 * g.y};
  const Vec2 Cg{J.j11 * g.x - J.j10 * g.y, -J.j01 * g.x + J.j00 * g.y};
  return {a * Jg.x + b * Cg.x, a * Jg.y + b * Cg.y};
}

}  // namespace soupuv::transfer::detail
