// The one closest point of a triangle (soupuv/geometry/closest_point.h):
// known distances in every Voronoi region, degenerate triangles, and the
// barycentric coordinates against a dense sampling of the triangle.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "soupuv/geometry/closest_point.h"

using namespace soupuv;
using namespace soupuv::geometry;

TEST(ClosestPoint, KnownDistances) {
  const Vec3 a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0};
  EXPECT_NEAR(point_triangle_distance({0.2, 0.2, 0.5}, a, b, c), 0.5, 1e-15);         // face
  EXPECT_NEAR(point_triangle_distance({-1, -1, 0}, a, b, c), std::sqrt(2.0), 1e-15);  // vertex
  EXPECT_NEAR(point_triangle_distance({-1, 0, 0}, a, b, c), 1.0, 1e-15);              // vertex
  EXPECT_NEAR(point_triangle_distance({0.5, -2, 0}, a, b, c), 2.0, 1e-15);            // edge
  EXPECT_NEAR(point_triangle_distance({1, 1, 0}, a, b, c), std::sqrt(0.5), 1e-15);    // hypotenuse
  // Degenerate triangles degrade to a segment and to a point.
  EXPECT_NEAR(point_triangle_distance({0.5, 1, 0}, a, b, b), 1.0, 1e-15);
  EXPECT_NEAR(point_triangle_distance({0, 0, 3}, a, a, a), 3.0, 1e-15);
}

TEST(ClosestPoint, BarycentricsRebuildThePointAndNoSampleIsCloser) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-2, 2);
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 a{u(rng), u(rng), u(rng)}, b{u(rng), u(rng), u(rng)};
    // Every fifth triangle is a needle (c on the line ab).
    const Vec3 c = trial % 5 == 0 ? a + 0.3 * (b - a) : Vec3{u(rng), u(rng), u(rng)};
    const Vec3 p{u(rng), u(rng), u(rng)};
    const ClosestPoint q = closest_point_on_triangle(p, a, b, c);
    const Vec3 rebuilt = q.bary[0] * a + q.bary[1] * b + q.bary[2] * c;
    EXPECT_LT(norm(rebuilt - q.point), 1e-12);
    for (double w : q.bary) EXPECT_GE(w, -1e-12);
    EXPECT_NEAR(q.bary[0] + q.bary[1] + q.bary[2], 1.0, 1e-12);
    const double d = norm(p - q.point);
    EXPECT_DOUBLE_EQ(point_triangle_distance(p, a, b, c), d);
    for (int i = 0; i <= 40; ++i)
      for (int j = 0; i + j <= 40; ++j) {
        const Vec3 s = a + (i / 40.0) * (b - a) + (j / 40.0) * (c - a);
        EXPECT_GE(norm(p - s), d - 1e-12);
      }
  }
}
