// Two-level preconditioner for the Krylov charge solve: a coarse correction
// over blocks of source triangles, followed (multiplicatively) by the
// block-Jacobi preconditioner.
//
//   CoarseCorrection M(A, src, blocks, fine, threads);
//   M.apply(r, z);      // z = P y + B (r - A~ P y),  y = E^-1 R r
//
// Inputs: the collocation operator A (its precomputed near matrix), the
// source geometry, a partition of the triangles into compact blocks (the
// coarse unknowns), and the fine (block-Jacobi) preconditioner B.
// Coarse space: P_J = charge spread over block J in proportion to area (the
// shape a smooth charge density has at block scale), R_I = sum of the
// residual over block I's collocation rows, E = R A~ P (n_blocks^2, dense LU).
// A~ P y is A P y with the far blocks as monopoles (Taylor-expanded to first
// order about each block's rows) and the near blocks summed per row (near
// matrix entries where A has them, triangle monopoles beyond): a few percent
// off at worst, which only weakens the preconditioner, never the answer.
//
// Why: block-Jacobi resolves each block against itself only, so a smooth
// charge change (block scale and up) is over-corrected by about the ratio of
// the global to the local potential, which grows with the number of blocks:
// those modes are GMRES's slow ones (iterations grew with n, 41 at 105,800
// triangles, 67 on the noisy 100k soup). The coarse solve takes them out
// first; an additive correction would add to the same large eigenvalues.
// Cost: O(n * near blocks) per apply plus O(n_blocks^2); set-up O(n * near
// blocks * block size) plus an O(n_blocks^3) LU (n_blocks ~ n / 100).
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <vector>

#include "collocation.h"
#include "soupuv/field/sources.h"

namespace soupuv::field {

class CoarseCorrection {
 public:
  // near_factor: blocks I, J are summed per row when their centres are
  // closer than near_factor * (radius_I + radius_J), else as a monopole
  // Taylor-expanded at I's centre; within touch_factor * (...) per triangle,
  // beyond it as J's monopole at each row.
  CoarseCorrection(const CollocationOperator& A, const SourceGeometry& src,
                   const std::vector<std::vector<uint32_t>>& blocks, const LeafBlockPreconditioner& fine,
                   int threads, double near_factor = 2.0, double touch_factor = 1.3);
  void apply(const std::vector<double>& r, std::vector<double>& z) const;
  size_t coarse_size() const { return blocks_.size(); }
  // Row-by-block entries of the near part of A~ P.
  size_t near_entries() const { return G_.size(); }
  // t = A~ P y for one value per block (tests compare it with A P y).
  void coarse_operator(const Eigen::VectorXd& y, std::vector<double>& t) const;

 private:

  const SourceGeometry& src_;
  const LeafBlockPreconditioner& fine_;
  int threads_;
  std::vector<std::vector<uint32_t>> blocks_;
  std::vector<int> block_of_;          // per triangle
  std::vector<double> weight_;         // per triangle: area / block area (P's entries)
  std::vector<Vec3> source_centre_;    // per block: area-weighted centroid (no dipole about it)
  std::vector<Vec3> row_centre_;       // per block: mean of its rows' centroids
  std::vector<std::vector<int>> near_blocks_;  // per block, ascending
  std::vector<size_t> g_start_;        // per block: its rows x near blocks in G_
  std::vector<double> G_;              // (A P)_iJ for J near block(i)
  Eigen::PartialPivLU<Eigen::MatrixXd> coarse_lu_;
};

}  // namespace soupuv::field
