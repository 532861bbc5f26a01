// SLIM (Rabinovich, Poranne, Panozzo, Sorkine-Hornung 2017, "Scalable
// Locally Injective Mappings") on one UV mesh, for the symmetric Dirichlet
// energy (the UV solve's flattenings use it: uvsolve/island_solve, piece_flatten).
//
// Input : the mesh's triangles (vertex ids), each one's rest shape
//         (sym_dirichlet.h: flattened at the wanted scale and orientation;
//         invalid rest = left out of the energy), the vertices' UVs (a start
//         with every valid triangle positively oriented) and which vertices
//         are fixed.
// Output: the free vertices moved to lower the energy sum A (|J|^2 +
//         |J^-1|^2); the energy before and after and the iterations made.
//         Every valid triangle stays positively oriented (a step never
//         reaches a degenerate triangle).
// Method: per iteration, the local step takes each triangle's Jacobian J =
//         U S V^T, its closest rotation R = U V^T and weights W = U diag(w)
//         U^T with w_i^2 = f'(s_i) / (2 (s_i - 1)) = (1 + s_i)(1 + s_i^2) /
//         s_i^3 for f(s) = s^2 + s^-2; the global step minimises sum A
//         ||W (J - R)||_F^2 over the free vertices (one sparse SPD solve,
//         Eigen's SimplicialLDLT, the pattern analysed once); the step from
//         the current UVs toward that solution is bounded to 0.8 of the first
//         degenerate triangle's step (Smith and Schaefer 2015) and halved
//         until the true energy drops.
// Cost  : O(mesh size) per iteration (the sparse factorisation of a planar
//         mesh's Laplacian-like system), iterations <= max_iterations.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "soupuv/vec.h"
#include "sym_dirichlet.h"  // relative: tests include this header by path

namespace soupuv::transfer::detail {

struct SlimOptions {
  int max_iterations = 40;
  double min_relative_decrease = 1e-4;
  // Called after each iteration that lowered the energy, with the number of
  // iterations made and the UVs; returning true ends the solve there (a
  // caller that can already tell the result will be refused).
  std::function<bool(int iterations, const std::vector<Vec2>& uv)> stop_after;
};

// The local step's target for one triangle of Jacobian J (det J > 0):
// M = W^T W = U diag(w(s1), w(s2)) U^T, w(s) = (1 + s)(1 + s^2) / s^3, and
// the closest rotation R = U V^T (both row-major 2x2), for the singular
// value decomposition J = U diag(s1, s2) V^T.
struct LocalTarget {
  double m00, m01, m11;
  double r00, r01, r10, r11;
};
LocalTarget local_target(const Jacobian& J);

struct SlimResult {
  double energy_before = 0, energy_after = 0;
  int iterations = 0;
  bool started = false;  // false: the start had a non-positive valid triangle
};

// Sum of the symmetric Dirichlet energies of the valid triangles (+inf when
// one is not positively oriented).
double mesh_energy(const std::vector<std::array<uint32_t, 3>>& triangles,
                   const std::vector<RestTriangle>& rest, const std::vector<Vec2>& uv);

SlimResult slim_relax(const std::vector<std::array<uint32_t, 3>>& triangles,
                      const std::vector<RestTriangle>& rest, const std::vector<uint8_t>& fixed,
                      std::vector<Vec2>& uv, const SlimOptions& options = {});

// The L2 stretch metric itself, after SLIM: the map's squared normalised L2
// stretch is F = S U / A3^2 with S = sum A3 (Gamma^2 + gamma^2) / 2 (Sander
// et al.'s UV -> surface singular values) and U = sum UV area; the mesh's
// own terms plus the rest of the map's (others_s, others_u, held fixed) are
// minimised by gradient descent preconditioned with the rest shapes'
// Dirichlet matrix (factored once), with the same flip-free step bound and
// backtracking. F is infinite on a flip too (S ~ 1 / det^2). Energies in the
// result are F before and after (times A3^2).
double mesh_l2_form(const std::vector<std::array<uint32_t, 3>>& triangles,
                    const std::vector<RestTriangle>& rest, const std::vector<Vec2>& uv,
                    double others_s, double others_u);

SlimResult l2_relax(const std::vector<std::array<uint32_t, 3>>& triangles,
                    const std::vector<RestTriangle>& rest, const std::vector<uint8_t>& fixed,
                    std::vector<Vec2>& uv, double others_s, double others_u,
                    const SlimOptions& options = {});

}  // namespace soupuv::transfer::detail
