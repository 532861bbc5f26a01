#include <gtest/gtest.h>

#include "testing/shapes.h"
#include "soupuv/geometry/triangle_triangle.h"
#include "soupuv/field/intersect.h"

using namespace soupuv;
using namespace soupuv::field;

namespace {

// Fig. 19: a horizontal plane cut through by a vertical one, off the grid lines.
Soup crossing_planes(int n) {
  Soup a = shapes::to_soup(shapes::plane_grid({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, n));
  Soup b = shapes::to_soup(shapes::plane_grid({0.037, 0, 0.041}, {0, 1, 0}, {0, 0, 1}, n));
  return shapes::merge(a, b);
}

double total_area(const Soup& s) {
  double a = 0;
  for (size_t t = 0; t < s.triangles.size(); ++t) a += triangle_area(s, t);
  return a;
}

}  // namespace

TEST(Intersect, TriangleTriangleCases) {
  std::array<Vec3, 3> t{Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{0, 1, 0}};
  EXPECT_TRUE(geometry::triangles_intersect(t, {Vec3{0.2, 0.2, -1}, Vec3{0.2, 0.2, 1}, Vec3{0.3, 0.1, 0}}));
  EXPECT_FALSE(geometry::triangles_intersect(t, {Vec3{2, 2, -1}, Vec3{2, 2, 1}, Vec3{3, 2, 0}}));       // plane crossed, triangle missed
  EXPECT_FALSE(geometry::triangles_intersect(t, {Vec3{0, 0, 0.1}, Vec3{1, 0, 0.2}, Vec3{0, 1, 0.3}}));  // above
  EXPECT_FALSE(geometry::triangles_intersect(t, {Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{0, -1, 0}}));       // coplanar neighbour
}

TEST(Intersect, Fig19PlanesAreRefinedSoEveryPieceIsOnOneSide) {
  Soup soup = crossing_planes(10);
  IntersectionRefinement r = refine_intersections(soup, Progress::none());
  EXPECT_GT(r.intersecting_pairs, 0u);
  // The vertical plane x = 0.037 crosses one column of the horizontal grid
  // (2 triangles per cell, 10 cells) and the horizontal plane z = 0 one row of
  // the vertical grid.
  EXPECT_EQ(r.cut_triangles, 40u);
  EXPECT_GT(r.soup.triangles.size(), soup.triangles.size());
  EXPECT_NEAR(total_area(r.soup), total_area(soup), 1e-9);
  EXPECT_EQ(r.parent.size(), r.soup.triangles.size());
  for (size_t t = 0; t < r.soup.triangles.size(); ++t) {
    bool horizontal = r.parent[t] < soup.triangles.size() / 2;
    double lo = INFINITY, hi = -INFINITY;
    for (int k = 0; k < 3; ++k) {
      Vec3 p = r.soup.corner(t, k);
      double d = horizontal ? p.x - 0.037 : p.z;
      lo = std::min(lo, d);
      hi = std::max(hi, d);
    }
    EXPECT_FALSE(lo < -1e-9 && hi > 1e-9) << "refined triangle " << t << " still straddles";
  }
}

TEST(Intersect, NoiseCrossingsBetweenNeighboursAreNotRefined) {
  Soup soup = shapes::to_soup(shapes::icosphere(1.0, 3), 1e-3, 5);
  IntersectionRefinement r = refine_intersections(soup, Progress::none());
  EXPECT_EQ(r.cut_triangles, 0u);
  EXPECT_EQ(r.soup.triangles.size(), soup.triangles.size());
}

