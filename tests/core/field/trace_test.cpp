// Field lines: radial on a sphere, never through the pipe of Fig. 15, and
// outward from every vertex of two disjoint closed parts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "soupuv/field/field.h"
#include "soupuv/field/triangle_integrals.h"
#include "testing/shapes.h"
#include "soupuv/geometry/segment_triangle.h"

using namespace soupuv;
using namespace soupuv::field;

namespace {
ChargeResult charge(const Soup& soup, int degree, double tol = 1e-5) {
  ChargeOptions o;
  o.tolerance = tol;
  o.quadrature_degree = degree;
  return solve_charges(soup, o);
}
Vec3 last(const FieldLines& l, size_t i) { return l.points[l.offsets[i + 1] - 1]; }
Vec3 first(const FieldLines& l, size_t i) { return l.points[l.offsets[i]]; }
}  // namespace

TEST(Trace, SphereLinesAreRadial) {
  Soup soup = shapes::to_soup(shapes::icosphere(1.0, 2));
  ChargeResult c = charge(soup, 4);
  TraceOptions o;
  o.max_steps = 200;
  o.step = 0.05;
  o.stop_radius = 2.0;
  FieldLines lines = trace_field_lines(c, corner_seeds(soup), o);
  ASSERT_EQ(lines.size(), soup.triangles.size() * 3);
  double worst = 0;
  for (size_t i = 0; i < lines.size(); ++i) {
    EXPECT_EQ(lines.ends[i], LineEnd::escaped);
    Vec3 v = first(lines, i), e = last(lines, i);
    // the end point lies on the ray through the vertex
    worst = std::max(worst, norm(cross(normalized(e), normalized(v))));
    EXPECT_GT(norm(e), 1.5);
  }
  std::printf("sphere: worst angle between end point and vertex direction %.2e rad\n", worst);
  EXPECT_LT(worst, 2e-2);
}

TEST(Trace, PipeLinesCrossNoTriangle) {
  // Fig. 15: an open pipe of 320 faces, degree-4 quadrature.
  Soup soup = shapes::to_soup(shapes::pipe(0.5, 2.0, 16, 10));
  ASSERT_EQ(soup.triangles.size(), 320u);
  ChargeResult c = charge(soup, 4);
  TraceOptions o;
  o.max_steps = 200;
  o.step = 0.05;
  FieldLines lines = trace_field_lines(c, corner_seeds(soup), o);
  size_t crossings = 0, escaped = 0;
  for (size_t i = 0; i < lines.size(); ++i) {
    if (lines.ends[i] == LineEnd::escaped) ++escaped;
    // skip the first segment (vertex -> start point), which touches the soup by construction
    for (uint32_t k = lines.offsets[i] + 1; k + 1 < lines.offsets[i + 1]; ++k)
      for (size_t t = 0; t < soup.triangles.size(); ++t)
        if (geometry::segment_crosses_triangle(lines.points[k], lines.points[k + 1], soup.corner(t, 0), soup.corner(t, 1),
                                        soup.corner(t, 2)))
          ++crossings;
  }
  std::printf("pipe: %zu lines, %zu escaped, %zu segment-triangle crossings\n", lines.size(), escaped, crossings);
  EXPECT_EQ(crossings, 0u);
  EXPECT_EQ(escaped, lines.size());
}

TEST(Trace, TwoClosedPartsTraceOutward) {
  TriMesh a = shapes::icosphere(0.5, 2), b = shapes::cube(0.8, 4);
  shapes::translate(b, {1.6, 0.2, 0});
  Soup soup = shapes::merge(shapes::to_soup(a), shapes::to_soup(b));
  ChargeResult c = charge(soup, 4);
  TraceOptions o;
  o.max_steps = 300;
  o.step = 0.04;
  FieldLines lines = trace_field_lines(c, corner_seeds(soup), o);
  const size_t na = a.faces.size();
  size_t inward = 0;
  for (size_t i = 0; i < lines.size(); ++i) {
    EXPECT_EQ(lines.ends[i], LineEnd::escaped) << "line " << i;
    size_t tri = lines.corner[i] / 3;
    Vec3 part_center = tri < na ? Vec3{0, 0, 0} : Vec3{1.6, 0.2, 0};
    Vec3 v = first(lines, i), x1 = lines.points[lines.offsets[i] + 1];
    if (dot(x1 - v, v - part_center) <= 0) ++inward;
  }
  EXPECT_EQ(inward, 0u);
}

TEST(Trace, StopBoxEndsLinesWhereTheyLeaveIt) {
  Soup soup = shapes::to_soup(shapes::icosphere(1.0, 1));
  ChargeResult c = charge(soup, 4);
  TraceOptions o;
  o.max_steps = 200;
  o.step = 0.05;
  o.stop_radius = 3.0;
  o.stop_box.add({-1.3, -1.3, -1.3});
  o.stop_box.add({1.3, 1.3, 1.3});
  FieldLines lines = trace_field_lines(c, corner_seeds(soup), o);
  auto outside = [](Vec3 p) { return std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}) > 1.3; };
  for (size_t i = 0; i < lines.size(); ++i) {
    ASSERT_EQ(lines.ends[i], LineEnd::escaped) << "line " << i;
    const uint32_t e = lines.offsets[i + 1];
    // Ends at its first point outside the box, well inside the stop sphere.
    EXPECT_TRUE(outside(lines.points[e - 1])) << "line " << i;
    EXPECT_FALSE(outside(lines.points[e - 2])) << "line " << i;
    EXPECT_LT(norm(lines.points[e - 1]), 1.3 * std::sqrt(3.0) + o.step);
  }
  // An empty box changes nothing: lines run on to the stop sphere.
  o.stop_box = Box3{};
  FieldLines far = trace_field_lines(c, corner_seeds(soup), o);
  for (size_t i = 0; i < far.size(); ++i) EXPECT_GT(norm(far.points[far.offsets[i + 1] - 1]), 3.0);
}

// FieldLineTracer: the probe is the tracer's own side choice, so a caller
// that probes, keeps or turns sides and then traces gets exactly the lines
// trace_field_lines gives for the kept ones, and a turned seed leaves on the
// other side.
TEST(Trace, ProbedSidesAreTheTracersOwnChoice) {
  // A sphere (one good side) beside an open sheet (both sides are good).
  TriMesh sheet = shapes::plane_grid({1.5, -0.5, -0.5}, {0, 1, 0}, {0, 0, 1}, 4);
  Soup soup = shapes::merge(shapes::to_soup(shapes::icosphere(0.5, 1)), shapes::to_soup(sheet));
  ChargeResult c = charge(soup, 4);
  TraceOptions o;
  o.max_steps = 60;
  o.step = 0.05;
  std::vector<TraceSeed> seeds = corner_seeds(soup);
  seeds[1].side = -1;  // a seed with its own side keeps it

  FieldLineTracer tracer(c, o);
  const std::vector<int> sides = tracer.probe_sides(seeds);
  ASSERT_EQ(sides.size(), seeds.size());
  EXPECT_EQ(sides[1], -1);
  for (int s : sides) EXPECT_TRUE(s == 1 || s == -1);
  const TraceStats probed = tracer.stats();
  EXPECT_EQ(probed.evaluations, 2 * (seeds.size() - 1));  // both sides of every side-0 seed
  EXPECT_EQ(probed.steps, 0u);

  // Seeds given their probed side trace the lines of the side-0 seeds.
  const FieldLines own = trace_field_lines(c, seeds, o);
  std::vector<TraceSeed> chosen = seeds;
  for (size_t i = 0; i < chosen.size(); ++i) chosen[i].side = sides[i];
  // Turn every sheet seed: its line must leave on the other side.
  const size_t sphere_corners = 3 * shapes::icosphere(0.5, 1).faces.size();
  for (size_t i = sphere_corners; i < chosen.size(); ++i) chosen[i].side = -sides[i];
  const FieldLines lines = tracer.trace(chosen);
  ASSERT_EQ(lines.size(), own.size());
  for (size_t i = 0; i < sphere_corners; ++i) {
    ASSERT_EQ(lines.offsets[i + 1] - lines.offsets[i], own.offsets[i + 1] - own.offsets[i]) << "line " << i;
    for (uint32_t j = 0; j < lines.offsets[i + 1] - lines.offsets[i]; ++j) {
      const Vec3 a = lines.points[lines.offsets[i] + j], b = own.points[own.offsets[i] + j];
      EXPECT_TRUE(a.x == b.x && a.y == b.y && a.z == b.z) << "line " << i << " point " << j;
    }
    EXPECT_EQ(lines.ends[i], own.ends[i]);
  }
  for (size_t i = sphere_corners; i < lines.size(); ++i) {
    const Vec3 v = first(lines, i), x1 = lines.points[lines.offsets[i] + 1];
    const Vec3 n = seeds[i].normal;
    EXPECT_EQ(dot(x1 - v, n) > 0 ? 1 : -1, chosen[i].side) << "line " << i;
    const Vec3 v_own = first(own, i), x1_own = own.points[own.offsets[i] + 1];
    EXPECT_EQ(dot(x1_own - v_own, n) > 0 ? 1 : -1, sides[i]) << "line " << i;
  }
  // The tracer's figures cover the probe and the trace.
  EXPECT_GT(tracer.stats().evaluations, probed.evaluations);
  EXPECT_GT(tracer.stats().steps, 0u);
}
