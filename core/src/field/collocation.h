// The collocation operator of eq. 5, A q = phi at the centroids, applied in
// O(n) with the FMM, plus the pieces the solvers share: single entries and
// columns of A, the near-field block-Jacobi preconditioner, and a fresh
// verification of a charge vector.
//
// A_ij = potential at centroid i of triangle j with unit charge (sources.h
// rule: closed form near, quadrature otherwise). The FMM's near field skips
// the closed-form pairs; they are precomputed once as a sparse matrix, since
// they are the expensive, constant part.
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <vector>

#include "soupuv/field/fmm.h"
#include "soupuv/field/sources.h"

namespace soupuv::field {

class CollocationOperator {
 public:
  CollocationOperator(const SourceGeometry& sources, const FmmOptions& options);
  // phi = A q
  void apply(const std::vector<double>& q, std::vector<double>& phi);
  size_t size() const { return src_.size(); }
  const Fmm& fmm() const { return *fmm_; }

 private:
  const SourceGeometry& src_;
  int threads_;
  std::unique_ptr<Fmm> fmm_;
  std::vector<int> leaf_;                 // target leaf of each centroid
  std::vector<size_t> close_start_;       // CSR over targets
  std::vector<uint32_t> close_col_;
  std::vector<double> close_val_;
};

// Block-Jacobi over the FMM's source leaves: each block is A restricted to a
// leaf's triangles (rows: their centroids), LU-factorised once.
class LeafBlockPreconditioner {
 public:
  LeafBlockPreconditioner(const SourceGeometry& sources, const std::vector<std::vector<uint32_t>>& blocks,
                          int threads);
  void apply(const std::vector<double>& r, std::vector<double>& z) const;

 private:
  std::vector<std::vector<uint32_t>> blocks_;
  std::vector<Eigen::PartialPivLU<Eigen::MatrixXd>> lu_;
  int threads_;
};

// Potentials at the centroids by a fresh evaluation: direct summation when
// n <= direct_max, else a high-order FMM. Returns max |phi - mean| / mean.
double verify_potential(const SourceGeometry& sources, const std::vector<double>& q, size_t direct_max,
                        int threads, std::string* method, double* mean_out);

}  // namespace soupuv::field
