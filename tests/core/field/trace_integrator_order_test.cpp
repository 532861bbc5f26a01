// Convergence order of the tracer's integrators on a smooth stretch of field
// lines: halving the fixed step must divide the end-point error (against a
// fine midpoint reference over the same arc length) by ~2 for Euler and ~4
// for the midpoint method. Lines start 0.1 off the surface: closer, the field
// turns on the scale of the distance to the soup, far below the steps, and
// both methods look first order (see bench/integrator.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "soupuv/field/field.h"
#include "testing/shapes.h"

using namespace soupuv;
using namespace soupuv::field;

namespace {

FieldLines trace_fixed(const ChargeResult& c, const std::vector<TraceSeed>& seeds,
                       TraceOptions::Integrator integ, double h) {
  TraceOptions o;
  o.integrator = integ;
  o.step = h;
  o.max_steps = static_cast<int>(std::lround(1.0 / h));  // arc length 1 for every h
  o.adaptive_step = false;
  o.start_offset = 0.1;
  o.stop_radius = 100;
  o.keep_points = false;
  o.threads = 1;
  return trace_field_lines(c, seeds, o);
}

double mean_end_error(const FieldLines& a, const FieldLines& ref) {
  double sum = 0;
  for (size_t i = 0; i < a.size(); ++i)
    sum += norm(a.points[a.offsets[i + 1] - 1] - ref.points[ref.offsets[i + 1] - 1]);
  return sum / a.size();
}

}  // namespace

TEST(TraceIntegrator, EulerFirstOrderMidpointSecondOrder) {
  Soup soup = shapes::to_soup(shapes::torus_with(1.0, 0.5, 800));
  ChargeOptions co;
  co.tolerance = 1e-6;
  ChargeResult c = solve_charges(soup, co);
  std::vector<TraceSeed> all = corner_seeds(soup), seeds;
  for (size_t i = 0; i < all.size(); i += all.size() / 20) seeds.push_back(all[i]);
  FieldLines ref = trace_fixed(c, seeds, TraceOptions::Integrator::midpoint, 0.0025);
  for (auto integ : {TraceOptions::Integrator::euler, TraceOptions::Integrator::midpoint}) {
    const bool mid = integ == TraceOptions::Integrator::midpoint;
    const double e1 = mean_end_error(trace_fixed(c, seeds, integ, 0.05), ref);
    const double e2 = mean_end_error(trace_fixed(c, seeds, integ, 0.025), ref);
    const double ratio = e1 / e2;
    std::printf("%s: error h=0.05 %.3e, h=0.025 %.3e, ratio %.2f (order %.2f)\n", mid ? "midpoint" : "euler", e1,
                e2, ratio, std::log2(ratio));
    if (mid) {
      EXPECT_GT(ratio, 3.3);
      EXPECT_LT(ratio, 4.8);
    } else {
      EXPECT_GT(ratio, 1.7);
      EXPECT_LT(ratio, 2.3);
    }
  }
}
