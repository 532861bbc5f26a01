// soupuv-bench step-rule: the tracer's near-surface step rule
// (TraceOptions::max_step_growth, near_step_fraction, max_turn_per_step)
// judged where it matters, at the points where lines cross an offset surface
// (what the proxy is), against a fine reference traced from the same charges.
//
// Cases: a torus (R = 1, r = 0.5; one line per mesh vertex, as Table 5),
// torus soups with noise of 3 % and 13 % of an edge, and a cube soup (one line per triangle corner: sharp
// edges, where lines bend). Offset surfaces: the torus tube of radius
// r + o, the cube's exterior distance o, for o = 0.05 and 0.2.
// The rules: 50 midpoint steps of 0.02 (Table 5) and of the default length
// (step 0 in the rows: 2 % of the bounding-box diagonal, what the pipeline
// traces with), each with max_step_growth 0 (the distance rule alone), 4, 16
// and 64. The reference: the distance rule at
// fraction 0.5, turn 0.01 rad per step, steps of 0.0025.
//
// Rows (suite "step-rule", kind "accuracy"): shape, triangles, lines,
// max_step_growth, seconds, evaluations, grown_steps(_redone), and per
// offset the crossing shift against the reference in mean edge lengths
// (median, p99, max, lines over 0.1 edges), lines without a crossing in
// either, and lines with a
// segment that meets a soup triangle (Fmm::segment_crosses). --quick: smaller
// meshes.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "bench_registry.h"
#include "soupuv/field/field.h"
#include "soupuv/field/fmm.h"
#include "soupuv/field/sources.h"
#include "testing/shapes.h"

using namespace soupuv;
using namespace soupuv::field;

namespace {

// Signed distance-like function of a case: negative inside the offset surface.
using OffsetFn = std::function<double(Vec3, double)>;

struct Case {
  std::string shape;
  Soup soup;
  std::vector<TraceSeed> seeds;
  OffsetFn outside;  // (p, o) -> > 0 beyond the offset surface at o
  bool corners;      // seeds are corner_seeds(soup): line 3t + k starts at corner k of triangle t
};

double torus_outside(Vec3 p, double o) {
  const double rho = std::sqrt(p.x * p.x + p.y * p.y);
  return std::hypot(rho - 1.0, p.z) - (0.5 + o);
}

double cube_outside(Vec3 p, double o) {
  const Vec3 q{std::max(std::abs(p.x) - 1.0, 0.0), std::max(std::abs(p.y) - 1.0, 0.0),
               std::max(std::abs(p.z) - 1.0, 0.0)};
  return norm(q) - o;
}

// First crossing of line i with the offset surface (linear in the segment);
// false if the line never gets beyond it.
bool crossing(const FieldLines& l, size_t i, const OffsetFn& outside, double o, Vec3& at) {
  for (uint32_t k = l.offsets[i]; k + 1 < l.offsets[i + 1]; ++k) {
    const double f0 = outside(l.points[k], o), f1 = outside(l.points[k + 1], o);
    if (f0 <= 0 && f1 > 0) {
      const double t = f0 / (f0 - f1);
      at = l.points[k] + t * (l.points[k + 1] - l.points[k]);
      return true;
    }
  }
  return false;
}

// Lines with a segment (after the start point) that meets a soup triangle.
size_t lines_meeting_soup(const Fmm& fmm, const FieldLines& l) {
  size_t count = 0;
  const long n = static_cast<long>(l.size());
#pragma omp parallel for schedule(dynamic, 64) reduction(+ : count)
  for (long i = 0; i < n; ++i)
    for (uint32_t k = l.offsets[i] + 1; k + 1 < l.offsets[i + 1]; ++k)
      if (fmm.segment_crosses(l.points[k], l.points[k + 1])) {
        ++count;
        break;
      }
  return count;
}

// Soup triangles whose three corner lines cross the offset surface farther
// apart than `factor` times the triangle's longest edge: where the proxy's
// UVs come back stretched (the transfer's figure of merit).
size_t triangles_spread(const Soup& soup, const FieldLines& l, const OffsetFn& outside, double o, double factor) {
  size_t count = 0;
  for (size_t t = 0; t < soup.triangles.size(); ++t) {
    Vec3 p[3];
    bool all = true;
    for (int k = 0; k < 3 && all; ++k) all = crossing(l, 3 * t + k, outside, o, p[k]);
    if (!all) continue;
    double edge = 0, spread = 0;
    for (int k = 0; k < 3; ++k) {
      edge = std::max(edge, norm(soup.corner(t, (k + 1) % 3) - soup.corner(t, k)));
      spread = std::max(spread, norm(p[(k + 1) % 3] - p[k]));
    }
    if (spread > factor * edge) ++count;
  }
  return count;
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(q * (v.size() - 1) + 0.5))];
}

void run_case(const Case& c) {
  const ChargeResult charges = solve_charges(c.soup, ChargeOptions{});
  const SourceGeometry src = make_sources(charges.positions, charges.triangles, charges.quadrature_degree);
  const Fmm fmm(src, FmmOptions{});
  const double edge = mean_edge_length(c.soup);
  TraceOptions ref_o;
  ref_o.max_step_growth = 0;
  ref_o.near_step_fraction = 0.5;
  ref_o.max_turn_per_step = 0.01;
  ref_o.step = 0.0025;
  ref_o.max_steps = 400;  // past o = 0.2 after the near-surface steps
  ref_o.stop_radius = 100;
  const FieldLines ref = trace_field_lines(charges, c.seeds, ref_o);
  for (double step : {0.02, 0.0})
  for (double growth : {0.0, 4.0, 16.0, 64.0}) {
    TraceOptions o;
    o.max_steps = 50;
    o.step = step;
    o.stop_radius = 100;
    o.max_step_growth = growth;
    TraceStats st;
    const FieldLines l = trace_field_lines(charges, c.seeds, o, Progress::none(), &st);
    const size_t meeting = lines_meeting_soup(fmm, l);
    for (double off : {0.05, 0.2}) {
      std::vector<double> shift;
      size_t missing = 0;
      for (size_t i = 0; i < l.size(); ++i) {
        Vec3 a, b;
        if (!crossing(l, i, c.outside, off, a) || !crossing(ref, i, c.outside, off, b)) {
          ++missing;
          continue;
        }
        shift.push_back(norm(a - b) / edge);
      }
      const double med = quantile(shift, 0.5), p99 = quantile(shift, 0.99), mx = quantile(shift, 1.0);
      const size_t over = std::count_if(shift.begin(), shift.end(), [](double x) { return x > 0.1; });
      const size_t spread = c.corners ? triangles_spread(c.soup, l, c.outside, off, 3.0) : 0;
      bench::emit({{"suite", "step-rule"}, {"kind", "accuracy"}, {"shape", c.shape},
                   {"triangles", c.soup.triangles.size()}, {"lines", l.size()}, {"method", "fmm"},
                   {"integrator", "midpoint"}, {"steps", o.max_steps}, {"step", o.step},
                   {"max_step_growth", growth}, {"seconds", st.seconds}, {"threads", bench::threads()},
                   {"evaluations", st.evaluations}, {"grown_steps", st.grown_steps},
                   {"grown_steps_redone", st.grown_steps_redone}, {"offset", off},
                   {"crossing_shift_median_edges", med}, {"crossing_shift_p99_edges", p99},
                   {"crossing_shift_max_edges", mx}, {"lines_shifted_over_0.1_edges", over},
                   {"lines_without_crossing", missing}, {"triangles_spread_over_3", spread},
                   {"lines_meeting_soup", meeting}});
      std::fprintf(stderr,
                   "step-rule %s n=%zu step %g growth %g: %.2fs, offset %.2f: crossing shift median %.2e p99 %.2e max %.2e "
                   "edges (%zu over 0.1), %zu without crossing, %zu triangles spread > 3x, %zu lines meet the soup, "
                   "%zu/%zu grown steps redone\n",
                   c.shape.c_str(), c.soup.triangles.size(), o.step, growth, st.seconds, off, med, p99, mx, over, missing,
                   spread, meeting,
                   st.grown_steps_redone, st.grown_steps);
    }
  }
}

int run_step_rule(const bench::Args& args) {
  const int torus_n = args.quick ? 1800 : 12800;
  const int noisy_n = args.quick ? 800 : 3200;
  const int cube_n = args.quick ? 6 : 20;  // 12 n^2 triangles
  {
    const TriMesh mesh = shapes::torus_with(1.0, 0.5, torus_n);
    run_case({"torus", shapes::to_soup(mesh), vertex_seeds(mesh), torus_outside, false});
  }
  {
    const Soup soup = shapes::to_soup(shapes::torus_with(1.0, 0.5, noisy_n), 1e-3, 1);
    run_case({"noisy-torus-soup", soup, corner_seeds(soup), torus_outside, true});
  }
  {
    // Noise of 13 % of an edge, as the pipeline's 100k soup (1e-3 of the
    // diagonal there): lines start among tilted neighbours.
    const Soup soup = shapes::to_soup(shapes::torus_with(1.0, 0.5, noisy_n), 5e-3, 1);
    run_case({"rough-torus-soup", soup, corner_seeds(soup), torus_outside, true});
  }
  {
    const Soup soup = shapes::to_soup(shapes::cube(2.0, cube_n));
    run_case({"cube-soup", soup, corner_seeds(soup), cube_outside, true});
  }
  bench::emit({{"suite", "step-rule"}, {"kind", "summary"}, {"threads", bench::threads()}});
  return 0;
}

soupuv::bench::Suite reg("step-rule",
                         "near-surface step rule: where lines cross offset surfaces, against a fine reference",
                         run_step_rule);

}  // namespace
