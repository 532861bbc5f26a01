// Collocation operator, leaf-block preconditioner and verification.
#include "collocation.h"

#include <omp.h>

#include <algorithm>
#include <cmath>

#include "soupuv/field/direct.h"
#include "soupuv/field/triangle_integrals.h"

namespace soupuv::field {

CollocationOperator::CollocationOperator(const SourceGeometry& sources, const FmmOptions& options)
    : src_(sources), threads_(options.threads > 0 ? options.threads : omp_get_max_threads()) {
  fmm_ = std::make_unique<Fmm>(src_, options, src_.centroid);
  const long n = static_cast<long>(src_.size());
  leaf_.resize(n);
  std::vector<std::vector<std::pair<uint32_t, double>>> close(n);
#pragma omp parallel for num_threads(threads_) schedule(dynamic, 64)
  for (long i = 0; i < n; ++i) {
    leaf_[i] = fmm_->locate(src_.centroid[i]);
    for (uint32_t j : fmm_->near_source_triangles(leaf_[i]))
      if (src_.is_near(j, src_.centroid[i]) && src_.area[j] > 0)
        close[i].push_back({j, unit_potential(src_, j, src_.centroid[i])});
  }
  close_start_.assign(n + 1, 0);
  for (long i = 0; i < n; ++i) close_start_[i + 1] = close_start_[i] + close[i].size();
  close_col_.resize(close_start_[n]);
  close_val_.resize(close_start_[n]);
  for (long i = 0; i < n; ++i)
    for (size_t k = 0; k < close[i].size(); ++k) {
      close_col_[close_start_[i] + k] = close[i][k].first;
      close_val_[close_start_[i] + k] = close[i][k].second;
    }
}

void CollocationOperator::apply(const std::vector<double>& q, std::vector<double>& phi) {
  fmm_->set_charges(q);
  const long n = static_cast<long>(src_.size());
  phi.resize(n);
#pragma omp parallel for num_threads(threads_) schedule(dynamic, 64)
  for (long i = 0; i < n; ++i) {
    double f = fmm_->potential_without_close(leaf_[i], src_.centroid[i]);
    for (size_t k = close_start_[i]; k < close_start_[i + 1]; ++k) f += close_val_[k] * q[close_col_[k]];
    phi[i] = f;
  }
}

LeafBlockPreconditioner::LeafBlockPreconditioner(const SourceGeometry& sources,
                                                 const std::vector<std::vector<uint32_t>>& blocks, int threads)
    : blocks_(blocks), lu_(blocks.size()), threads_(threads > 0 ? threads : omp_get_max_threads()) {
#pragma omp parallel for num_threads(threads_) schedule(dynamic, 8)
  for (long b = 0; b < static_cast<long>(blocks_.size()); ++b) {
    const auto& idx = blocks_[b];
    const int m = static_cast<int>(idx.size());
    Eigen::MatrixXd A(m, m);
    for (int r = 0; r < m; ++r)
      for (int c = 0; c < m; ++c) A(r, c) = unit_potential(sources, idx[c], sources.centroid[idx[r]]);
    lu_[b] = Eigen::PartialPivLU<Eigen::MatrixXd>(A);
  }
}

void LeafBlockPreconditioner::apply(const std::vector<double>& r, std::vector<double>& z) const {
  z.resize(r.size());
#pragma omp parallel for num_threads(threads_) schedule(dynamic, 16)
  for (long b = 0; b < static_cast<long>(blocks_.size()); ++b) {
    const auto& idx = blocks_[b];
    Eigen::VectorXd v(idx.size());
    for (size_t k = 0; k < idx.size(); ++k) v[k] = r[idx[k]];
    Eigen::VectorXd x = lu_[b].solve(v);
    for (size_t k = 0; k < idx.size(); ++k) z[idx[k]] = x[k];
  }
}

double verify_potential(const SourceGeometry& sources, const std::vector<double>& q, size_t direct_max,
                        int threads, std::string* method, double* mean_out) {
  std::vector<double> phi;
  if (sources.size() <= direct_max) {
    direct_sum(sources, q, sources.centroid, &phi, nullptr, threads);
    if (method) *method = "direct";
  } else {
    FmmOptions o;
    o.order = 10;
    o.theta = 0.4;
    o.threads = threads;
    CollocationOperator op(sources, o);
    op.apply(q, phi);
    if (method) *method = "fmm-p10-theta0.4";
  }
  double mean = 0;
  for (double f : phi) mean += f;
  mean /= std::max<size_t>(1, phi.size());
  double worst = 0;
  for (double f : phi) worst = std::max(worst, std::fabs(f - mean));
  if (mean_out) *mean_out = mean;
  return mean != 0 ? worst / std::fabs(mean) : INFINITY;
}

}  // namespace soupuv::field
