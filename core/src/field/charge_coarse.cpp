// Coarse correction for the Krylov charge solve (see charge_coarse.h).
#include "charge_coarse.h"

#include <omp.h>

#include <algorithm>
#include <cmath>

namespace soupuv::field {

namespace {
// sum_k w[k] / |x - p_k| over the k with taken[k] != row (the triangles the
// near matrix did not already give). Flat, so it vectorises (AVX2 clone).
__attribute__((target_clones("avx2", "default")))
double untaken_monopoles(const double* px, const double* py, const double* pz, const double* w,
                         const int32_t* taken, size_t count, Vec3 x, int32_t row) {
  double sum = 0;
#pragma omp simd reduction(+ : sum)
  for (size_t k = 0; k < count; ++k) {
    const double dx = x.x - px[k], dy = x.y - py[k], dz = x.z - pz[k];
    const double v = w[k] / std::sqrt(dx * dx + dy * dy + dz * dz);
    sum += taken[k] != row ? v : 0.0;
  }
  return sum;
}
}  // namespace

CoarseCorrection::CoarseCorrection(const CollocationOperator& A, const SourceGeometry& src,
                                   const std::vector<std::vector<uint32_t>>& blocks,
                                   const LeafBlockPreconditioner& fine, int threads, double near_factor,
                                   double touch_factor)
    : src_(src), fine_(fine), threads_(threads > 0 ? threads : omp_get_max_threads()), blocks_(blocks) {
  const size_t n = src.size();
  const long nb = static_cast<long>(blocks_.size());
  block_of_.assign(n, -1);
  weight_.assign(n, 0.0);
  source_centre_.resize(nb);
  row_centre_.resize(nb);
  std::vector<double> source_radius(nb, 0.0), row_radius(nb, 0.0);
  for (long b = 0; b < nb; ++b) {
    double area = 0;
    Vec3 cs{0, 0, 0}, cr{0, 0, 0};
    for (uint32_t j : blocks_[b]) {
      block_of_[j] = static_cast<int>(b);
      area += src.area[j];
      cs += src.area[j] * src.centroid[j];
      cr += src.centroid[j];
    }
    const double count = static_cast<double>(std::max<size_t>(1, blocks_[b].size()));
    // A block of degenerate triangles still needs a non-zero coarse column.
    const bool flat = !(area > 0);
    for (uint32_t j : blocks_[b]) weight_[j] = flat ? 1.0 / count : src.area[j] / area;
    source_centre_[b] = flat ? (1.0 / count) * cr : (1.0 / area) * cs;
    row_centre_[b] = (1.0 / count) * cr;
    for (uint32_t j : blocks_[b]) {
      source_radius[b] = std::max(source_radius[b], norm(src.centroid[j] - source_centre_[b]) + src.radius[j]);
      row_radius[b] = std::max(row_radius[b], norm(src.centroid[j] - row_centre_[b]));
    }
  }
  // Near blocks: all pairs, O(n_blocks^2) distance tests (cheap next to the
  // LU below, which is cubic in n_blocks anyway).
  near_blocks_.resize(nb);
#pragma omp parallel for num_threads(threads_) schedule(dynamic, 16)
  for (long I = 0; I < nb; ++I)
    for (long J = 0; J < nb; ++J) {
      const double reach = near_factor * (row_radius[I] + source_radius[J]);
      if (J == I || norm2(row_centre_[I] - source_centre_[J]) < reach * reach)
        near_blocks_[I].push_back(static_cast<int>(J));
    }
  // Touching blocks (centres closer than touch_factor * (radius_I +
  // radius_J)) are summed triangle by triangle; the other near blocks are
  // far enough for the block's own monopole at each row (one term per row
  // instead of a hundred).
  std::vector<std::vector<char>> touching(nb);
  for (long I = 0; I < nb; ++I)
    for (int J : near_blocks_[I]) {
      const double reach = touch_factor * (row_radius[I] + source_radius[J]);
      touching[I].push_back(J == I || norm2(row_centre_[I] - source_centre_[J]) < reach * reach);
    }
  g_start_.assign(nb + 1, 0);
  for (long I = 0; I < nb; ++I) g_start_[I + 1] = g_start_[I] + blocks_[I].size() * near_blocks_[I].size();
  G_.assign(g_start_[nb], 0.0);
  // G_iJ = sum_{j in J} A_ij w_j: the near matrix's entries where it has
  // them; beyond, the triangles are well separated from i's leaf (the FMM
  // took them by expansion), so a monopole per triangle is accurate. The
  // triangles are laid out block by block (structure of arrays) so the
  // monopole sums are one vectorised loop per near block.
  std::vector<size_t> start(nb + 1, 0);
  for (long b = 0; b < nb; ++b) start[b + 1] = start[b] + blocks_[b].size();
  std::vector<double> px(n), py(n), pz(n), pw(n);
  std::vector<uint32_t> pos(n);  // triangle -> its slot in that layout
  for (long b = 0; b < nb; ++b)
    for (size_t k = 0; k < blocks_[b].size(); ++k) {
      const uint32_t j = blocks_[b][k];
      const size_t at = start[b] + k;
      px[at] = src.centroid[j].x;
      py[at] = src.centroid[j].y;
      pz[at] = src.centroid[j].z;
      pw[at] = weight_[j];
      pos[j] = static_cast<uint32_t>(at);
    }
#pragma omp parallel num_threads(threads_)
  {
    std::vector<int> slot(nb, -1);
    std::vector<int32_t> taken(n, -1);  // per layout slot: the row that took it from the near matrix
#pragma omp for schedule(dynamic, 4)
    for (long I = 0; I < nb; ++I) {
      const auto& nbI = near_blocks_[I];
      const size_t width = nbI.size();
      for (size_t s = 0; s < width; ++s) slot[nbI[s]] = static_cast<int>(s);
      for (size_t k = 0; k < blocks_[I].size(); ++k) {
        const uint32_t i = blocks_[I][k];
        double* g = &G_[g_start_[I] + k * width];
        const auto row = A.near_row(i);
        for (size_t e = 0; e < row.count; ++e) {
          const uint32_t j = row.cols[e];
          const int s = slot[block_of_[j]];
          if (s < 0 || !touching[I][s]) continue;
          g[s] += weight_[j] * static_cast<double>(row.vals[e]);
          taken[pos[j]] = static_cast<int32_t>(i);
        }
        const Vec3 x = src.centroid[i];
        for (size_t s = 0; s < width; ++s) {
          const int J = nbI[s];
          if (!touching[I][s]) {
            // Near, but not touching: the block's monopole at x itself.
            g[s] = 1.0 / norm(x - source_centre_[J]);
            continue;
          }
          const size_t b0 = start[J], count = start[J + 1] - b0;
          g[s] += untaken_monopoles(&px[b0], &py[b0], &pz[b0], &pw[b0], &taken[b0], count, x,
                                    static_cast<int32_t>(i));
        }
      }
      for (int J : nbI) slot[J] = -1;
    }
  }
  // E = R A~ P: near blocks from G (row sums), far blocks as monopoles at
  // the row centre (the first-order Taylor terms sum to zero over the rows).
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(nb, nb);
#pragma omp parallel for num_threads(threads_) schedule(dynamic, 16)
  for (long I = 0; I < nb; ++I) {
    const auto& nbI = near_blocks_[I];
    const double rows = static_cast<double>(blocks_[I].size());
    size_t s = 0;
    for (long J = 0; J < nb; ++J) {
      if (s < nbI.size() && nbI[s] == J) {
        double sum = 0;
        for (size_t k = 0; k < blocks_[I].size(); ++k) sum += G_[g_start_[I] + k * nbI.size() + s];
        E(I, J) = sum;
        ++s;
      } else {
        E(I, J) = rows / norm(row_centre_[I] - source_centre_[J]);
      }
    }
  }
  coarse_lu_ = Eigen::PartialPivLU<Eigen::MatrixXd>(E);
}

void CoarseCorrection::coarse_operator(const Eigen::VectorXd& y, std::vector<double>& t) const {
  const long nb = static_cast<long>(blocks_.size());
  t.resize(src_.size());
#pragma omp parallel for num_threads(threads_) schedule(dynamic, 8)
  for (long I = 0; I < nb; ++I) {
    // Far blocks: potential and its gradient at the row centre.
    const auto& nbI = near_blocks_[I];
    const Vec3 c = row_centre_[I];
    double phi = 0;
    Vec3 grad{0, 0, 0};
    size_t s = 0;
    for (long J = 0; J < nb; ++J) {
      if (s < nbI.size() && nbI[s] == J) {
        ++s;
        continue;
      }
      const Vec3 d = c - source_centre_[J];
      const double inv = 1.0 / norm(d);
      phi += y[J] * inv;
      grad -= (y[J] * inv * inv * inv) * d;
    }
    const size_t width = nbI.size();
    for (size_t k = 0; k < blocks_[I].size(); ++k) {
      const uint32_t i = blocks_[I][k];
      const double* g = &G_[g_start_[I] + k * width];
      double v = phi + dot(grad, src_.centroid[i] - c);
      for (size_t s2 = 0; s2 < width; ++s2) v += g[s2] * y[nbI[s2]];
      t[i] = v;
    }
  }
}

void CoarseCorrection::apply(const std::vector<double>& r, std::vector<double>& z) const {
  const long nb = static_cast<long>(blocks_.size());
  Eigen::VectorXd b(nb);
  for (long I = 0; I < nb; ++I) {
    double sum = 0;
    for (uint32_t i : blocks_[I]) sum += r[i];
    b[I] = sum;
  }
  const Eigen::VectorXd y = coarse_lu_.solve(b);
  std::vector<double> t;
  coarse_operator(y, t);
  for (size_t i = 0; i < t.size(); ++i) t[i] = r[i] - t[i];
  fine_.apply(t, z);
  for (size_t j = 0; j < z.size(); ++j) z[j] += weight_[j] * y[block_of_[j]];
}

}  // namespace soupuv::field
