// solve_charges: refine, dispatch to a solver, normalise the total charge to
// 1 and verify the potential by a fresh evaluation.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <ctime>
#include <map>
#include <numeric>
#include <sstream>
#include <tuple>

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
  // Exact duplicates (the same three corners, e.g. a doubled part) make two
  // columns of A equal: the collocation system is singular and every solver
  // failed ("zero total charge"). Charge one copy; the copies share its charge.
  std::vector<uint32_t> copy_of(r.triangles.size());
  std::vector<Tri> distinct;
  {
    std::map<std::array<double, 9>, uint32_t> seen;
    for (size_t t = 0; t < r.triangles.size(); ++t) {
      std::array<Vec3, 3> c = {r.positions[r.triangles[t][0]], r.positions[r.triangles[t][1]],
                               r.positions[r.triangles[t][2]]};
      std::sort(c.begin(), c.end(), [](Vec3 a, Vec3 b) { return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z); });
      const std::array<double, 9> key = {c[0].x, c[0].y, c[0].z, c[1].x, c[1].y, c[1].z, c[2].x, c[2].y, c[2].z};
      auto [it, fresh] = seen.emplace(key, static_cast<uint32_t>(distinct.size()));
      if (fresh) distinct.push_back(r.triangles[t]);
      copy_of[t] = it->second;
    }
  }
  SourceGeometry src = make_sources(r.positions, distinct, options.quadrature_degree);
  r.source_triangles = r.triangles.size();
  double total_area = 0;
  for (double a : src.area) total_area += a;
  if (!(total_area > 0)) throw Error(ErrorCode::no_triangles, "all triangles are degenerate");
  progress.update("charge", 0.0);
  std::unique_ptr<CollocationOperator> op;
  switch (options.solver) {
    case ChargeOptions::Solver::krylov: {
      solve_krylov(src, options, progress, r, op);
      // Exact CAD exports can hold coplanar, overlapping (not identical)
      // triangles; their near-equal columns can break the Krylov solve
      // (bracket-exact of the corpus: a zero or non-finite total). Robin
      // hood's positive iteration survives them: retry with it and say so.
      auto failed = [&] {
        double sum = 0;
        for (double q : r.charges) sum += q;
        return !std::isfinite(sum) || !(std::fabs(sum) > 0);
      };
      auto restart = [&](const char* how) {
        r.warnings.push_back(std::string("the Krylov charge solve failed (total charge not finite or zero); ") + how);
        r.history.clear();
        r.history_seconds.clear();
        r.history_iterations.clear();
        op.reset();
      };
      if (failed()) {
        // First without the coarse correction and the blocks' overlap (a
        // near-singular coarse or overlapped block is the likely cause).
        restart("solved again with plain block-Jacobi");
        ChargeOptions plain = options;
        plain.krylov_coarse_correction = false;
        plain.krylov_overlap_ratio = 0;
        solve_krylov(src, plain, progress, r, op);
      }
      if (failed()) {
        restart("solved again by robin hood");
        solve_robin_hood(src, options, progress, r, op);
      }
      break;
    }
    case ChargeOptions::Solver::robin_hood: solve_robin_hood(src, options, progress, r, op); break;
    case ChargeOptions::Solver::dense_lu: solve_dense_lu(src, options, progress, r); break;
  }
  if (distinct.size() < r.triangles.size()) {
    std::vector<int> copies(distinct.size(), 0);
    for (uint32_t d : copy_of) ++copies[d];
    std::vector<double> all(r.triangles.size());
    for (size_t t = 0; t < all.size(); ++t) all[t] = r.charges[copy_of[t]] / copies[copy_of[t]];
    r.charges.swap(all);
  }
  double total = std::accumulate(r.charges.begin(), r.charges.end(), 0.0);
  if (!(std::fabs(total) > 0)) throw Error(ErrorCode::internal, "charge solve produced zero total charge");
  for (double& q : r.charges) q /= total;
  r.solve_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.solve_cpu_seconds = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
  progress.update("charge", 0.95);
  const int verify_order = options.verify_order > 0 ? options.verify_order : options.fmm_order + 2;
  // The verification charges the distinct triangles (each with its copies' sum).
  std::vector<double> distinct_charges(distinct.size(), 0.0);
  for (size_t t = 0; t < r.charges.size(); ++t) distinct_charges[copy_of[t]] += r.charges[t];
  r.max_rel_potential_error = verify_potential(src, distinct_charges, options.verify_direct_max, verify_order,
                                               options.threads, op.get(), &r.verified_by, &r.mean_potential);
  op.reset();
  r.converged = r.max_rel_potential_error <= options.tolerance;
  if (!r.converged) {
    // Say why: a solve that met its own target against its FMM leaves that
    // FMM's truncation error, which the higher-order verification sees.
    const double target = options.tolerance / (r.solver == "krylov" ? 5 : r.solver.rfind("robin-hood", 0) == 0 ? 2 : 1);
    const double reached = r.history.empty() ? NAN : r.history.back();
    std::ostringstream why;
    why << "charge not converged: potential error " << r.max_rel_potential_error << " (verified by "
        << r.verified_by << ") above the tolerance " << options.tolerance << "; ";
    if (reached <= target)
      why << "the solver met its own target (" << reached << " <= " << target << " against the order-"
          << options.fmm_order << " FMM), so the rest is that FMM's truncation error";
    else if (const int budget = options.max_iterations > 0 ? options.max_iterations : kKrylovIterationBudget;
             r.solver == "krylov" && r.iterations >= budget)
      why << "the solver stopped at " << reached << " (its target " << target << ") after its budget of " << budget
          << " mat-vecs (--charge-iterations; a slow solve gave the same maps past it on the corpus)";
    else
      why << "the solver stopped at " << reached << " (its target " << target << ")";
    r.warnings.push_back(why.str());
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  progress.update("charge", 1.0);
  return r;
}

}  // namespace soupuv::field
