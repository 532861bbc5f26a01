// soupuv-bench integrator: paper Table 6. Euler vs midpoint final-position
// error against a fine midpoint reference, for fixed step sizes over the same
// arc length, on field lines of a torus (400 lines).
#include <cstdio>

#include "bench_registry.h"
#include "soupuv/field/field.h"
#include "soupuv/shapes.h"

using namespace soupuv;
using namespace soupuv::field;

namespace {

int run_integrator(const bench::Args& args) {
  Soup soup = shapes::to_soup(shapes::torus_with(1.0, 0.5, 800));
  ChargeOptions co;
  co.tolerance = 1e-6;
  ChargeResult c = solve_charges(soup, co);
  std::vector<TraceSeed> all = corner_seeds(soup), seeds;
  for (size_t i = 0; i < all.size() && seeds.size() < 400; i += all.size() / 400) seeds.push_back(all[i]);
  const double length = 1.0;
  const double ref_step = args.quick ? 1e-3 : 1e-4;
  auto trace = [&](TraceOptions::Integrator integ, double h, TraceStats* st) {
    TraceOptions o;
    o.integrator = integ;
    o.step = h;
    o.max_steps = static_cast<int>(std::lround(length / h));
    o.adaptive_step = false;
    o.start_offset = 1e-3;
    o.stop_radius = 100;
    o.keep_points = false;
    return trace_field_lines(c, seeds, o, Progress::none(), st);
  };
  FieldLines ref = trace(TraceOptions::Integrator::midpoint, ref_step, nullptr);
  std::vector<double> hs = {0.1, 0.05, 0.02, 0.01, 0.005};
  std::map<std::string, std::vector<double>> err;
  for (auto integ : {TraceOptions::Integrator::euler, TraceOptions::Integrator::midpoint}) {
    std::string name = integ == TraceOptions::Integrator::euler ? "euler" : "midpoint";
    for (double h : hs) {
      TraceStats st;
      FieldLines l = trace(integ, h, &st);
      double worst = 0, mean = 0;
      for (size_t i = 0; i < l.size(); ++i) {
        double d = norm(l.points[l.offsets[i + 1] - 1] - ref.points[ref.offsets[i + 1] - 1]);
        worst = std::max(worst, d);
        mean += d / l.size();
      }
      err[name].push_back(mean);
      bench::emit({{"suite", "integrator"}, {"shape", "torus"}, {"triangles", soup.triangles.size()},
                   {"method", "fmm"}, {"integrator", name}, {"step", h}, {"steps", st.steps / l.size()},
                   {"lines", l.size()}, {"seconds", st.seconds}, {"threads", bench::threads()},
                   {"max_position_error", worst}, {"mean_position_error", mean}, {"reference_step", ref_step}});
      std::fprintf(stderr, "%s h=%g: max %.2e mean %.2e\n", name.c_str(), h, worst, mean);
    }
  }
  bench::emit({{"suite", "integrator"}, {"kind", "summary"}, {"threads", bench::threads()},
               {"slope", {{"euler", bench::loglog_slope(hs, err["euler"])},
                          {"midpoint", bench::loglog_slope(hs, err["midpoint"])}}}});
  return 0;
}

bench::Suite reg("integrator", "Euler vs midpoint final-position error vs step (Table 6)", run_integrator);

}  // namespace
