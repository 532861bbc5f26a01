// Restarted GMRES with right preconditioning for A x = b, matrix-free.
//
//   GmresResult r = gmres(apply_A, apply_Minv, b, GmresOptions{.rtol = 1e-4});
//
// Inputs: apply_A(v, out) computes out = A v; apply_Minv(v, out) computes
// out = M^-1 v (right preconditioner: GMRES works on A M^-1 y = b, x = M^-1 y);
// b. Output: x with ||b - A x||_2 <= rtol * ||b||_2 by GMRES's own (recursive)
// residual estimate, or with max_i |b - A x|_i <= max_norm_target, whichever
// comes first; the mat-vec count, and the estimate after every iteration.
// The max-norm test forms the residual from the Arnoldi relation
// (b - A x = V_{k+1} (beta e1 - H y): O(k n), no mat-vec), and only once the
// 2-norm estimate says the RMS is below the target. The caller checks the
// true residual: with an approximate A (a cheap FMM) the estimate is only as
// good as A.
#pragma once

#include <functional>
#include <vector>

namespace soupuv::field {

using LinearMap = std::function<void(const std::vector<double>&, std::vector<double>&)>;

struct GmresOptions {
  double rtol = 1e-6;
  // Absolute max-norm target on b - A x (0: off). A charge solve is judged
  // by its worst collocation point, and on noisy soups the max sits 20-100x
  // above the RMS: stopping on the 2-norm either stops early or iterates
  // far past what the max needs.
  double max_norm_target = 0;
  int restart = 40;
  int max_iterations = 300;
  // A restart cycle that leaves more than this share of its starting
  // residual has stalled: restarting builds the same Krylov space again.
  // A preconditioned charge solve that converges gains orders of magnitude
  // per cycle; one on coplanar overlapping fragments (bracket-exact of the
  // corpus) gained 10-30 % per 60-vector cycle without converging
  // (docs/tuning.md). 1: never.
  double stall_ratio = 0.5;
  // The same test inside a cycle, over its last stall_window iterations
  // (at the rate the cycle test asks for, stall_ratio^(window / restart)):
  // a cycle that has stalled stops there instead of running its remaining
  // vectors for nothing (bracket-exact's second cycle was flat from its
  // first vector). 0: only whole cycles are tested.
  int stall_window = 0;
  // The budget test: after at least reach_window iterations of a cycle, a
  // solve whose residual estimate, falling at the rate of its last
  // reach_window iterations, would still be above its goal when
  // max_iterations run out stops there (out_of_reach) instead of spending the
  // rest of its budget. The goal is the larger of rtol and the RMS level at
  // which max_norm_target could be met. A solve on its way down keeps going;
  // one on a plateau (bracket's and bracket-exact's coplanar slivers: from
  // their 2nd to 30th mat-vec the estimate fell 2x) stops within a window.
  // 0: off.
  int reach_window = 0;
  // Called after every iteration with the relative residual estimate; return
  // false to stop (time limit, cancel).
  std::function<bool(double)> on_iteration;
};

struct GmresResult {
  std::vector<double> x;
  int iterations = 0;              // mat-vecs with A
  double estimate = 1;             // last relative residual estimate
  double max_norm = -1;            // last max-norm residual formed (-1: never formed)
  bool stalled = false;            // stopped because a restart cycle stalled (stall_ratio, stall_window)
  bool out_of_reach = false;       // stopped by the budget test (reach_window)
};

GmresResult gmres(const LinearMap& A, const LinearMap& Minv, const std::vector<double>& b, const GmresOptions& o);

}  // namespace soupuv::field
