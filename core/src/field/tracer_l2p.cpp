// Field of a local expansion for the tracer (see tracer_l2p.h).
#include "tracer_l2p.h"

#include <map>

namespace soupuv::field::tracer {

FieldExpansion::FieldExpansion(const TaylorBasis& basis) {
  const int p = basis.order();
  n_ = p >= 1 ? TaylorBasis::size_for(p - 1) : 0;
  std::map<std::array<int, 3>, int> index;
  for (int b = 0; b < basis.size(); ++b) index[basis.multi_index(b)] = b;
  parent_.assign(n_, 0);
  axis_.assign(n_, 0);
  for (int c = 0; c < 3; ++c) up_[c].assign(n_, 0);
  // The basis is ordered by total degree, so its first n_ indices are the
  // monomials of degree <= p - 1 and each one's parent comes before it.
  for (int b = 0; b < n_; ++b) {
    const auto& B = basis.multi_index(b);
    for (int c = 0; c < 3; ++c) {
      auto U = B;
      ++U[c];
      up_[c][b] = index.at(U);
    }
    if (b == 0) continue;
    for (int c = 0; c < 3; ++c)
      if (B[c] > 0) {
        auto P = B;
        --P[c];
        parent_[b] = index.at(P);
        axis_[b] = c;
        break;
      }
  }
  // Keep the basis' multi-indices for from_local's factors.
  for (int c = 0; c < 3; ++c) factor_[c].assign(n_, 0.0);
  for (int b = 0; b < n_; ++b)
    for (int c = 0; c < 3; ++c) factor_[c][b] = basis.multi_index(b)[c] + 1;
}

void FieldExpansion::from_local(const double* L, double* g) const {
  // d/dx_c sum_b L_b d^b = sum_b' (b'_c + 1) L_{b' + e_c} d^b'; E = -grad.
  for (int c = 0; c < 3; ++c)
    for (int b = 0; b < n_; ++b) g[c * n_ + b] = -factor_[c][b] * L[up_[c][b]];
}

void FieldExpansion::evaluate(const double* g, Vec3 d, Vec3* E) const {
  double stack[512];
  std::vector<double> heap;
  double* w = stack;
  if (n_ > 512) {
    heap.resize(n_);
    w = heap.data();
  }
  const double dd[3] = {d.x, d.y, d.z};
  w[0] = 1;
  for (int b = 1; b < n_; ++b) w[b] = w[parent_[b]] * dd[axis_[b]];
  const double *gx = g, *gy = g + n_, *gz = g + 2 * n_;
  // Two partial sums per component: a single running sum is bound by the
  // add latency.
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0, z0 = 0, z1 = 0;
  int b = 0;
  for (; b + 2 <= n_; b += 2) {
    x0 += gx[b] * w[b];
    x1 += gx[b + 1] * w[b + 1];
    y0 += gy[b] * w[b];
    y1 += gy[b + 1] * w[b + 1];
    z0 += gz[b] * w[b];
    z1 += gz[b + 1] * w[b + 1];
  }
  for (; b < n_; ++b) {
    x0 += gx[b] * w[b];
    y0 += gy[b] * w[b];
    z0 += gz[b] * w[b];
  }
  *E += Vec3{x0 + x1, y0 + y1, z0 + z1};
}

}  // namespace soupuv::field::tracer
