// Sander stretch from the UV -> 3D Jacobian (soupuv/geometry/triangle_stretch.h):
// an isometry, a scaling, a shear's singular values, either UV orientation,
// and a collapsed UV triangle.
#include <gtest/gtest.h>

#include <cmath>

#include "soupuv/geometry/flatten_triangle.h"
#include "soupuv/geometry/triangle_stretch.h"

using namespace soupuv;
using namespace soupuv::geometry;

TEST(TriangleStretch, IsometryScalingAndShear) {
  const std::array<Vec3, 3> q = {Vec3{1, 2, 3}, Vec3{2, 2, 3}, Vec3{1, 2.5, 4}};
  const std::array<Vec2, 3> flat = flatten_triangle(q);
  EXPECT_NEAR(norm(flat[2] - flat[1]), norm(q[2] - q[1]), 1e-12);
  SanderStretch s;
  ASSERT_TRUE(sander_stretch(q[0], q[1], q[2], flat, s));
  EXPECT_NEAR(s.big, 1, 1e-12);
  EXPECT_NEAR(s.small, 1, 1e-12);
  EXPECT_NEAR(s.l2_squared, 1, 1e-12);
  // UV half the size: the map UV -> 3D doubles every length.
  const std::array<Vec2, 3> half = {0.5 * flat[0], 0.5 * flat[1], 0.5 * flat[2]};
  ASSERT_TRUE(sander_stretch(q[0], q[1], q[2], half, s));
  EXPECT_NEAR(s.big, 2, 1e-12);
  EXPECT_NEAR(s.small, 2, 1e-12);
  // Mirrored UVs: the same figures (the metrics count the flip separately).
  const std::array<Vec2, 3> mirrored = {Vec2{-flat[0].x, flat[0].y}, Vec2{-flat[1].x, flat[1].y},
                                        Vec2{-flat[2].x, flat[2].y}};
  ASSERT_TRUE(sander_stretch(q[0], q[1], q[2], mirrored, s));
  EXPECT_NEAR(s.big, 1, 1e-12);
  // A shear (x, y) -> (x + y, y) of the unit right triangle: singular values
  // of [1 1; 0 1]^-1 are the golden ratio's inverse and the golden ratio.
  const std::array<Vec3, 3> unit = {Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{0, 1, 0}};
  const std::array<Vec2, 3> sheared = {Vec2{0, 0}, Vec2{1, 0}, Vec2{1, 1}};
  ASSERT_TRUE(sander_stretch(unit[0], unit[1], unit[2], sheared, s));
  const double phi = 0.5 * (1 + std::sqrt(5.0));
  EXPECT_NEAR(s.big, phi, 1e-12);
  EXPECT_NEAR(s.small, 1 / phi, 1e-12);
  const TriangleStretch t = triangle_stretch(unit, sheared);
  EXPECT_NEAR(t.area3d, 0.5, 1e-15);
  EXPECT_NEAR(t.area_uv, 0.5, 1e-15);
  EXPECT_NEAR(t.gamma_max, phi, 1e-12);
  EXPECT_NEAR(t.l2_squared, 0.5 * (phi * phi + 1 / (phi * phi)), 1e-12);
}

TEST(TriangleStretch, CollapsedUvHasNoStretch) {
  const std::array<Vec3, 3> q = {Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{0, 1, 0}};
  const std::array<Vec2, 3> line = {Vec2{0, 0}, Vec2{1, 0}, Vec2{2, 0}};
  SanderStretch s;
  EXPECT_FALSE(sander_stretch(q[0], q[1], q[2], line, s));
  const TriangleStretch t = triangle_stretch(q, line);
  EXPECT_EQ(t.l2_squared, 0);
  EXPECT_EQ(t.gamma_max, 0);
}
