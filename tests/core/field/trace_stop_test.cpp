// TraceOptions::stop_crossing: a line ends at the first step whose segment
// the test accepts, and up to there it is the line traced without the stop
// (the same steps, bit for bit), so the first crossing the transfer lands
// on is the same either way.
#include <gtest/gtest.h>

#include "soupuv/field/field.h"
#include "testing/shapes.h"

using namespace soupuv;
using namespace soupuv::field;

TEST(TraceStop, LinesEndAtTheirFirstCrossingAndAreTheUnstoppedLinesUpToIt) {
  const Soup soup = shapes::to_soup(shapes::icosphere(1.0, 2));
  ChargeOptions co;
  co.tolerance = 1e-5;
  const ChargeResult c = solve_charges(soup, co);
  TraceOptions o;
  o.max_steps = 200;
  o.step = 0.05;
  o.stop_radius = 3.0;
  const auto seeds = corner_seeds(soup);
  const FieldLines full = trace_field_lines(c, seeds, o);
  // A sphere of radius 1.4 around the centre: every radial line crosses it once.
  const double r = 1.4;
  o.stop_crossing = [r](Vec3 a, Vec3 b) { return (norm(a) < r) != (norm(b) < r); };
  TraceStats stats;
  const FieldLines stopped = trace_field_lines(c, seeds, o, Progress::none(), &stats);
  ASSERT_EQ(stopped.size(), full.size());
  EXPECT_EQ(stats.reached, stopped.size());
  size_t saved = 0;
  for (size_t i = 0; i < stopped.size(); ++i) {
    ASSERT_EQ(stopped.ends[i], LineEnd::reached) << "line " << i;
    const uint32_t b = stopped.offsets[i], e = stopped.offsets[i + 1];
    const uint32_t fb = full.offsets[i], fe = full.offsets[i + 1];
    ASSERT_LE(e - b, fe - fb);
    for (uint32_t k = 0; k < e - b; ++k)
      ASSERT_EQ(norm(stopped.points[b + k] - full.points[fb + k]), 0.0) << "line " << i << " point " << k;
    // The last segment is the first that crosses.
    EXPECT_GE(norm(stopped.points[e - 1]), r);
    EXPECT_LT(norm(stopped.points[e - 2]), r);
    saved += (fe - fb) - (e - b);
  }
  EXPECT_GT(saved, 0u);
}
