// solve_charges: refine, dispatch to a solver, normalise the total charge to
// 1 and verify the potential by a fresh evaluation.
#include <chrono>
#include <cmath>
#include <ctime>
#include <numeric>

#include "charge_solvers.h"
#include "collocation.h"
#include "soupuv/errors.h"

namespace soupuv::field {

int fmm_order_for_tolerance(double tolerance) {
  if (tolerance >= 1e-4) return 4;
  if (tolerance >= 1e-5) return 6;
  if (tolerance >= 1e-6) return 8;
  if (tolerance >= 1e-7) return 10;
  return 12;
}

ChargeResult solve_charges(const Soup& soup, const ChargeOptions& options_in, Progress& progress) {
  ChargeOptions options = options_in;
  if (options.fmm_order <= 0) options.fmm_order = fmm_order_for_tolerance(options.tolerance);
  auto t0 = std::chrono::steady_clock::now();
  const std::clock_t c0 = std::clock();
  if (soup.triangles.empty()) throw Error(ErrorCode::no_triangles, "no triangles to charge");
  ChargeResult r;
  Refined refined = refine_large_triangles(soup, options.refine_area_ratio);
  r.positions = std::move(refined.positions);
  r.triangles = std::move(refined.triangles);
  r.parent = std::move(refined.parent);
  r.refined_triangles = refined.split_inputs;
  r.quadrature_degree = options.quadrature_degree;
  r.fmm_order = options.fmm_order;
  r.fmm_theta = options.fmm_theta;
  SourceGeometry src = make_sources(r.positions, r.triangles, options.quadrature_degree);
  r.source_triangles = src.size();
  double total_area = 0;
  for (double a : src.area) total_area += a;
  if (!(total_area > 0)) throw Error(ErrorCode::no_triangles, "all triangles are degenerate");
  progress.update("charge", 0.0);
  std::unique_ptr<CollocationOperator> op;
  switch (options.solver) {
    case ChargeOptions::Solver::krylov: solve_krylov(src, options, progress, r, op); break;
    case ChargeOptions::Solver::robin_hood: solve_robin_hood(src, options, progress, r, op); break;
    case ChargeOptions::Solver::dense_lu: solve_dense_lu(src, options, progress, r); break;
  }
  double total = std::accumulate(r.charges.begin(), r.charges.end(), 0.0);
  if (!(std::fabs(total) > 0)) throw Error(ErrorCode::internal, "charge solve produced zero total charge");
  for (double& q : r.charges) q /= total;
  r.solve_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.solve_cpu_seconds = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
  progress.update("charge", 0.95);
  const int verify_order = options.verify_order > 0 ? options.verify_order : options.fmm_order + 2;
  r.max_rel_potential_error = verify_potential(src, r.charges, options.verify_direct_max, verify_order,
                                               options.threads, op.get(), &r.verified_by, &r.mean_potential);
  op.reset();
  r.converged = r.max_rel_potential_error <= options.tolerance;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  progress.update("charge", 1.0);
  return r;
}

}  // namespace soupuv::field
