// Row nesting: islands side by side keep the gap (Euclidean, not by box)
// and sit no farther than it requires.
#include "uvsolve/nest_rows.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace soupuv {
namespace {

using uvsolve::detail::least_clear_shift;
using uvsolve::detail::RowNester;
using uvsolve::detail::RowTriangle;

// Distance from p to segment [a, b].
double point_segment(Vec2 p, Vec2 a, Vec2 b) {
  const Vec2 d = b - a;
  const double t = std::clamp(dot(p - a, d) / dot(d, d), 0.0, 1.0);
  return norm(p - (a + t * d));
}

bool inside(Vec2 p, const RowTriangle& t) {
  const double a = cross(t[1] - t[0], p - t[0]), b = cross(t[2] - t[1], p - t[1]), c = cross(t[0] - t[2], p - t[2]);
  return (a >= 0 && b >= 0 && c >= 0) || (a <= 0 && b <= 0 && c <= 0);
}

// An independent distance between two triangles: 0 if a corner of one is
// inside the other or two edges cross, else the least corner-edge distance.
double distance(const RowTriangle& p, const RowTriangle& q) {
  for (int k = 0; k < 3; ++k)
    if (inside(p[k], q) || inside(q[k], p)) return 0;
  double d = INFINITY;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const Vec2 a = p[i], b = p[(i + 1) % 3], c = q[j], e = q[(j + 1) % 3];
      const double s1 = cross(b - a, c - a), s2 = cross(b - a, e - a), s3 = cross(e - c, a - c), s4 = cross(e - c, b - c);
      if (s1 * s2 < 0 && s3 * s4 < 0) return 0;
      d = std::min({d, point_segment(a, c, e), point_segment(c, a, b)});
    }
  return d;
}

RowTriangle shifted(RowTriangle t, double s) {
  for (Vec2& p : t) p.x += s;
  return t;
}

TEST(NestRows, TurnedTriangleSitsCloserThanItsBox) {
  // An isosceles triangle 3 wide, 1.5 tall, and the same turned apex-down.
  const RowTriangle up{Vec2{0, 0}, Vec2{3, 0}, Vec2{1.5, 1.5}};
  const RowTriangle down{Vec2{0, 1.5}, Vec2{1.5, 0}, Vec2{3, 1.5}};
  // The slanted edges are parallel (x + y = 3 and x + y = 1.5 + s), so the
  // gap 2 holds from s = 1.5 + 2 sqrt(2) on; boxes side by side need 5.
  const double s = least_clear_shift(up, down, 2.0);
  EXPECT_NEAR(s, 1.5 + 2 * std::sqrt(2.0), 1e-9);
  EXPECT_NEAR(distance(up, shifted(down, s)), 2.0, 1e-9);
  // Two boxes: the same triangle upright needs its corner 2 from the apex
  // line's end, s = 3 + 2 at the base.
  EXPECT_NEAR(least_clear_shift(up, up, 2.0), 5.0, 1e-9);
}

TEST(NestRows, FarTrianglesDoNotConstrain) {
  const RowTriangle a{Vec2{0, 0}, Vec2{1, 0}, Vec2{0, 1}};
  const RowTriangle b{Vec2{0, 10}, Vec2{1, 10}, Vec2{0, 11}};
  EXPECT_EQ(least_clear_shift(a, b, 2.0), -INFINITY);
}

TEST(NestRows, RandomRowsKeepTheGapAndTouchIt) {
  // Random small triangles in boxes 0..w x 0..h, nested one after another:
  // every pair keeps the gap, and each island but the first is within a
  // hair of the gap from some earlier one (it could not sit closer).
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  const double gap = 0.7;
  RowNester nest(gap);
  std::vector<RowTriangle> placed;
  double last = 0;
  for (int k = 0; k < 200; ++k) {
    const double w = 0.5 + 3 * u(rng), h = 0.3 + 1.5 * u(rng);
    RowTriangle t{Vec2{0, u(rng) * h}, Vec2{w, u(rng) * h}, Vec2{u(rng) * w, u(rng) < 0.5 ? 0.0 : h}};
    const double s = nest.shift_for(&t, 1);
    EXPECT_GE(s, last - 1e-12);
    nest.add(&t, 1, w, s);
    const RowTriangle at = shifted(t, s);
    double nearest = INFINITY;
    for (const RowTriangle& p : placed) nearest = std::min(nearest, distance(p, at));
    if (!placed.empty() && s > last) {
      EXPECT_GE(nearest, gap - 1e-9) << k;
      EXPECT_LE(nearest, gap + 1e-9) << k;
    } else if (!placed.empty()) {
      EXPECT_GE(nearest, gap - 1e-9) << k;
    }
    placed.push_back(at);
    last = s;
  }
  EXPECT_GT(nest.length(), 0);
}

}  // namespace
}  // namespace soupuv
