// Krylov charge solve: defect correction around GMRES (gmres.h).
//
//   x = area / mean(A_cheap area), r = 1 - A_cheap x
//   repeat: d = GMRES(A_cheap M^-1, r): first to a loose 2-norm tolerance,
//               later until max |r - A_cheap d| <= tolerance / 10;  x += d;
//           r = 1 - A_full x   (one accurate mat-vec)
//   until max |r| <= tolerance / 5
//
// A_cheap and A_full share the tree and the precomputed near matrix and
// differ only in the FMM order of the far field (collocation.h), so the inner
// iterations cost a low-order FMM while the answer has the full operator's
// accuracy: each outer step shrinks the residual by about the inner
// tolerance or the cheap far field's relative error, whichever is larger
// (measured ~1e-4), and two or three outer steps reach 1e-7. M is two-level:
// a coarse correction over compact source cells of up to krylov_block_size
// triangles (charge_coarse.h: the smooth modes, which made the iterations
// grow with n), then block-Jacobi over the same cells, each block overlapping
// its strongly coupled neighbours (collocation.h: the neighbour pairs split
// by block borders, where the max residual sat). Measured (loaded machine):
// 9-10 mat-vecs from 4,800 to 105,800 triangles, clean or noisy; block-Jacobi
// alone took 19-41 clean and 67 on the noisy 100k soup.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "charge_coarse.h"
#include "charge_solvers.h"
#include "collocation.h"
#include "gmres.h"

namespace soupuv::field {

void solve_krylov(const SourceGeometry& src, const ChargeOptions& o, Progress& progress, ChargeResult& r,
                  std::unique_ptr<CollocationOperator>& op) {
  auto t0 = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  const size_t n = src.size();
  FmmOptions fo;
  fo.order = o.fmm_order;
  fo.theta = o.fmm_theta;
  const int threads =
      o.threads > 0 ? o.threads : (n < o.krylov_parallel_min ? 1 : omp_get_max_threads());
  fo.threads = threads;
  fo.leaf_size = o.krylov_leaf_size;
  const int cheap_order = std::min(o.krylov_inner_order, o.fmm_order);
  op = std::make_unique<CollocationOperator>(src, fo, cheap_order < o.fmm_order ? cheap_order : 0);
  CollocationOperator& A = *op;
  const bool split = cheap_order < o.fmm_order;
  const auto cheap = split ? CollocationOperator::Accuracy::cheap : CollocationOperator::Accuracy::full;
  const auto blocks = A.fmm().source_blocks(o.krylov_block_size);
  LeafBlockPreconditioner B(A, blocks, threads, o.krylov_overlap_ratio);
  std::unique_ptr<CoarseCorrection> C;
  if (o.krylov_coarse_correction && blocks.size() > 1) C = std::make_unique<CoarseCorrection>(A, src, blocks, B, threads);
  r.setup_seconds = elapsed();
  r.near_entries = A.near_entries();
  r.solver = "krylov";
  const int max_it = o.max_iterations > 0 ? o.max_iterations : kKrylovIterationBudget;
  // max |1 - A q| bounds the deviation of A q from its mean by twice that.
  const double target = o.tolerance / 5;
  // Initial guess: charge proportional to area (exact for a sphere), scaled
  // so that the mean potential is 1; its residual by the cheap operator (the
  // first outer step replaces it by the full one).
  std::vector<double> x(n), res(n), ax;
  for (size_t t = 0; t < n; ++t) x[t] = src.area[t];
  A.apply(x, ax, cheap);
  ++r.cheap_matvecs;
  double mean = 0;
  for (double v : ax) mean += v;
  mean /= static_cast<double>(n);
  if (!(mean > 0)) mean = 1;
  for (size_t t = 0; t < n; ++t) {
    x[t] /= mean;
    res[t] = 1.0 - ax[t] / mean;
  }
  const double bnorm = std::sqrt(static_cast<double>(n));
  int total = 1;
  bool out_of_time = false;
  double last_rmax = INFINITY;
  for (int outer = 0; outer < 20 && total < max_it && !out_of_time; ++outer) {
    double rmax = 0, r2 = 0;
    for (double v : res) {
      rmax = std::max(rmax, std::fabs(v));
      r2 += v * v;
    }
    const double rscale = std::sqrt(r2) / bnorm;  // GMRES's relative estimates are in this unit
    r.history.push_back(rmax);
    r.history_seconds.push_back(elapsed());
    r.history_iterations.push_back(total);
    if (rmax <= target) break;
    // An outer step that does not halve the max residual is stagnating
    // (the cheap far field cannot resolve what is left): stop rather than
    // pay a full mat-vec per step for nothing; the verification reports it.
    if (outer >= 2 && rmax > 0.5 * last_rmax) {
      r.warnings.push_back("krylov: defect correction stagnated at max residual " + std::to_string(rmax));
      break;
    }
    last_rmax = rmax;
    GmresOptions go;
    go.restart = 60;  // a restart forgets the slow modes; 60 vectors of n doubles are cheap next to the near matrix
    go.stall_window = 20;  // a third of a cycle (docs/tuning.md, "GMRES stalls inside a cycle")
    go.reach_window = 4;   // docs/tuning.md, "A solve that cannot reach its target in its budget"
    if (split && outer == 0) {
      // The cheap far field is only ~5e-5 accurate (p = 4): iterate to about
      // that, and let the full mat-vec say what is left.
      go.rtol = o.krylov_inner_tolerance;
      go.max_norm_target = 0.5 * target;
    } else {
      // Bring the MAX residual below the target directly (GMRES's 2-norm
      // test would either stop with a few rows far above it -- on noisy
      // soups the max is 20-100x the RMS -- or iterate far past it). With
      // a split, the correction d is ~1e-4 of x, so the cheap/full
      // difference adds only ~1e-4 x 5e-5 of it: half the target is enough.
      go.rtol = 0;
      go.max_norm_target = split ? 0.5 * target : 0.9 * target;
    }
    go.max_iterations = max_it - total;
    go.on_iteration = [&](double est) {
      ++total;
      r.history.push_back(est * rscale);
      r.history_seconds.push_back(elapsed());
      r.history_iterations.push_back(total);
      progress.update("charge", std::min(0.9, std::log(est * rscale) / std::log(target) * 0.9));
      if (o.max_seconds > 0 && elapsed() > o.max_seconds) out_of_time = true;
      return !out_of_time;
    };
    LinearMap apply_cheap = [&](const std::vector<double>& v, std::vector<double>& out) { A.apply(v, out, cheap); };
    LinearMap apply_M = [&](const std::vector<double>& v, std::vector<double>& out) {
      if (C)
        C->apply(v, out);
      else
        B.apply(v, out);
    };
    GmresResult d = gmres(apply_cheap, apply_M, res, go);
    r.cheap_matvecs += d.iterations;
    total = r.cheap_matvecs + r.full_matvecs;
    for (size_t t = 0; t < n; ++t) x[t] += d.x[t];
    A.apply(x, ax, CollocationOperator::Accuracy::full);
    ++r.full_matvecs;
    ++total;
    for (size_t t = 0; t < n; ++t) res[t] = 1.0 - ax[t];
    if (d.out_of_reach) {
      r.warnings.push_back("krylov: GMRES stopped after " + std::to_string(total) +
                           " mat-vecs: at the rate of its last " + std::to_string(go.reach_window) +
                           " iterations it would not reach its target within its budget of " +
                           std::to_string(max_it) + " (--charge-iterations)");
      break;
    }
    if (d.stalled) {
      // A further outer step restarts the same stalled iteration.
      r.warnings.push_back("krylov: GMRES stalled (its residual fell by less than " +
                           std::to_string(int(std::round(100 * (1 - go.stall_ratio)))) + " % per " +
                           std::to_string(go.restart) + " iterations)");
      break;
    }
  }
  r.iterations = total;
  r.charges = std::move(x);
}

}  // namespace soupuv::field
