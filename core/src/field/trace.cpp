// Field-line tracing (paper §7.6): one line per seed, started at
// v + eps * n on the side where |E| is larger, stepped along E/|E| (eq. 10)
// by explicit Euler or the midpoint method. The step shrinks near the
// surface to half the distance to the nearest closed-form triangle (never
// below eps), so a line cannot jump through a nearby face; lines stop outside
// the stop sphere, at the step limit, or where |E| vanishes. The FMM over
// the sources is built once; each step only evaluates it at the particle.
#include <omp.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>

#include "soupuv/errors.h"
#include "soupuv/field/field.h"
#include "soupuv/field/fmm.h"
#include "soupuv/field/sources.h"
#include "soupuv/field/triangle_integrals.h"

namespace soupuv::field {

std::vector<TraceSeed> corner_seeds(const Soup& soup) {
  std::vector<TraceSeed> seeds;
  seeds.reserve(soup.triangles.size() * 3);
  for (size_t t = 0; t < soup.triangles.size(); ++t) {
    Vec3 n = triangle_normal(soup, t);
    Vec3 g = (soup.corner(t, 0) + soup.corner(t, 1) + soup.corner(t, 2)) / 3.0;
    for (int k = 0; k < 3; ++k)
      seeds.push_back({soup.corner(t, k), n, 0, static_cast<uint32_t>(t * 3 + k), g, true});
  }
  return seeds;
}

FieldLines trace_field_lines(const ChargeResult& charges, const std::vector<TraceSeed>& seeds,
                             const TraceOptions& options, Progress& progress, TraceStats* stats) {
  using Clock = std::chrono::steady_clock;
  auto t0 = Clock::now();
  if (charges.charges.size() != charges.triangles.size())
    throw Error(ErrorCode::invalid_input, "trace: charges do not match the source triangles");
  SourceGeometry src = make_sources(charges.positions, charges.triangles, charges.quadrature_degree);
  Box3 box;
  double edge_sum = 0;
  for (size_t j = 0; j < src.size(); ++j) {
    box.add(src.a[j]); box.add(src.b[j]); box.add(src.c[j]);
    edge_sum += norm(src.b[j] - src.a[j]) + norm(src.c[j] - src.b[j]) + norm(src.a[j] - src.c[j]);
  }
  const Vec3 center = box.center();
  const double diag = box.diagonal();
  const double step = options.step > 0 ? options.step : 0.02 * diag;
  const double eps = options.start_offset > 0 ? options.start_offset : 1e-3 * edge_sum / (3.0 * src.size());
  const double stop_radius = options.stop_radius > 0 ? options.stop_radius : diag;  // twice the half diagonal
  const double stalled_field = 1e-9 / (diag * diag);  // total charge is 1

  Box3 region;
  region.add(center - Vec3{stop_radius, stop_radius, stop_radius});
  region.add(center + Vec3{stop_radius, stop_radius, stop_radius});
  FmmOptions fo;
  fo.order = options.fmm_order;
  fo.theta = options.fmm_theta;
  fo.threads = options.threads;
  fo.leaf_size = options.fmm_leaf_size;
  std::unique_ptr<Fmm> fmm;
  if (!options.direct) {
    fmm = std::make_unique<Fmm>(src, fo, region);
    fmm->set_charges(charges.charges);
  }
  // The evaluator a step calls: the FMM, or direct summation over every source.
  auto field_at = [&](Vec3 x, Vec3* E, double* nearest) {
    if (!options.direct) {
      fmm->evaluate(x, nullptr, E, nearest);
      return;
    }
    Vec3 e{0, 0, 0};
    double best = std::numeric_limits<double>::infinity();
    for (size_t j = 0; j < src.size(); ++j) {
      Vec3 ej{0, 0, 0};
      unit_potential_field(src, j, x, nullptr, &ej);
      e += charges.charges[j] * ej;
      if (nearest && src.is_near(j, x))
        best = std::min(best, point_triangle_distance(src.a[j], src.b[j], src.c[j], x));
    }
    *E += e;
    if (nearest) *nearest = best;
  };
  double build_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  progress.update("trace", 0.05);

  const long n = static_cast<long>(seeds.size());
  std::vector<std::vector<Vec3>> lines(n);
  std::vector<LineEnd> ends(n, LineEnd::step_limit);
  const int nth = options.threads > 0 ? options.threads : omp_get_max_threads();
  size_t evaluations = 0, steps_total = 0;
  const bool midpoint = options.integrator == TraceOptions::Integrator::midpoint;
  // An exception must not leave an OpenMP region: a cancel is noted and
  // rethrown after the loop.
  std::atomic<bool> canceled{false};
#pragma omp parallel for num_threads(nth) schedule(dynamic, 64) reduction(+ : evaluations, steps_total)
  for (long s = 0; s < n; ++s) {
    if (canceled.load(std::memory_order_relaxed)) continue;
    const TraceSeed& seed = seeds[s];
    Vec3 nrm = normalized(seed.normal);
    if (norm2(nrm) == 0) nrm = normalized(seed.position - center);
    if (norm2(nrm) == 0) nrm = {0, 0, 1};
    int side = seed.side;
    Vec3 E_plus, E_minus;
    if (side == 0) {
      Vec3 base = seed.position;
      if (seed.has_interior) base = base + 0.05 * (seed.interior - seed.position);
      field_at(base + eps * nrm, &E_plus, nullptr);
      field_at(base - eps * nrm, &E_minus, nullptr);
      evaluations += 2;
      side = norm2(E_plus) >= norm2(E_minus) ? 1 : -1;
    }
    std::vector<Vec3>& line = lines[s];
    line.push_back(seed.position);
    Vec3 x = seed.position + (side * eps) * nrm;
    line.push_back(x);
    LineEnd end = LineEnd::step_limit;
    for (int k = 0; k < options.max_steps; ++k) {
      Vec3 E{0, 0, 0};
      double nearest = std::numeric_limits<double>::infinity();
      field_at(x, &E, &nearest);
      ++evaluations;
      double e = norm(E);
      if (!(e > stalled_field)) {
        end = LineEnd::stalled;
        break;
      }
      double h = options.adaptive_step ? std::min(step, std::max(eps, 0.5 * nearest)) : step;
      if (midpoint) {
        Vec3 xm = x + (0.5 * h / e) * E;
        Vec3 Em{0, 0, 0};
        field_at(xm, &Em, nullptr);
        ++evaluations;
        double em = norm(Em);
        if (!(em > stalled_field)) {
          end = LineEnd::stalled;
          break;
        }
        x = x + (h / em) * Em;
      } else {
        x = x + (h / e) * E;
      }
      ++steps_total;
      if (options.keep_points) line.push_back(x);
      if (norm(x - center) > stop_radius) {
        end = LineEnd::escaped;
        break;
      }
    }
    if (!options.keep_points) line.push_back(x);
    ends[s] = end;
    if ((s & 1023) == 0 && omp_get_thread_num() == 0) {
      try {
        progress.update("trace", 0.05 + 0.9 * s / double(n));
      } catch (const Error&) {
        canceled = true;
      }
    }
  }
  if (canceled) throw Error(ErrorCode::canceled, "field-line tracing canceled");
  FieldLines out;
  size_t total = 0;
  for (auto& l : lines) total += l.size();
  out.points.reserve(total);
  out.offsets.reserve(n + 1);
  for (long s = 0; s < n; ++s) {
    out.points.insert(out.points.end(), lines[s].begin(), lines[s].end());
    out.offsets.push_back(static_cast<uint32_t>(out.points.size()));
    out.corner.push_back(seeds[s].corner);
  }
  out.ends = std::move(ends);
  if (stats) {
    stats->seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    stats->build_seconds = build_seconds;
    stats->evaluations = evaluations;
    stats->steps = steps_total;
    stats->escaped = stats->step_limit = stats->stalled = 0;
    for (LineEnd e : out.ends) {
      if (e == LineEnd::escaped) ++stats->escaped;
      else if (e == LineEnd::step_limit) ++stats->step_limit;
      else ++stats->stalled;
    }
  }
  progress.update("trace", 1.0);
  return out;
}

}  // namespace soupuv::field
