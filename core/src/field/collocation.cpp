// Collocation operator, leaf-block preconditioner and verification.
#include "collocation.h"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "soupuv/field/direct.h"
#include "soupuv/field/quadrature.h"
#include "soupuv/field/triangle_integrals.h"
#include "near_row.h"
#include "tracer_closed_form_batch.h"

namespace soupuv::field {

// LU of a preconditioner block. Coplanar, overlapping triangles (exact CAD
// exports: bracket-exact of the corpus) give near-equal rows and columns;
// their exactly singular block made the preconditioner return inf and the
// Krylov solve a non-finite total charge. A block that is singular to
// working precision is factored with its diagonal raised by 1e-6 of its
// largest entry: it only preconditions, the outer iteration still solves
// the exact system.
Eigen::PartialPivLU<Eigen::MatrixXd> factor_regularised(Eigen::MatrixXd block) {
  Eigen::PartialPivLU<Eigen::MatrixXd> lu(block);
  if (lu.rcond() > 1e-12) return lu;
  block.diagonal().array() += 1e-6 * block.cwiseAbs().maxCoeff();
  return Eigen::PartialPivLU<Eigen::MatrixXd>(block);
}

namespace {
// sum_k w[k] / |x - p_k| over m points: the middle band's degree-6 rule
// (sources.h) on one triangle's precomputed points, a loop the compiler
// vectorises (the field module builds with -fno-math-errno for this; its
// scalar twin built the points and took one sqrt at a time: as much of the
// set-up as the closed form).
__attribute__((target_clones("avx2", "default")))
double weighted_inverse_sum(const double* px, const double* py, const double* pz, const double* w, int m, Vec3 x) {
  double s = 0;
#pragma omp simd reduction(+ : s)
  for (int k = 0; k < m; ++k) {
    const double dx = x.x - px[k], dy = x.y - py[k], dz = x.z - pz[k];
    s += w[k] / std::sqrt(dx * dx + dy * dy + dz * dz);
  }
  return s;
}

// sum_k a[k] * b[k]; the simd reduction lets the compiler keep several
// partial sums (one running sum is bound by the add latency).
__attribute__((target_clones("avx2", "default")))
double dot_float_double(const float* a, const double* b, size_t m) {
  double s = 0;
#pragma omp simd reduction(+ : s)
  for (size_t k = 0; k < m; ++k) s += static_cast<double>(a[k]) * b[k];
  return s;
}
}  // namespace

CollocationOperator::CollocationOperator(const SourceGeometry& sources, const FmmOptions& options,
                                         int cheap_order)
    : src_(sources), options_(options), threads_(options.threads > 0 ? options.threads : omp_get_max_threads()) {
  auto t0 = std::chrono::steady_clock::now();
  fmm_ = std::make_unique<Fmm>(src_, options, src_.centroid);
  if (cheap_order > 0 && cheap_order < options.order) {
    // Same tree and lists (they do not depend on the order), so the near
    // matrix below is exactly the cheap FMM's near field too.
    cheap_ = std::make_unique<Fmm>(*fmm_, cheap_order);
  }
  const long n = static_cast<long>(src_.size());
  leaf_.resize(n);
  near_start_.assign(n + 1, 0);
  leaf_cols_.resize(fmm_->stats().target_cells);
  for (long i = 0; i < n; ++i) {
    leaf_[i] = fmm_->locate(src_.centroid[i]);
    auto& cols = leaf_cols_[leaf_[i]];
    if (cols.empty()) cols = fmm_->near_source_triangles(leaf_[i]);
    near_start_[i + 1] = near_start_[i] + cols.size();
  }
  near_val_.resize(near_start_[n]);
  // Each source's closed-form frame, for the pairs within the closed-form
  // radius: those are evaluated four at a time (closed_form_potentials).
  std::vector<tracer::TriangleFrame> frames(n);
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (long j = 0; j < n; ++j) frames[j] = tracer::triangle_frame(src_.a[j], src_.b[j], src_.c[j]);
  // ... and its middle-band points (the degree-6 rule of sources.cpp's
  // middle_band, the same barycentric combination), by coordinate.
  const TriangleRule& band_rule = triangle_rule(6);
  const int mb = static_cast<int>(band_rule.weights.size());
  std::vector<double> bx(size_t(n) * mb), by(size_t(n) * mb), bz(size_t(n) * mb);
#pragma omp parallel for num_threads(threads_) schedule(static)
  for (long j = 0; j < n; ++j)
    for (int k = 0; k < mb; ++k) {
      const auto& l = band_rule.points[k];
      const Vec3 p = l[0] * src_.a[j] + l[1] * src_.b[j] + l[2] * src_.c[j];
      bx[size_t(j) * mb + k] = p.x, by[size_t(j) * mb + k] = p.y, bz[size_t(j) * mb + k] = p.z;
    }
  leaf_rows_.resize(leaf_cols_.size());
  for (long i = 0; i < n; ++i) leaf_rows_[leaf_[i]].push_back(static_cast<uint32_t>(i));
  const auto& rows = leaf_rows_;
  const int m = src_.points_per_triangle;
#pragma omp parallel num_threads(threads_)
  {
    detail::NearColumns nc;
    std::vector<uint8_t> near;
    std::vector<double> closed_value;
    std::vector<uint32_t> closed_at;                     // positions k in the row
    std::vector<const tracer::TriangleFrame*> closed_frames;
#pragma omp for schedule(dynamic, 4)
    for (long leaf = 0; leaf < static_cast<long>(rows.size()); ++leaf) {
      if (rows[leaf].empty()) continue;
      // The leaf's columns, gathered once for all its rows (near_row.h).
      const auto& cols = leaf_cols_[leaf];
      const size_t count = cols.size();
      nc.count = count;
      nc.cx.resize(count), nc.cy.resize(count), nc.cz.resize(count), nc.near_r2.resize(count);
      nc.px.resize(count * m), nc.py.resize(count * m), nc.pz.resize(count * m);
      near.resize(count);
      for (size_t k = 0; k < count; ++k) {
        const uint32_t j = cols[k];
        nc.cx[k] = src_.centroid[j].x, nc.cy[k] = src_.centroid[j].y, nc.cz[k] = src_.centroid[j].z;
        const double r = src_.near_factor * src_.radius[j];  // as SourceGeometry::is_near
        nc.near_r2[k] = r * r;
        for (int q = 0; q < m; ++q) {
          const Vec3 p = src_.qpoints[static_cast<size_t>(j) * m + q];
          nc.px[q * count + k] = p.x, nc.py[q * count + k] = p.y, nc.pz[q * count + k] = p.z;
        }
      }
      for (uint32_t i : rows[leaf]) {
        const Vec3 x = src_.centroid[i];
        float* val = &near_val_[near_start_[i]];
        detail::plain_near_row(nc, m, src_.qweights.data(), x, val, near.data());
        closed_at.clear();
        closed_frames.clear();
        for (size_t k = 0; k < count; ++k) {
          if (!near[k]) continue;
          // Closed form or the degree-6 band: unit_potential's own rule
          // (the closed form below, batched; a zero-area or degenerate
          // triangle has no potential, as in near_potential_field).
          const uint32_t j = cols[k];
          double v = 0;
          if (src_.is_closed_form(j, x)) {
            if (src_.area[j] > 0 && !frames[j].degenerate) {
              closed_at.push_back(uint32_t(k));
              closed_frames.push_back(&frames[j]);
            }
          } else if (src_.area[j] > 0) {
            const size_t o = size_t(j) * mb;
            v = weighted_inverse_sum(&bx[o], &by[o], &bz[o], band_rule.weights.data(), mb, x);
          }
          val[k] = static_cast<float>(v);
        }
        closed_value.resize(closed_at.size());
        tracer::closed_form_potentials(closed_frames.data(), int(closed_frames.size()), x, closed_value.data());
        for (size_t c = 0; c < closed_at.size(); ++c)
          val[closed_at[c]] = static_cast<float>(closed_value[c] / src_.area[cols[closed_at[c]]]);
      }
    }
  }
  setup_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void CollocationOperator::apply(const std::vector<double>& q, std::vector<double>& phi, Accuracy accuracy) {
  apply_with((accuracy == Accuracy::cheap && cheap_) ? *cheap_ : *fmm_, q, phi);
}

void CollocationOperator::apply_order(const std::vector<double>& q, std::vector<double>& phi, int order) {
  if (order == options_.order) return apply_with(*fmm_, q, phi);
  auto& far = by_order_[order];
  if (!far) {
    // Same tree and lists, so the near matrix fits.
    far = std::make_unique<Fmm>(*fmm_, order);
  }
  apply_with(*far, q, phi);
}

void CollocationOperator::apply_with(Fmm& f, const std::vector<double>& q, std::vector<double>& phi) const {
  f.set_charges(q);
  phi.resize(src_.size());
  // By target leaf: its rows share one column list, so the charges are
  // gathered once per leaf and each row is a contiguous dot product.
#pragma omp parallel num_threads(threads_)
  {
    std::vector<double> qc;
#pragma omp for schedule(dynamic, 8)
    for (long leaf = 0; leaf < static_cast<long>(leaf_rows_.size()); ++leaf) {
      const auto& rows = leaf_rows_[leaf];
      if (rows.empty()) continue;
      const auto& cols = leaf_cols_[leaf];
      qc.resize(cols.size());
      for (size_t k = 0; k < cols.size(); ++k) qc[k] = q[cols[k]];
      for (uint32_t i : rows)
        phi[i] = f.far_potential(static_cast<int>(leaf), src_.centroid[i]) +
                 dot_float_double(&near_val_[near_start_[i]], qc.data(), cols.size());
    }
  }
}

Eigen::MatrixXd CollocationOperator::block(const std::vector<uint32_t>& idx, std::vector<int>& mark) const {
  const int m = static_cast<int>(idx.size());
  Eigen::MatrixXd A(m, m);
  int marked = -1;  // the target leaf whose columns `mark` holds
  auto unmark = [&] {
    if (marked >= 0)
      for (uint32_t j : leaf_cols_[marked]) mark[j] = -1;
  };
  for (int r = 0; r < m; ++r) {
    const uint32_t i = idx[r];
    if (leaf_[i] != marked) {
      unmark();
      marked = leaf_[i];
      const auto& cols = leaf_cols_[marked];
      for (size_t k = 0; k < cols.size(); ++k) mark[cols[k]] = static_cast<int>(k);
    }
    const float* val = &near_val_[near_start_[i]];
    for (int c = 0; c < m; ++c) {
      const int k = mark[idx[c]];
      A(r, c) = k >= 0 ? static_cast<double>(val[k]) : unit_potential(src_, idx[c], src_.centroid[i]);
    }
  }
  unmark();
  return A;
}

void CollocationOperator::strong_couplings(uint32_t i, double ratio, std::vector<uint32_t>& out) const {
  const auto& cols = leaf_cols_[leaf_[i]];
  const float* val = &near_val_[near_start_[i]];
  double self = 0;
  for (size_t k = 0; k < cols.size(); ++k)
    if (cols[k] == i) self = val[k];
  if (!(self > 0)) return;
  for (size_t k = 0; k < cols.size(); ++k)
    if (cols[k] != i && val[k] >= ratio * self) out.push_back(cols[k]);
}

LeafBlockPreconditioner::LeafBlockPreconditioner(const CollocationOperator& op,
                                                 const std::vector<std::vector<uint32_t>>& blocks, int threads,
                                                 double overlap_ratio)
    : blocks_(blocks), own_(blocks.size()), lu_(blocks.size()),
      threads_(threads > 0 ? threads : omp_get_max_threads()) {
  size_t overlap = 0;
#pragma omp parallel num_threads(threads_) reduction(+ : overlap)
  {
    // This thread's own ICV (it ends with the region): Eigen's LU would
    // otherwise fork an OpenMP team for the GEMM of every block whenever
    // this region has one thread (Eigen only stays serial inside a team of
    // several): 40 % of a one-thread solve's samples were libgomp spinning.
    omp_set_num_threads(1);
    std::vector<int> mark(op.size(), -1);
    std::vector<uint32_t> strong;
#pragma omp for schedule(dynamic, 8)
    for (long b = 0; b < static_cast<long>(blocks_.size()); ++b) {
      auto& idx = blocks_[b];
      own_[b] = idx.size();
      if (overlap_ratio > 0) {
        strong.clear();
        for (size_t k = 0; k < own_[b]; ++k) op.strong_couplings(idx[k], overlap_ratio, strong);
        // `mark` doubles as the membership test (block() leaves it all -1).
        for (uint32_t j : idx) mark[j] = 0;
        for (uint32_t j : strong)
          if (mark[j] < 0) {
            mark[j] = 0;
            idx.push_back(j);
          }
        for (uint32_t j : idx) mark[j] = -1;
        overlap += idx.size() - own_[b];
      }
      lu_[b] = factor_regularised(op.block(idx, mark));
    }
  }
  overlap_ = overlap;
}

void LeafBlockPreconditioner::apply(const std::vector<double>& r, std::vector<double>& z) const {
  z.resize(r.size());
  // One block per chunk: a few dozen blocks of ~128 at small sizes would
  // otherwise split unevenly over the threads.
#pragma omp parallel for num_threads(threads_) schedule(dynamic, 1)
  for (long b = 0; b < static_cast<long>(blocks_.size()); ++b) {
    const auto& idx = blocks_[b];
    Eigen::VectorXd v(idx.size());
    for (size_t k = 0; k < idx.size(); ++k) v[k] = r[idx[k]];
    Eigen::VectorXd x = lu_[b].solve(v);
    // Own rows only: every triangle is written by exactly one block.
    for (size_t k = 0; k < own_[b]; ++k) z[idx[k]] = x[k];
  }
}

double verify_potential(const SourceGeometry& sources, const std::vector<double>& q, size_t direct_max,
                        int fmm_order, int threads, CollocationOperator* op, std::string* method,
                        double* mean_out) {
  std::vector<double> phi;
  if (sources.size() <= direct_max) {
    direct_sum(sources, q, sources.centroid, &phi, nullptr, threads);
    if (method) *method = "direct";
  } else {
    std::unique_ptr<CollocationOperator> own;
    if (!op) {
      FmmOptions o;
      o.order = fmm_order;
      o.leaf_size = 64;
      o.threads = threads;
      own = std::make_unique<CollocationOperator>(sources, o);
      op = own.get();
    }
    op->apply_order(q, phi, fmm_order);
    if (method) *method = "fmm-p" + std::to_string(fmm_order) + "+near-matrix";
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
