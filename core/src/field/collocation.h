// The collocation operator of eq. 5, A q = phi at the centroids, applied in
// O(n) with the FMM, plus the pieces the solvers share: single entries and
// columns of A, the near-field block-Jacobi preconditioner, and a fresh
// verification of a charge vector.
//
// A_ij = potential at centroid i of triangle j with unit charge (sources.h
// rule: closed form near, quadrature otherwise). Everything the FMM would
// evaluate directly is precomputed once as a sparse matrix (O(n) entries, a
// bounded number per row): the FMM then contributes only its far field, and a
// mat-vec is P2M..L2P plus one sparse product.
#pragma once

#include <Eigen/Dense>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "soupuv/field/fmm.h"
#include "soupuv/field/sources.h"

namespace soupuv::field {

class CollocationOperator {
 public:
  enum class Accuracy { full, cheap };
  // cheap_order > 0 also builds a second FMM of that (lower) order over the
  // same tree: it shares the near matrix, only the far field is coarser. The
  // Krylov solver iterates with it and corrects with the full operator.
  CollocationOperator(const SourceGeometry& sources, const FmmOptions& options, int cheap_order = 0);
  // phi = A q (far field of the requested accuracy; the near part is exact).
  void apply(const std::vector<double>& q, std::vector<double>& phi, Accuracy accuracy = Accuracy::full);
  // phi = A q with a far field of this expansion order over the same tree
  // (built on first use and kept): the verification's higher-order pass
  // reuses the near matrix instead of recomputing every near pair.
  void apply_order(const std::vector<double>& q, std::vector<double>& phi, int order);
  size_t size() const { return src_.size(); }
  const Fmm& fmm() const { return *fmm_; }
  size_t near_entries() const { return near_val_.size(); }
  // A restricted to the triangles `idx` (rows: their centroids): entries
  // from the near matrix where it has them (float-rounded), the rest by
  // unit_potential. `mark` is scratch of size() ints, all -1, returned so.
  Eigen::MatrixXd block(const std::vector<uint32_t>& idx, std::vector<int>& mark) const;
  // Appends to `out` the triangles j != i with A_ij >= ratio * A_ii (from the
  // near matrix): the triangles that nearly coincide with triangle i as seen
  // from its centroid (overlapping copies in a noisy soup).
  void strong_couplings(uint32_t i, double ratio, std::vector<uint32_t>& out) const;
  double setup_seconds() const { return setup_seconds_; }
  // Row i of the precomputed near matrix: A_ij for j = cols[k], k < count.
  struct NearRow {
    const uint32_t* cols;
    const float* vals;
    size_t count;
  };
  NearRow near_row(uint32_t i) const {
    const auto& cols = leaf_cols_[leaf_[i]];
    return {cols.data(), &near_val_[near_start_[i]], cols.size()};
  }

 private:
  void apply_with(Fmm& far, const std::vector<double>& q, std::vector<double>& phi) const;

  const SourceGeometry& src_;
  FmmOptions options_;
  int threads_;
  std::unique_ptr<Fmm> fmm_, cheap_;
  std::map<int, std::unique_ptr<Fmm>> by_order_;   // apply_order's far fields
  std::vector<int> leaf_;                 // target leaf of each centroid
  // Every pair the FMM takes directly (the target leaf's near source leaves),
  // A_ij precomputed once; a mat-vec's near part is then one sparse product.
  // All targets of a leaf share its column list, so only values are stored
  // per target, as float: 4 bytes per entry (~900 entries per row at leaf
  // size 32). Every entry is positive and rounded by at most 6e-8 of
  // itself, so for the (positive) charges the near sum is off by < 6e-8
  // relative: far under the FMM's own error.
  std::vector<std::vector<uint32_t>> leaf_cols_;   // per target leaf
  std::vector<std::vector<uint32_t>> leaf_rows_;   // per target leaf: the centroids in it
  std::vector<size_t> near_start_;                 // per target: offset into near_val_
  std::vector<float> near_val_;
  double setup_seconds_ = 0;
};

// Block-Jacobi over compact groups of source triangles, with overlap
// (restricted additive Schwarz): each block is extended by the triangles
// strongly coupled to one of its rows (A_ij >= overlap_ratio * A_ii), A is
// restricted to the extended set and LU-factorised once, and applying it
// writes back only the block's own rows. Without the overlap, two
// neighbouring triangles that fall into different blocks leave their
// difference mode (q_i - q_j) to GMRES: after the coarse correction
// (charge_coarse.h) that mode, on a few rows along block borders, is where
// the max residual sits.
// The entries come from the operator's near matrix (a block's triangles are
// near each other): recomputing them was ~6 % of a solve.
class LeafBlockPreconditioner {
 public:
  // overlap_ratio <= 0: plain block-Jacobi.
  LeafBlockPreconditioner(const CollocationOperator& A, const std::vector<std::vector<uint32_t>>& blocks,
                          int threads, double overlap_ratio = 0);
  void apply(const std::vector<double>& r, std::vector<double>& z) const;
  // Triangles added by the overlap, over all blocks.
  size_t overlap_size() const { return overlap_; }

 private:
  std::vector<std::vector<uint32_t>> blocks_;  // own rows first, then the overlap
  std::vector<size_t> own_;                    // per block: how many rows are its own
  std::vector<Eigen::PartialPivLU<Eigen::MatrixXd>> lu_;
  int threads_;
  size_t overlap_ = 0;
};

// Potentials at the centroids by a fresh evaluation of the final charges:
// direct summation when n <= direct_max, else the FMM with a far field of
// order `fmm_order` (above the solve's) plus the exact near pairs. `op`, when
// given, lends its near matrix (the model's own entries, computed once from
// the geometry, never updated by a solver): building it again was ~30 % of
// a 100k solve's CPU. Returns max |phi - mean| / mean.
double verify_potential(const SourceGeometry& sources, const std::vector<double>& q, size_t direct_max,
                        int fmm_order, int threads, CollocationOperator* op, std::string* method,
                        double* mean_out);

}  // namespace soupuv::field
