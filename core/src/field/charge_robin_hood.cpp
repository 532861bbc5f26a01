// Robin hood iteration (paper §7.5, after [30]): start from charges
// proportional to area, compute the potentials once (FMM or direct), then
// repeatedly move the charge eq. 6 from the triangle of highest potential to
// the one of lowest, updating every potential by eq. 8 in O(n) (columns of A
// recomputed, never stored). Total charge is conserved exactly; the tracked
// potentials inherit the initialisation's error, which the caller's fresh
// verification exposes.
#include <omp.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "charge_solvers.h"
#include "collocation.h"
#include "soupuv/field/direct.h"

namespace soupuv::field {

void solve_robin_hood(const SourceGeometry& src, const ChargeOptions& o, Progress& progress, ChargeResult& r,
                      std::unique_ptr<CollocationOperator>& op) {
  auto t0 = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  const long n = static_cast<long>(src.size());
  // One transfer updates n potentials: below ~20k triangles a parallel region
  // per transfer costs more than it saves (measured on a loaded 2-core machine).
  const int nth = o.threads > 0 ? o.threads : (n > 20000 ? omp_get_max_threads() : 1);
  double total_area = 0;
  for (double a : src.area) total_area += a;
  std::vector<double> q(n), phi;
  for (long i = 0; i < n; ++i) q[i] = src.area[i] / total_area;
  if (o.direct_initialization) {
    direct_sum(src, q, src.centroid, &phi, nullptr, o.threads);
    r.solver = "robin-hood-direct-init";
  } else {
    FmmOptions fo;
    fo.order = o.fmm_order;
    fo.theta = o.fmm_theta;
    fo.threads = o.threads;
    op = std::make_unique<CollocationOperator>(src, fo);
    op->apply(q, phi);
    r.solver = "robin-hood";
  }
  const long max_it = o.max_iterations > 0 ? o.max_iterations : 200L * n;
  long imax = 0, imin = 0;
  double mean = 0;
  for (long i = 0; i < n; ++i) {
    mean += phi[i];
    if (phi[i] > phi[imax]) imax = i;
    if (phi[i] < phi[imin]) imin = i;
  }
  mean /= n;
  long it = 0;
  long next_record = 1;
  for (; it < max_it; ++it) {
    double dev = (phi[imax] - phi[imin]) / mean;
    const bool done = dev <= o.tolerance / 2 || imax == imin;
    // History on a geometric schedule plus the last transfer. (The schedule
    // used to advance on every transfer below the tolerance as well, and
    // overflowed a long there: UBSan.)
    const bool scheduled = it == next_record - 1;
    if (scheduled || done) {
      r.history.push_back(dev);
      r.history_seconds.push_back(elapsed());
      r.history_iterations.push_back(static_cast<int>(it));
      if (scheduled) next_record = next_record * 5 / 4 + 1;
      progress.update("charge", std::min(0.9, std::log(dev) / std::log(o.tolerance) * 0.9));
    }
    if (done) break;
    if (o.max_seconds > 0 && (it & 63) == 0 && elapsed() > o.max_seconds) break;
    const long m = imax, k = imin;
    const Vec3 cm = src.centroid[m], ck = src.centroid[k];
    double denom = unit_potential(src, m, cm) + unit_potential(src, k, ck) - unit_potential(src, k, cm) -
                   unit_potential(src, m, ck);
    double dq = (phi[m] - phi[k]) / denom;
    q[m] -= dq;
    q[k] += dq;
    // eq. 8, fused with the search for the next pair
    double best_hi = -std::numeric_limits<double>::infinity(), best_lo = std::numeric_limits<double>::infinity();
    long hi = 0, lo = 0;
#pragma omp parallel num_threads(nth)
    {
      double my_hi = -std::numeric_limits<double>::infinity(), my_lo = std::numeric_limits<double>::infinity();
      long my_hi_i = 0, my_lo_i = 0;
#pragma omp for schedule(static)
      for (long i = 0; i < n; ++i) {
        const Vec3 c = src.centroid[i];
        phi[i] += dq * (unit_potential(src, k, c) - unit_potential(src, m, c));
        if (phi[i] > my_hi) { my_hi = phi[i]; my_hi_i = i; }
        if (phi[i] < my_lo) { my_lo = phi[i]; my_lo_i = i; }
      }
#pragma omp critical
      {
        if (my_hi > best_hi) { best_hi = my_hi; hi = my_hi_i; }
        if (my_lo < best_lo) { best_lo = my_lo; lo = my_lo_i; }
      }
    }
    imax = hi;
    imin = lo;
    // mean potential changes by dq * (column sums difference); keep it exact enough
    if ((it & 1023) == 1023) {
      mean = 0;
      for (long i = 0; i < n; ++i) mean += phi[i];
      mean /= n;
    }
  }
  r.iterations = static_cast<int>(it);
  r.charges = std::move(q);
}

}  // namespace soupuv::field
