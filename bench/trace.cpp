// soupuv-bench trace: paper Table 5. Torus (R=1, r=0.5) at 800 ... 204,800
// triangles: trace 50 midpoint steps from every corner with the FMM, and by
// direct summation up to 12,800 triangles (--direct-max N). field_rel_error
// is the largest |E_fmm - E_direct| / |E_direct| over up to 200 points
// sampled along the FMM lines. Also: how far line end points move when the
// charge tolerance or the FMM order is loosened (which accuracy is enough).
#include <algorithm>
#include <cstdio>

#include "bench_registry.h"
#include "soupuv/field/direct.h"
#include "soupuv/field/field.h"
#include "soupuv/field/fmm.h"
#include "soupuv/shapes.h"

using namespace soupuv;
using namespace soupuv::field;

namespace {

double sampled_field_error(const ChargeResult& c, const FieldLines& lines, const TraceOptions& o) {
  SourceGeometry src = make_sources(c.positions, c.triangles, c.quadrature_degree);
  std::vector<Vec3> xs;
  size_t stride = std::max<size_t>(1, lines.points.size() / 200);
  for (size_t i = 0; i < lines.points.size(); i += stride) xs.push_back(lines.points[i]);
  std::vector<Vec3> Ed;
  direct_sum(src, c.charges, xs, nullptr, &Ed);
  // The same target region the tracer uses (a cube around its stop sphere),
  // so the sampled error is the tracer's own FMM error.
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
  fmm.set_charges(c.charges);
  double worst = 0;
  for (size_t i = 0; i < xs.size(); ++i) {
    Vec3 E{0, 0, 0};
    fmm.evaluate(xs[i], nullptr, &E);
    worst = std::max(worst, norm(E - Ed[i]) / norm(Ed[i]));
  }
  return worst;
}

double end_shift(const FieldLines& a, const FieldLines& b) {
  double worst = 0;
  for (size_t i = 0; i < a.size(); ++i)
    worst = std::max(worst, norm(a.points[a.offsets[i + 1] - 1] - b.points[b.offsets[i + 1] - 1]));
  return worst;
}

int run_trace(const bench::Args& args) {
  // --quick (CI, about a minute on 2 busy cores): two sizes, direct only at the smallest.
  size_t max_tris = args.quick ? 1800 : 204800, direct_max = args.quick ? 800 : 12800;
  for (size_t i = 0; i + 1 < args.rest.size(); ++i) {
    if (args.rest[i] == "--max-triangles") max_tris = std::stoul(args.rest[i + 1]);
    if (args.rest[i] == "--direct-max") direct_max = std::stoul(args.rest[i + 1]);
  }
  std::vector<int> sizes = {800, 1800, 3200, 6400, 12800, 25600, 51200, 105800, 204800};
  std::vector<double> fx, fy, dx, dy;
  double ratio_at_max_direct = NAN;
  for (int n : sizes) {
    if (static_cast<size_t>(n) > max_tris) break;
    Soup soup = shapes::to_soup(shapes::torus_with(1.0, 0.5, n));
    ChargeOptions co;
    co.tolerance = 1e-5;
    ChargeResult c = solve_charges(soup, co);
    auto seeds = corner_seeds(soup);
    TraceOptions o;
    o.max_steps = 50;
    o.step = 0.02;
    o.stop_radius = 100;  // 50 full steps for every line
    o.keep_points = n <= 51200;
    TraceStats st;
    FieldLines lines = trace_field_lines(c, seeds, o, Progress::none(), &st);
    double err = o.keep_points ? sampled_field_error(c, lines, o) : NAN;
    bench::emit({{"suite", "trace"}, {"shape", "torus"}, {"triangles", n}, {"method", "fmm"},
                 {"integrator", "midpoint"}, {"steps", 50}, {"lines", lines.size()}, {"seconds", st.seconds},
                 {"build_seconds", st.build_seconds}, {"evaluations", st.evaluations},
                 {"threads", bench::threads()}, {"field_rel_error", err}, {"fmm_order", o.fmm_order},
                 {"fmm_theta", o.fmm_theta}, {"peak_rss_mb", bench::peak_rss_mb()}});
    std::fprintf(stderr, "trace fmm n=%d: %.2fs err %.1e\n", n, st.seconds, err);
    fx.push_back(n);
    fy.push_back(st.seconds);
    if (static_cast<size_t>(n) <= direct_max) {
      TraceOptions d = o;
      d.direct = true;
      TraceStats sd;
      FieldLines dl = trace_field_lines(c, seeds, d, Progress::none(), &sd);
      bench::emit({{"suite", "trace"}, {"shape", "torus"}, {"triangles", n}, {"method", "direct"},
                   {"integrator", "midpoint"}, {"steps", 50}, {"lines", dl.size()}, {"seconds", sd.seconds},
                   {"threads", bench::threads()}, {"field_rel_error", 0.0},
                   {"end_point_shift_vs_fmm", end_shift(lines, dl)}});
      std::fprintf(stderr, "trace direct n=%d: %.2fs\n", n, sd.seconds);
      dx.push_back(n);
      dy.push_back(sd.seconds);
      ratio_at_max_direct = sd.seconds / st.seconds;
    }
  }
  // Which accuracy is enough: end-point movement when loosening the charge
  // tolerance and the tracer's FMM order, against a tight reference.
  {
    int n = args.quick ? 800 : 12800;
    Soup soup = shapes::to_soup(shapes::torus_with(1.0, 0.5, n));
    auto seeds = corner_seeds(soup);
    TraceOptions o;
    o.max_steps = 50;
    o.step = 0.02;
    o.stop_radius = 100;
    ChargeOptions tight;
    tight.tolerance = 1e-8;
    ChargeResult ct = solve_charges(soup, tight);
    TraceOptions ref_o = o;
    ref_o.fmm_order = 10;
    FieldLines ref = trace_field_lines(ct, seeds, ref_o);
    const std::vector<double> tolerances =
        args.quick ? std::vector<double>{1e-2, 1e-5} : std::vector<double>{1e-2, 1e-3, 1e-4, 1e-5, 1e-6};
    for (double tol : tolerances) {
      ChargeOptions co;
      co.tolerance = tol;
      ChargeResult c = solve_charges(soup, co);
      FieldLines l = trace_field_lines(c, seeds, ref_o);
      bench::emit({{"suite", "trace"}, {"kind", "accuracy"}, {"shape", "torus"}, {"triangles", n},
                   {"method", "fmm"}, {"integrator", "midpoint"}, {"steps", 50}, {"charge_tolerance", tol},
                   {"charge_error", c.max_rel_potential_error}, {"seconds", c.seconds}, {"threads", bench::threads()},
                   {"max_end_point_shift", end_shift(l, ref)}, {"step", o.step}});
    }
    const std::vector<int> orders = args.quick ? std::vector<int>{4, 6} : std::vector<int>{2, 4, 6, 8};
    for (int p : orders) {
      TraceOptions po = o;
      po.fmm_order = p;
      TraceStats st;
      FieldLines l = trace_field_lines(ct, seeds, po, Progress::none(), &st);
      bench::emit({{"suite", "trace"}, {"kind", "accuracy"}, {"shape", "torus"}, {"triangles", n},
                   {"method", "fmm"}, {"integrator", "midpoint"}, {"steps", 50}, {"fmm_order", p},
                   {"seconds", st.seconds}, {"threads", bench::threads()},
                   {"max_end_point_shift", end_shift(l, ref)}, {"step", o.step}});
    }
  }
  bench::emit({{"suite", "trace"}, {"kind", "summary"}, {"threads", bench::threads()},
               {"slope", {{"fmm", bench::loglog_slope(fx, fy)}, {"direct", bench::loglog_slope(dx, dy)}}},
               {"direct_over_fmm_at_largest_direct", ratio_at_max_direct},
               {"largest_direct_triangles", dx.empty() ? 0.0 : dx.back()}});
  return 0;
}

bench::Suite reg("trace", "field-line tracing: Table 5 (FMM vs direct), and which accuracy is enough", run_trace);

}  // namespace
