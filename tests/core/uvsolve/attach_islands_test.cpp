// attach_small_islands: a small island joins its neighbour where it fits
// beside it, and stays apart where it would lap over it or is not small.
#include "uvsolve/attach_islands.h"

#include <gtest/gtest.h>

#include <cmath>

#include "soupuv/geometry/weld.h"

namespace soupuv {
namespace {

using uvsolve::detail::UvLayout;

Vec3 on_circle(double degrees) {
  const double a = degrees * M_PI / 180;
  return {std::cos(a), std::sin(a), 0};
}

// A flat fan of five 60-degree triangles around the origin (0..300
// degrees), one island mapped by its own x, y; and one more triangle, the
// wedge from 300 to `wedge_end` degrees, welded to the fan's last edge but
// its own island, mapped turned by 90 degrees and moved far away.
struct FanAndWedge {
  Soup soup;
  UvLayout layout;
  std::vector<geometry::AdjacentPair> pairs;
};

FanAndWedge fan_and_wedge(double wedge_end) {
  FanAndWedge f;
  auto add = [&](Vec3 a, Vec3 b, Vec3 c) {
    for (const Vec3& p : {a, b, c}) f.soup.positions.push_back(p);
    const uint32_t base = uint32_t(f.soup.positions.size() - 3);
    f.soup.triangles.push_back(Tri{base, base + 1, base + 2});
    f.soup.origins.push_back({});
  };
  const Vec3 o{0, 0, 0};
  for (int k = 0; k < 5; ++k) add(o, on_circle(60 * k), on_circle(60 * (k + 1)));
  add(o, on_circle(300), on_circle(wedge_end));

  UvLayout& L = f.layout;
  // Fan: vertex 0 the origin, 1 + k the point at 60 k degrees.
  L.uv.push_back({0, 0});
  for (int k = 0; k <= 5; ++k) {
    const Vec3 p = on_circle(60 * k);
    L.uv.push_back({p.x, p.y});
  }
  for (uint32_t k = 0; k < 5; ++k) L.corner_vertex.push_back({0, 1 + k, 2 + k});
  // Wedge: its own three vertices, turned by 90 degrees and moved by (10, 5).
  for (const Vec3& p : {o, on_circle(300), on_circle(wedge_end)}) L.uv.push_back(Vec2{-p.y + 10, p.x + 5});
  L.corner_vertex.push_back({7, 8, 9});
  L.island = {0, 0, 0, 0, 0, 1};
  L.island_count = 2;
  f.pairs = geometry::edge_adjacency(geometry::weld_corners(f.soup, 1e-9), f.soup.triangles.size());
  return f;
}

// The fan (area 2.17) is never small here; the wedge (0.32 at 340 degrees,
// 0.49 at 380) is below the limits the tests pass, unless said otherwise.
uvsolve::detail::AttachFigures attach(FanAndWedge& f, double max_area, double max_lap_area = 0) {
  return uvsolve::detail::attach_small_islands(f.soup, f.pairs, 1.0, 0.05, 1.25, max_area, max_lap_area,
                                               f.layout);
}

// Nearly the area the wedge to `wedge_end` degrees (> 360) laps over the
// fan's first triangle: the part of the wedge above the x axis, the
// triangle between the origin, the point at wedge_end and where the
// wedge's far edge (300 degrees to wedge_end) crosses the x axis. The fan's
// chord from 0 to 60 degrees clips a sliver of it off.
double wedge_lap(double wedge_end) {
  const Vec3 a = on_circle(300), b = on_circle(wedge_end);
  const double s = -a.y / (b.y - a.y);  // a + s (b - a) is on the x axis
  const double x = a.x + s * (b.x - a.x);
  const Vec3 c = on_circle(wedge_end);
  // The lap is the part of the wedge above the x axis: origin, (x, 0), c.
  return 0.5 * x * c.y;
}

TEST(AttachIslands, SmallIslandJoinsItsNeighbourAlongTheWeldedEdge) {
  FanAndWedge f = fan_and_wedge(340);
  const auto figures = attach(f, 1.0);
  EXPECT_EQ(figures.attached, 1u);
  const UvLayout& L = f.layout;
  ASSERT_EQ(L.island_count, 1u);
  // The welded corners are the fan's own vertices: the seam is gone.
  EXPECT_EQ(L.corner_vertex[5][0], 0u);
  EXPECT_EQ(L.corner_vertex[5][1], 6u);
  // Moved rigidly: its free corner lands where the plane puts it.
  const Vec2 far = L.uv[L.corner_vertex[5][2]];
  const Vec3 want = on_circle(340);
  EXPECT_NEAR(far.x, want.x, 1e-9);
  EXPECT_NEAR(far.y, want.y, 1e-9);
  for (size_t t = 0; t < L.corner_vertex.size(); ++t) EXPECT_GT(uvsolve::detail::signed_area2(L, t), 0) << t;
}

TEST(AttachIslands, IslandThatWouldLapOverItsNeighbourStaysApart) {
  // The wedge runs to 380 degrees: beside the fan's last edge it covers
  // the fan's first triangle.
  FanAndWedge f = fan_and_wedge(380);
  const auto figures = attach(f, 1.0);
  EXPECT_EQ(figures.attached, 0u);
  EXPECT_EQ(figures.refused_overlap, figures.attempts);
  EXPECT_EQ(f.layout.island_count, 2u);
  EXPECT_EQ(f.layout.corner_vertex[5][0], 7u);
}

TEST(AttachIslands, SliverLapWithinTheBudgetJoinsAndLargerStaysApart) {
  // Past 360 degrees by 3: the wedge laps the fan's first triangle by a
  // sliver (~0.025 of the wedge's 0.43).
  const double lap = wedge_lap(363);
  ASSERT_GT(lap, 0);
  {
    FanAndWedge f = fan_and_wedge(363);
    const auto figures = attach(f, 1.0, 0.9 * lap);
    EXPECT_EQ(figures.attached, 0u);
    EXPECT_EQ(f.layout.island_count, 2u);
  }
  FanAndWedge f = fan_and_wedge(363);
  const auto figures = attach(f, 1.0, 1.1 * lap);
  EXPECT_EQ(figures.attached, 1u);
  EXPECT_EQ(figures.attached_with_lap, 1u);
  EXPECT_LE(figures.lapped_area, lap);
  EXPECT_GT(figures.lapped_area, 0.95 * lap);
  EXPECT_EQ(f.layout.island_count, 1u);
}

TEST(AttachIslands, IslandAboveTheAreaLimitStaysApart) {
  FanAndWedge f = fan_and_wedge(340);
  // The wedge's area is sin(40 degrees) / 2 = 0.32.
  const auto figures = attach(f, 0.3);
  EXPECT_EQ(figures.candidates, 0u);
  EXPECT_EQ(f.layout.island_count, 2u);
}

}  // namespace
}  // namespace soupuv
