// soupuv-bench trace: paper Table 5. Torus (R=1, r=0.5) at 800 ... 204,800
// triangles: 50 midpoint steps from every unique mesh vertex (as the paper;
// `--seeds corners` traces every triangle corner instead) with the FMM, and by
// direct summation up to 12,800 triangles (--direct-max N). Direct runs on a
// subset of lines when the full run would be long and is scaled per line
// (the row says so: direct_lines_measured < lines).
//
// field_rel_error: max |E_fmm - E_direct| / |E_direct| over points sampled
// along the FMM lines at several step indices (from next to the surface to
// the line ends), evaluated by the tracer's own evaluator (TracerField);
// the row also gives the error over the samples outside every triangle's
// near zone, and the fraction of samples inside one.
//
// Non-quick also: which accuracy is enough (rows kind "accuracy"): how far
// line end points move when the charge tolerance (1e-3 ... 1e-7) or the
// tracer's FMM order is loosened, against a tight reference.
//
// Flags: --order P --theta T --leaf K (tracer FMM), --near-step-fraction F
// --max-turn T --max-step-growth G (the adaptive step, TraceOptions), --min-triangles N,
// --max-triangles N, --direct-max N, --direct-budget PAIRS, --seeds corners,
// --no-study, --study-only, --study-triangles N, --repeat R (FMM rows: the
// fastest of R runs; first_run_seconds / first_run_cpu_seconds: the first),
// --field-kernel (only the evaluator's cost per point, see run_field_kernel).
// FMM rows also carry first_run_minor_faults / last_run_minor_faults and
// first_run_sys_seconds / last_run_sys_seconds: a first run touches fresh
// memory, a repeat reuses the freed pages. With SOUPUV_BENCH_MARK_RUNS set,
// each run's CLOCK_MONOTONIC start goes to stderr, to cut a
// `perf record -k CLOCK_MONOTONIC` profile into first and later runs.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <limits>
#include <random>
#include <string>

#include "bench_registry.h"
#include "soupuv/field/direct.h"
#include "soupuv/field/field.h"
#include "soupuv/field/fmm.h"
#include "soupuv/field/tracer_field.h"
#include "testing/shapes.h"

using namespace soupuv;
using namespace soupuv::field;

namespace {

// CPU seconds (user + sys) of this process so far: on a shared machine a
// steadier measure than wall time for slopes and ratios.
double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// Minor page faults and system CPU seconds of the process so far: a first
// run that touches fresh memory pays them, a repeat reuses the freed pages.
long minor_faults() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_minflt;
}
double sys_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_stime.tv_sec + 1e-6 * u.ru_stime.tv_usec;
}

struct SampledError {
  double max = 0, max_far = 0, median = 0, p99 = 0, near_fraction = 0;
  // max |E_fmm - E_direct| over the median |E_direct| of the samples: the
  // relative error blows up next to a field null (the torus hole's centre),
  // where the absolute error does not.
  double max_abs_over_median_field = 0;
  Vec3 worst_at;
  double field_at_worst = 0;
  size_t samples = 0;
};

// Samples up to ~40 lines at step indices 0, 1, 2, 4, 8, 16, 32, 50 (when the
// line has them) and compares the tracer's evaluator with direct summation.
SampledError sampled_field_error(const ChargeResult& c, const FieldLines& lines, const TraceOptions& o) {
  SourceGeometry src = make_sources(c.positions, c.triangles, c.quadrature_degree);
  std::vector<Vec3> xs;
  const size_t stride = std::max<size_t>(1, lines.size() / 40);
  for (size_t i = 0; i < lines.size(); i += stride) {
    const uint32_t a = lines.offsets[i], b = lines.offsets[i + 1];
    for (uint32_t k : {1u, 2u, 3u, 5u, 9u, 17u, 33u, 51u})
      if (a + k < b) xs.push_back(lines.points[a + k]);
  }
  std::vector<Vec3> Ed;
  direct_sum(src, c.charges, xs, nullptr, &Ed);
  Box3 box;
  for (Vec3 p : c.positions) box.add(p);
  const double R = o.stop_radius;
  Box3 region;
  region.add(box.center() - Vec3{R, R, R});
  region.add(box.center() + Vec3{R, R, R});
  FmmOptions fo;
  fo.order = o.fmm_order;
  fo.theta = o.fmm_theta;
  fo.leaf_size = o.fmm_leaf_size;
  Fmm fmm(src, fo, region);
  TracerField tf(fmm, c.charges);
  SampledError r;
  size_t near = 0;
  std::vector<double> errs, mags;
  double max_abs = 0;
  for (size_t i = 0; i < xs.size(); ++i) {
    Vec3 E{0, 0, 0};
    double nearest = 0;
    const int leaf = tf.locate(xs[i]);
    tf.prepare({leaf});
    tf.field(leaf, &xs[i], 1, &E, &nearest);
    const double err = norm(E - Ed[i]) / norm(Ed[i]);
    errs.push_back(err);
    mags.push_back(norm(Ed[i]));
    max_abs = std::max(max_abs, norm(E - Ed[i]));
    if (err > r.max) {
      r.max = err;
      r.worst_at = xs[i];
      r.field_at_worst = norm(Ed[i]);
    }
    if (nearest < std::numeric_limits<double>::infinity()) ++near;
    else r.max_far = std::max(r.max_far, err);
  }
  r.samples = xs.size();
  std::sort(errs.begin(), errs.end());
  if (!errs.empty()) {
    r.median = errs[errs.size() / 2];
    r.p99 = errs[std::min(errs.size() - 1, errs.size() * 99 / 100)];
    std::nth_element(mags.begin(), mags.begin() + mags.size() / 2, mags.end());
    r.max_abs_over_median_field = max_abs / mags[mags.size() / 2];
  }
  r.near_fraction = xs.empty() ? 0 : double(near) / xs.size();
  return r;
}

// End-point shifts between two tracings of the same seeds: max, p99, median.
// The max alone says little: lines from the torus' inner equator run into
// the field null at the hole's centre and leave up or down depending on the
// last digits, so a handful of lines move by the line length whatever the
// accuracy.
struct Shifts {
  double max = 0, p99 = 0, median = 0;
  size_t worst = 0;        // line of the max
  size_t over_1e2 = 0;     // lines that moved by more than 0.01
  size_t lines = 0;        // lines compared
};
// Shift of point `step` of each line (the point after that many steps;
// -1: the end point); lines shorter than that in either tracing are left out.
Shifts point_shifts(const FieldLines& a, const FieldLines& b, int step = -1) {
  std::vector<std::pair<double, size_t>> d;
  for (size_t i = 0; i < a.size(); ++i) {
    const uint32_t ka = step < 0 ? a.offsets[i + 1] - 1 : a.offsets[i] + 1 + step;
    const uint32_t kb = step < 0 ? b.offsets[i + 1] - 1 : b.offsets[i] + 1 + step;
    if (ka >= a.offsets[i + 1] || kb >= b.offsets[i + 1]) continue;
    d.push_back({norm(a.points[ka] - b.points[kb]), i});
  }
  std::sort(d.begin(), d.end());
  Shifts s;
  s.lines = d.size();
  if (d.empty()) return s;
  s.max = d.back().first;
  s.worst = d.back().second;
  s.p99 = d[std::min(d.size() - 1, d.size() * 99 / 100)].first;
  s.median = d[d.size() / 2].first;
  for (const auto& [v, i] : d) s.over_1e2 += v > 1e-2;
  return s;
}
Shifts end_shifts(const FieldLines& a, const FieldLines& b) { return point_shifts(a, b); }

// The tracer's FMM for Table 5: p = 7, theta = 0.45, 32-triangle leaves. On
// a 12,800-triangle torus (400 points 1e-4 .. 0.4 above the surface) p = 7,
// theta = 0.45 gave max field rel. error 1.2e-4 (median 2.4e-6; the max sits
// in the hole, where |E| is a tenth of the surface field), against p = 6,
// theta = 0.5: 1.5e-3 and p = 6, theta = 0.4: 2.3e-4 (session 2). With the
// float near field, 32-triangle leaves beat 16 (fewer M2L; see
// TraceOptions::fmm_leaf_size); p = 6 theta = 0.4 with coarser target leaves
// was slower and over 1e-4 (2.0e-4 .. 2.5e-4 sampled along the lines).
TraceOptions table5_fmm() {
  TraceOptions o;
  o.fmm_order = 7;
  o.fmm_theta = 0.45;
  o.fmm_leaf_size = 32;
  return o;
}

struct Flags {
  size_t min_tris = 0, max_tris = 204800, direct_max = 12800, study_tris = 12800;
  double direct_budget = 1e9;  // point-triangle pairs the direct run may spend per size
  bool corners = false, study = true, table = true, kernel = false;
  int repeat = 1;
  TraceOptions trace = table5_fmm();
};

TraceOptions table5_options(const Flags& f) {
  TraceOptions o = f.trace;
  o.max_steps = 50;
  o.step = 0.02;
  o.stop_radius = 100;  // 50 full steps for every line
  return o;
}

// --field-kernel: TracerField::field alone, one thread, on 20,000 points at
// 1e-3 .. 0.3 above random surface points of the torus (the heights a line
// passes), two points per call as the tracer's batches mostly give; the best
// and the median of R passes (--repeat, default 25). Short passes and the
// best of many make it a steadier A/B measure of the evaluator than a whole
// trace on a loaded machine. Charges proportional to area (no solve: the cost
// does not depend on their values); not part of the default run.
void run_field_kernel(const Flags& f) {
  const int reps = f.repeat > 1 ? f.repeat : 25;
  for (int n : {800, 1800, 3200, 6400, 12800, 25600, 51200, 105800, 204800}) {
    if (static_cast<size_t>(n) > f.max_tris) break;
    if (static_cast<size_t>(n) < f.min_tris) continue;
    const Soup soup = shapes::to_soup(shapes::torus_with(1.0, 0.5, n));
    const SourceGeometry src = make_sources(soup.positions, soup.triangles, 4);
    std::vector<double> q(src.size());
    double total = 0;
    for (double a : src.area) total += a;
    for (size_t j = 0; j < src.size(); ++j) q[j] = src.area[j] / total;
    FmmOptions fo;
    fo.order = f.trace.fmm_order;
    fo.theta = f.trace.fmm_theta;
    fo.leaf_size = f.trace.fmm_leaf_size;
    fo.threads = 1;
    Box3 region;
    region.add({-3, -3, -3});
    region.add({3, 3, 3});
    Fmm fmm(src, fo, region);
    TracerField tf(fmm, q, 1);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<std::pair<int, Vec3>> points;
    for (int i = 0; i < 20000; ++i) {
      const size_t t = std::min(src.size() - 1, static_cast<size_t>(u(rng) * src.size()));
      const Vec3 normal = normalized(cross(src.b[t] - src.a[t], src.c[t] - src.a[t]));
      const Vec3 x = src.centroid[t] + (1e-3 * std::pow(300.0, u(rng))) * normal;
      points.push_back({tf.locate(x), x});
    }
    std::sort(points.begin(), points.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<int> leaves;
    std::vector<Vec3> xs;
    for (const auto& [leaf, x] : points) {
      leaves.push_back(leaf);
      xs.push_back(x);
    }
    tf.prepare(leaves);
    std::vector<Vec3> E(xs.size());
    std::vector<double> nearest(xs.size());
    std::vector<double> pass;
    for (int r = 0; r < reps; ++r) {
      std::fill(E.begin(), E.end(), Vec3{0, 0, 0});
      const auto t0 = std::chrono::steady_clock::now();
      for (size_t s = 0; s < xs.size();) {
        size_t e = s + 1;
        while (e < xs.size() && e - s < 2 && leaves[e] == leaves[s]) ++e;
        tf.field(leaves[s], &xs[s], static_cast<int>(e - s), &E[s], &nearest[s]);
        s = e;
      }
      pass.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    std::sort(pass.begin(), pass.end());
    const double us = 1e6 / static_cast<double>(xs.size());
    bench::emit({{"suite", "trace"}, {"kind", "field_kernel"}, {"shape", "torus"}, {"triangles", n},
                 {"method", "tracer-field"}, {"points", xs.size()}, {"seconds", pass.front()},
                 {"seconds_median", pass[pass.size() / 2]}, {"repeat", reps}, {"threads", 1},
                 {"us_per_point", us * pass.front()}, {"us_per_point_median", us * pass[pass.size() / 2]},
                 {"fmm_order", fo.order}, {"fmm_theta", fo.theta}, {"fmm_leaf_size", fo.leaf_size}});
    std::fprintf(stderr, "trace field kernel n=%d: %.3f us/point best of %d (median %.3f)\n", n, us * pass.front(), reps,
                 us * pass[pass.size() / 2]);
  }
}

void run_table5(const Flags& f, const bench::Args& args) {
  std::vector<int> sizes = {800, 1800, 3200, 6400, 12800, 25600, 51200, 105800, 204800};
  std::vector<double> fx, fy, fc, dx, dy, dc;
  double ratio_at_max_direct = NAN, fmm_at_max_direct = NAN, cpu_ratio_at_max_direct = NAN;
  // Per size: CPU microseconds per field evaluation of the FMM run.
  nlohmann::json cpu_per_eval_us = nlohmann::json::object();
  for (int n : sizes) {
    if (static_cast<size_t>(n) > f.max_tris) break;
    if (static_cast<size_t>(n) < f.min_tris) continue;
    TriMesh mesh = shapes::torus_with(1.0, 0.5, n);
    Soup soup = shapes::to_soup(mesh);
    ChargeOptions co;
    co.tolerance = 1e-5;
    ChargeResult c = solve_charges(soup, co);
    std::fprintf(stderr, "trace n=%d: charges in %.2fs\n", n, c.seconds);
    auto seeds = f.corners ? corner_seeds(soup) : vertex_seeds(mesh);
    TraceOptions o = table5_options(f);
    o.keep_points = n <= 51200;
    // --repeat R: the fastest of R identical runs (CPU and wall each), for
    // A/B comparisons on a shared machine.
    TraceStats st;
    FieldLines lines;
    double cpu_fmm = std::numeric_limits<double>::infinity(), wall_fmm = cpu_fmm;
    double first_wall = 0, first_cpu = 0;  // the process's first run (cold allocations)
    long first_faults = 0, last_faults = 0;
    double first_sys = 0, last_sys = 0;
    for (int r = 0; r < f.repeat; ++r) {
      const double cpu0 = cpu_seconds(), sys0 = sys_seconds();
      const long faults0 = minor_faults();
      if (std::getenv("SOUPUV_BENCH_MARK_RUNS")) {  // run boundaries for perf record -k CLOCK_MONOTONIC
        timespec ts{};
        clock_gettime(CLOCK_MONOTONIC, &ts);
        std::fprintf(stderr, "run %d start %.6f\n", r, ts.tv_sec + 1e-9 * ts.tv_nsec);
      }
      lines = trace_field_lines(c, seeds, o, Progress::none(), &st);
      cpu_fmm = std::min(cpu_fmm, cpu_seconds() - cpu0);
      wall_fmm = std::min(wall_fmm, st.seconds);
      last_faults = minor_faults() - faults0;
      last_sys = sys_seconds() - sys0;
      if (r == 0) {
        first_wall = st.seconds;
        first_cpu = cpu_seconds() - cpu0;
        first_faults = last_faults;
        first_sys = last_sys;
      }
    }
    st.seconds = wall_fmm;
    SampledError err;
    if (o.keep_points) err = sampled_field_error(c, lines, o);
    bench::emit({{"suite", "trace"}, {"shape", "torus"}, {"triangles", n}, {"method", "fmm"},
                 {"integrator", "midpoint"}, {"steps", 50}, {"lines", lines.size()},
                 {"seeds", f.corners ? "corners" : "unique mesh vertices"}, {"seconds", st.seconds},
                 {"cpu_seconds", cpu_fmm}, {"repeat", f.repeat},
                 {"first_run_seconds", first_wall}, {"first_run_cpu_seconds", first_cpu},
                 {"first_run_minor_faults", first_faults}, {"last_run_minor_faults", last_faults},
                 {"first_run_sys_seconds", first_sys}, {"last_run_sys_seconds", last_sys},
                 {"build_seconds", st.build_seconds}, {"evaluations", st.evaluations},
                 {"threads", bench::threads()},
                 {"field_rel_error", o.keep_points ? err.max : NAN},
                 {"field_rel_error_outside_near_zone", o.keep_points ? err.max_far : NAN},
                 {"field_rel_error_median", o.keep_points ? err.median : NAN},
                 {"field_rel_error_p99", o.keep_points ? err.p99 : NAN},
                 {"field_abs_error_over_median_field", o.keep_points ? err.max_abs_over_median_field : NAN},
                 {"worst_error_at", {err.worst_at.x, err.worst_at.y, err.worst_at.z}},
                 {"field_magnitude_at_worst", err.field_at_worst},
                 {"error_samples", err.samples}, {"error_samples_near_fraction", err.near_fraction},
                 {"fmm_order", o.fmm_order}, {"fmm_theta", o.fmm_theta}, {"fmm_leaf_size", o.fmm_leaf_size},
                 {"near_step_fraction", o.near_step_fraction}, {"max_turn_per_step", o.max_turn_per_step},
                 {"max_step_growth", o.max_step_growth}, {"grown_steps", st.grown_steps},
                 {"grown_steps_redone", st.grown_steps_redone},
                 {"cpu_per_evaluation_us", 1e6 * cpu_fmm / double(st.evaluations)},
                 {"expansions", st.expansions}, {"m2l_operations", st.m2l_operations}, {"m2l_terms", st.m2l_terms},
                 {"m2l_per_evaluation", double(st.m2l_operations) / double(st.evaluations)},
                 {"escaped", st.escaped}, {"step_limit", st.step_limit}, {"stalled", st.stalled},
                 {"trapped", st.trapped},
                 {"peak_rss_mb", bench::peak_rss_mb()}});
    std::fprintf(stderr, "trace fmm n=%d lines=%zu: %.2fs (build %.2fs, cpu %.2fs)", n, lines.size(), st.seconds,
                 st.build_seconds, cpu_fmm);
    if (err.samples > 0)
      std::fprintf(stderr, " err max %.1e p99 %.1e median %.1e (far %.1e, near %.0f%%)", err.max, err.p99, err.median,
                   err.max_far, 100 * err.near_fraction);
    std::fprintf(stderr, "\n");
    cpu_per_eval_us[std::to_string(n)] = 1e6 * cpu_fmm / double(st.evaluations);
    fx.push_back(n);
    fy.push_back(st.seconds);
    fc.push_back(cpu_fmm);
    if (static_cast<size_t>(n) > f.direct_max) continue;
    // Direct summation costs n per evaluation: measure on at most ~1e9
    // point-triangle pairs' worth of lines and scale per line.
    const double pairs_per_line = 100.0 * n;
    const double budget = args.quick ? 2e8 : f.direct_budget;
    size_t every = std::max<size_t>(1, static_cast<size_t>(seeds.size() * pairs_per_line / budget));
    std::vector<TraceSeed> sub;
    for (size_t i = 0; i < seeds.size(); i += every) sub.push_back(seeds[i]);
    TraceOptions d = o;
    d.direct = true;
    TraceStats sd;
    const double dcpu0 = cpu_seconds();
    FieldLines dl = trace_field_lines(c, sub, d, Progress::none(), &sd);
    const double scale = double(seeds.size()) / sub.size();
    const double scaled = sd.seconds * scale, scaled_cpu = (cpu_seconds() - dcpu0) * scale;
    FieldLines fl = trace_field_lines(c, sub, o);  // the FMM's lines for the same seeds
    // How far the FMM's lines end from the direct ones. The max is a few
    // lines from the inner equator (the seed's distance from the axis says
    // so): they run into the field null at the hole's centre, where the
    // direction is decided by the last digits, and leave up or down. The
    // median and the shift after the first steps measure the evaluators.
    const Shifts end = end_shifts(fl, dl), at10 = point_shifts(fl, dl, 10), at25 = point_shifts(fl, dl, 25);
    const Vec3 worst_seed = sub[end.worst].position, worst10_seed = sub[at10.worst].position;
    bench::emit({{"suite", "trace"}, {"shape", "torus"}, {"triangles", n}, {"method", "direct"},
                 {"integrator", "midpoint"}, {"steps", 50}, {"lines", seeds.size()},
                 {"direct_lines_measured", sub.size()}, {"seconds", scaled}, {"seconds_measured", sd.seconds},
                 {"cpu_seconds", scaled_cpu},
                 {"threads", bench::threads()}, {"field_rel_error", 0.0},
                 {"end_point_shift_vs_fmm", end.max}, {"end_point_shift_p99", end.p99},
                 {"end_point_shift_median", end.median}, {"lines_shifted_over_0.01", end.over_1e2},
                 {"worst_shift_seed_axis_distance", std::hypot(worst_seed.x, worst_seed.y)},
                 {"worst_shift_seed_z", worst_seed.z},
                 {"shift_after_10_steps", {{"max", at10.max}, {"p99", at10.p99}, {"median", at10.median},
                                           {"worst_seed_axis_distance", std::hypot(worst10_seed.x, worst10_seed.y)},
                                           {"worst_seed_z", worst10_seed.z}}},
                 {"shift_after_25_steps", {{"max", at25.max}, {"p99", at25.p99}, {"median", at25.median}}}});
    std::fprintf(stderr,
                 "trace direct n=%d: %.2fs for %zu lines, %.2fs scaled to %zu; end shift vs fmm max %.2e (%zu lines "
                 "> 0.01, worst seed %.3f from the axis) p99 %.2e median %.2e; after 10 steps max %.2e (seed %.3f from "
                 "the axis, z %.3f), 25 steps max %.2e\n",
                 n, sd.seconds, sub.size(), scaled, seeds.size(), end.max, end.over_1e2,
                 std::hypot(worst_seed.x, worst_seed.y), end.p99, end.median, at10.max,
                 std::hypot(worst10_seed.x, worst10_seed.y), worst10_seed.z, at25.max);
    dx.push_back(n);
    dy.push_back(scaled);
    dc.push_back(scaled_cpu);
    ratio_at_max_direct = scaled / st.seconds;
    cpu_ratio_at_max_direct = scaled_cpu / cpu_fmm;
    fmm_at_max_direct = st.seconds;
  }
  bench::emit({{"suite", "trace"}, {"kind", "summary"}, {"threads", bench::threads()},
               {"seeds", f.corners ? "corners" : "unique mesh vertices"},
               {"slope", {{"fmm", bench::loglog_slope(fx, fy)}, {"direct", bench::loglog_slope(dx, dy)}}},
               {"slope_cpu", {{"fmm", bench::loglog_slope(fx, fc)}, {"direct", bench::loglog_slope(dx, dc)}}},
               {"direct_over_fmm_cpu_at_largest_direct", cpu_ratio_at_max_direct},
               {"slope_fmm_from", fx.empty() ? 0.0 : fx.front()}, {"slope_fmm_to", fx.empty() ? 0.0 : fx.back()},
               {"direct_over_fmm_at_largest_direct", ratio_at_max_direct},
               {"cpu_per_evaluation_us", cpu_per_eval_us},
               {"fmm_seconds_at_largest_direct", fmm_at_max_direct},
               {"largest_direct_triangles", dx.empty() ? 0.0 : dx.back()},
               {"fmm_seconds_at_largest", fy.empty() ? NAN : fy.back()},
               {"fmm_cpu_seconds_at_largest", fc.empty() ? NAN : fc.back()},
               {"largest_triangles", fx.empty() ? 0.0 : fx.back()}});
}

// Which accuracy is enough: end points against a reference charged to 1e-8
// and traced with p = 10, as the charge tolerance or the tracer's order is loosened.
void run_study(const Flags& f) {
  const int n = static_cast<int>(f.study_tris);
  TriMesh mesh = shapes::torus_with(1.0, 0.5, n);
  Soup soup = shapes::to_soup(mesh);
  auto seeds = f.corners ? corner_seeds(soup) : vertex_seeds(mesh);
  TraceOptions o = table5_options(f);
  o.keep_points = false;
  ChargeOptions tight;
  tight.tolerance = 1e-8;
  ChargeResult ct = solve_charges(soup, tight);
  TraceOptions ref_o = o;
  ref_o.fmm_order = 10;
  FieldLines ref = trace_field_lines(ct, seeds, ref_o);
  const double mean_edge = std::sqrt(4 * 3.14159265358979 * 3.14159265358979 * 0.5 / (n / 2.0));
  for (double tol : {1e-3, 1e-4, 1e-5, 1e-6, 1e-7}) {
    ChargeOptions co;
    co.tolerance = tol;
    ChargeResult c = solve_charges(soup, co);
    FieldLines l = trace_field_lines(c, seeds, ref_o);
    const Shifts shift = end_shifts(l, ref);
    bench::emit({{"suite", "trace"}, {"kind", "accuracy"}, {"shape", "torus"}, {"triangles", n},
                 {"method", "fmm"}, {"integrator", "midpoint"}, {"steps", 50}, {"lines", seeds.size()},
                 {"charge_tolerance", tol}, {"charge_error", c.max_rel_potential_error},
                 {"charge_seconds", c.seconds}, {"seconds", c.seconds}, {"threads", bench::threads()},
                 {"fmm_order", ref_o.fmm_order}, {"max_end_point_shift", shift.max},
                 {"p99_end_point_shift", shift.p99}, {"median_end_point_shift", shift.median},
                 {"median_shift_over_mean_edge", shift.median / mean_edge}, {"step", o.step}});
    std::fprintf(stderr, "study tol %.0e: charge %.2fs err %.1e, end shift max %.2e p99 %.2e median %.2e\n", tol,
                 c.seconds, c.max_rel_potential_error, shift.max, shift.p99, shift.median);
  }
  for (int p : {2, 3, 4, 5, 6, 8}) {
    TraceOptions po = o;
    po.fmm_order = p;
    TraceStats st;
    FieldLines l = trace_field_lines(ct, seeds, po, Progress::none(), &st);
    const Shifts shift = end_shifts(l, ref);
    bench::emit({{"suite", "trace"}, {"kind", "accuracy"}, {"shape", "torus"}, {"triangles", n},
                 {"method", "fmm"}, {"integrator", "midpoint"}, {"steps", 50}, {"lines", seeds.size()},
                 {"charge_tolerance", tight.tolerance}, {"fmm_order", p}, {"fmm_theta", po.fmm_theta},
                 {"seconds", st.seconds}, {"threads", bench::threads()}, {"max_end_point_shift", shift.max},
                 {"p99_end_point_shift", shift.p99}, {"median_end_point_shift", shift.median},
                 {"median_shift_over_mean_edge", shift.median / mean_edge}, {"step", o.step}});
    std::fprintf(stderr, "study p=%d: trace %.2fs, end shift max %.2e p99 %.2e median %.2e\n", p, st.seconds,
                 shift.max, shift.p99, shift.median);
  }
}

int run_trace(const bench::Args& args) {
  Flags f;
  if (args.quick) {
    // CI, about a minute on 2 busy cores: three sizes, direct at the smallest, no study.
    f.max_tris = 3200;
    f.direct_max = 800;
    f.study = false;
  }
  for (size_t i = 0; i < args.rest.size(); ++i) {
    const std::string& a = args.rest[i];
    const bool has = i + 1 < args.rest.size();
    if (a == "--max-triangles" && has) f.max_tris = std::stoul(args.rest[++i]);
    else if (a == "--min-triangles" && has) f.min_tris = std::stoul(args.rest[++i]);
    else if (a == "--direct-budget" && has) f.direct_budget = std::stod(args.rest[++i]);
    else if (a == "--direct-max" && has) f.direct_max = std::stoul(args.rest[++i]);
    else if (a == "--study-triangles" && has) f.study_tris = std::stoul(args.rest[++i]);
    else if (a == "--order" && has) f.trace.fmm_order = std::stoi(args.rest[++i]);
    else if (a == "--theta" && has) f.trace.fmm_theta = std::stod(args.rest[++i]);
    else if (a == "--leaf" && has) f.trace.fmm_leaf_size = std::stoi(args.rest[++i]);
    else if (a == "--near-step-fraction" && has) f.trace.near_step_fraction = std::stod(args.rest[++i]);
    else if (a == "--max-step-growth" && has) f.trace.max_step_growth = std::stod(args.rest[++i]);
    else if (a == "--max-turn" && has) f.trace.max_turn_per_step = std::stod(args.rest[++i]);
    else if (a == "--seeds" && has) f.corners = args.rest[++i] == "corners";
    else if (a == "--repeat" && has) f.repeat = std::max(1, std::stoi(args.rest[++i]));
    else if (a == "--no-study") f.study = false;
    else if (a == "--field-kernel") f.kernel = true;
    else if (a == "--study-only") f.table = false;
  }
  if (f.kernel) {
    run_field_kernel(f);
    return 0;
  }
  if (f.table) run_table5(f, args);
  if (f.study) run_study(f);
  return 0;
}

bench::Suite reg("trace", "field-line tracing: Table 5 (FMM vs direct), and which accuracy is enough", run_trace);

}  // namespace
