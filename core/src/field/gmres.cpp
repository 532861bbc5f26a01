// Restarted right-preconditioned GMRES (modified Gram-Schmidt, Givens
// rotations); see gmres.h.
#include "gmres.h"

#include <cmath>

namespace soupuv::field {

namespace {
double dotv(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}
}  // namespace

GmresResult gmres(const LinearMap& A, const LinearMap& Minv, const std::vector<double>& b, const GmresOptions& o) {
  const size_t n = b.size();
  GmresResult out;
  out.x.assign(n, 0.0);
  const double bnorm = std::sqrt(dotv(b, b));
  if (!(bnorm > 0)) {
    out.estimate = 0;
    return out;
  }
  std::vector<double> res = b, w, z, ax;
  bool stop = false;
  while (out.iterations < o.max_iterations && !stop) {
    const double beta = std::sqrt(dotv(res, res));
    out.estimate = beta / bnorm;
    if (out.estimate <= o.rtol) break;
    std::vector<std::vector<double>> V(1, res);
    for (double& v : V[0]) v /= beta;
    std::vector<std::vector<double>> H(o.restart + 1, std::vector<double>(o.restart, 0.0));
    std::vector<double> cs(o.restart), sn(o.restart), g(o.restart + 1, 0.0);
    g[0] = beta;
    int k = 0;
    while (k < o.restart && out.iterations < o.max_iterations) {
      Minv(V[k], z);
      A(z, w);
      ++out.iterations;
      for (int i = 0; i <= k; ++i) {
        H[i][k] = dotv(w, V[i]);
        for (size_t t = 0; t < n; ++t) w[t] -= H[i][k] * V[i][t];
      }
      H[k + 1][k] = std::sqrt(dotv(w, w));
      const double hnext = H[k + 1][k];  // the Arnoldi norm, before the rotations touch it
      for (int i = 0; i < k; ++i) {
        double tmp = cs[i] * H[i][k] + sn[i] * H[i + 1][k];
        H[i + 1][k] = -sn[i] * H[i][k] + cs[i] * H[i + 1][k];
        H[i][k] = tmp;
      }
      double d = std::hypot(H[k][k], H[k + 1][k]);
      cs[k] = H[k][k] / d;
      sn[k] = H[k + 1][k] / d;
      H[k][k] = d;
      H[k + 1][k] = 0;
      g[k + 1] = -sn[k] * g[k];
      g[k] = cs[k] * g[k];
      ++k;
      out.estimate = std::fabs(g[k]) / bnorm;
      if (o.on_iteration && !o.on_iteration(out.estimate)) stop = true;
      if (stop || out.estimate <= o.rtol || !(hnext > 0)) break;
      std::vector<double> next(n);
      for (size_t t = 0; t < n; ++t) next[t] = w[t] / hnext;
      V.push_back(std::move(next));
    }
    // x += M^-1 (V y) with y from the k x k triangular system.
    std::vector<double> y(k, 0.0);
    for (int i = k - 1; i >= 0; --i) {
      double s = g[i];
      for (int j = i + 1; j < k; ++j) s -= H[i][j] * y[j];
      y[i] = s / H[i][i];
    }
    std::vector<double> u(n, 0.0);
    for (int i = 0; i < k; ++i)
      for (size_t t = 0; t < n; ++t) u[t] += y[i] * V[i][t];
    Minv(u, z);
    for (size_t t = 0; t < n; ++t) out.x[t] += z[t];
    if (stop || out.estimate <= o.rtol || out.iterations >= o.max_iterations) break;
    // Restart from the true residual of this operator (one extra mat-vec).
    A(out.x, ax);
    ++out.iterations;
    for (size_t t = 0; t < n; ++t) res[t] = b[t] - ax[t];
  }
  return out;
}

}  // namespace soupuv::field
