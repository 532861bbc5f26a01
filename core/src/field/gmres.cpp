// Restarted right-preconditioned GMRES (modified Gram-Schmidt, Givens
// rotations); see gmres.h.
#include "gmres.h"

#include <algorithm>
#include <cmath>

namespace soupuv::field {

namespace {
double dotv(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}
// y with R y = g[0..k) for the rotated (upper triangular) Hessenberg matrix.
std::vector<double> solve_upper(const std::vector<std::vector<double>>& R, const std::vector<double>& g, int k) {
  std::vector<double> y(k, 0.0);
  for (int i = k - 1; i >= 0; --i) {
    double s = g[i];
    for (int j = i + 1; j < k; ++j) s -= R[i][j] * y[j];
    y[i] = s / R[i][i];
  }
  return y;
}

// max_t |V_{k+1} (beta e1 - Hraw y)|_t: the residual of the restart's
// right-hand side after the update M^-1 V_k y, without a mat-vec.
double residual_max_norm(const std::vector<std::vector<double>>& V, const std::vector<std::vector<double>>& Hraw,
                         const std::vector<double>& y, double beta, int k) {
  std::vector<double> c(k + 1, 0.0);
  c[0] = beta;
  for (int i = 0; i <= k; ++i)
    for (int j = 0; j < k; ++j) c[i] -= Hraw[i][j] * y[j];
  const size_t n = V[0].size();
  std::vector<double> r(n, 0.0);
  for (int i = 0; i <= k; ++i)
    for (size_t t = 0; t < n; ++t) r[t] += c[i] * V[i][t];
  double worst = 0;
  for (double v : r) worst = std::max(worst, std::fabs(v));
  return worst;
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
  // The budget test's goal, in the estimate's unit (relative to ||b||): the
  // max norm can only be met once the RMS is below it.
  const double goal =
      std::max(o.rtol, o.max_norm_target > 0 ? o.max_norm_target * std::sqrt(static_cast<double>(n)) / bnorm : 0.0);
  while (out.iterations < o.max_iterations && !stop) {
    const double beta = std::sqrt(dotv(res, res));
    out.estimate = beta / bnorm;
    if (out.estimate <= o.rtol) break;
    if (o.max_norm_target > 0) {
      out.max_norm = 0;
      for (double v : res) out.max_norm = std::max(out.max_norm, std::fabs(v));
      if (out.max_norm <= o.max_norm_target) break;
    }
    std::vector<std::vector<double>> V(1, res);
    for (double& v : V[0]) v /= beta;
    std::vector<std::vector<double>> H(o.restart + 1, std::vector<double>(o.restart, 0.0));
    // H before the Givens rotations: A M^-1 V_k = V_{k+1} Hraw.
    std::vector<std::vector<double>> Hraw(o.restart + 1, std::vector<double>(o.restart, 0.0));
    std::vector<double> cs(o.restart), sn(o.restart), g(o.restart + 1, 0.0);
    g[0] = beta;
    // The estimate after each of this cycle's iterations, for the in-cycle
    // stall test.
    std::vector<double> cycle_estimate{beta / bnorm};
    const double window_ratio =
        o.stall_window > 0 ? std::pow(o.stall_ratio, double(o.stall_window) / o.restart) : 0;
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
      for (int i = 0; i <= k + 1; ++i) Hraw[i][k] = H[i][k];
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
      cycle_estimate.push_back(out.estimate);
      if (o.stall_window > 0 && k >= o.stall_window && k < o.restart &&
          out.estimate > window_ratio * cycle_estimate[k - o.stall_window]) {
        out.stalled = true;
        break;
      }
      if (o.reach_window > 0 && k >= o.reach_window && goal > 0 && out.estimate > goal) {
        const double rate = out.estimate / cycle_estimate[k - o.reach_window];  // per window
        const int left = o.max_iterations - out.iterations;
        if (!(rate < 1) || o.reach_window * std::log(goal / out.estimate) / std::log(rate) > left) {
          out.out_of_reach = true;
          break;
        }
      }
      std::vector<double> next(n);
      for (size_t t = 0; t < n; ++t) next[t] = w[t] / hnext;
      V.push_back(std::move(next));
      // max |r| >= RMS: form the residual only once the RMS could be below.
      if (o.max_norm_target > 0 && std::fabs(g[k]) <= o.max_norm_target * std::sqrt(static_cast<double>(n))) {
        out.max_norm = residual_max_norm(V, Hraw, solve_upper(H, g, k), beta, k);
        if (out.max_norm <= o.max_norm_target) break;
      }
    }
    // x += M^-1 (V y) with y from the k x k triangular system.
    const std::vector<double> y = solve_upper(H, g, k);
    std::vector<double> u(n, 0.0);
    for (int i = 0; i < k; ++i)
      for (size_t t = 0; t < n; ++t) u[t] += y[i] * V[i][t];
    Minv(u, z);
    for (size_t t = 0; t < n; ++t) out.x[t] += z[t];
    if (stop || out.stalled || out.out_of_reach || out.estimate <= o.rtol || out.iterations >= o.max_iterations)
      break;
    if (o.max_norm_target > 0 && out.max_norm >= 0 && out.max_norm <= o.max_norm_target) break;
    if (k == o.restart && out.estimate > o.stall_ratio * (beta / bnorm)) {
      out.stalled = true;
      break;
    }
    // Restart from the true residual of this operator (one extra mat-vec).
    A(out.x, ax);
    ++out.iterations;
    for (size_t t = 0; t < n; ++t) res[t] = b[t] - ax[t];
  }
  return out;
}

}  // namespace soupuv::field
