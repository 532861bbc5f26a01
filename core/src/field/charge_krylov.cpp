// Restarted GMRES on A q = 1 with right block-Jacobi preconditioning
// (A M^-1 y = 1, q = M^-1 y) and the FMM mat-vec. Stops when the relative
// residual drops below tolerance / 10 (the max-norm deviation is then
// verified independently by the caller).
#include <omp.h>

#include <chrono>
#include <cmath>

#include "charge_solvers.h"
#include "collocation.h"

namespace soupuv::field {

namespace {
double dotv(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}
}  // namespace

void solve_krylov(const SourceGeometry& src, const ChargeOptions& o, Progress& progress, ChargeResult& r) {
  auto t0 = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  const size_t n = src.size();
  FmmOptions fo;
  fo.order = o.fmm_order;
  fo.theta = o.fmm_theta;
  fo.threads = o.threads;
  CollocationOperator A(src, fo);
  LeafBlockPreconditioner M(src, A.fmm().source_leaf_triangles(), o.threads);
  r.solver = "krylov";
  const int restart = 40;
  const int max_it = o.max_iterations > 0 ? o.max_iterations : 300;
  const double target = o.tolerance / 30;
  std::vector<double> x(n, 0.0), b(n, 1.0), w, z, ax;
  const double bnorm = std::sqrt(static_cast<double>(n));
  int total = 0;
  std::vector<double> res(n, 1.0);  // residual for x = 0
  while (total < max_it) {
    double beta = std::sqrt(dotv(res, res));
    if (beta / bnorm < target) break;
    std::vector<std::vector<double>> V(1, res);
    for (double& v : V[0]) v /= beta;
    std::vector<std::vector<double>> H(restart + 1, std::vector<double>(restart, 0.0));
    std::vector<double> cs(restart), sn(restart), g(restart + 1, 0.0);
    g[0] = beta;
    int k = 0;
    for (; k < restart && total < max_it; ++k) {
      M.apply(V[k], z);
      A.apply(z, w);
      ++total;
      for (int i = 0; i <= k; ++i) {  // modified Gram-Schmidt
        H[i][k] = dotv(w, V[i]);
        for (size_t t = 0; t < n; ++t) w[t] -= H[i][k] * V[i][t];
      }
      H[k + 1][k] = std::sqrt(dotv(w, w));
      const double hnext = H[k + 1][k];  // the Arnoldi norm, before the rotations touch it
      for (int i = 0; i < k; ++i) {  // apply previous Givens rotations
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
      double rel = std::fabs(g[k + 1]) / bnorm;
      r.history.push_back(rel);
      r.history_seconds.push_back(elapsed());
      r.history_iterations.push_back(total);
      progress.update("charge", std::min(0.9, std::log(rel) / std::log(target) * 0.9));
      if (rel < target || (o.max_seconds > 0 && elapsed() > o.max_seconds)) {
        ++k;
        break;
      }
      std::vector<double> next(n);
      for (size_t t = 0; t < n; ++t) next[t] = w[t] / hnext;
      V.push_back(std::move(next));
    }
    // Solve the small triangular system and update x += M^-1 (V y).
    std::vector<double> y(k, 0.0);
    for (int i = k - 1; i >= 0; --i) {
      double s = g[i];
      for (int j = i + 1; j < k; ++j) s -= H[i][j] * y[j];
      y[i] = s / H[i][i];
    }
    std::vector<double> u(n, 0.0);
    for (int i = 0; i < k; ++i)
      for (size_t t = 0; t < n; ++t) u[t] += y[i] * V[i][t];
    M.apply(u, z);
    for (size_t t = 0; t < n; ++t) x[t] += z[t];
    // True residual for the restart (one extra mat-vec per cycle).
    A.apply(x, ax);
    for (size_t t = 0; t < n; ++t) res[t] = b[t] - ax[t];
    if (o.max_seconds > 0 && elapsed() > o.max_seconds) break;
    if (!r.history.empty() && r.history.back() < target) {
      double true_rel = std::sqrt(dotv(res, res)) / bnorm;
      if (true_rel < target) break;
    }
  }
  r.iterations = total;
  r.charges = std::move(x);
}

}  // namespace soupuv::field
