// continuity_bound: the cube's 7 forced seams, none on smooth or open shapes.
#include <gtest/gtest.h>

#include "soupuv/quality/continuity_bound.h"
#include "testing/shapes.h"

using namespace soupuv;
using namespace soupuv::quality;

namespace {

ContinuityBound of(const TriMesh& mesh) {
  const Soup soup = shapes::to_soup(mesh, 0.0);
  const geometry::Weld weld = geometry::weld_corners(soup, 0.0);
  return continuity_bound(soup, weld, geometry::edge_adjacency(weld, soup.triangles.size()));
}

}  // namespace

TEST(ContinuityBound, CubeNeedsSevenSeamEdges) {
  const ContinuityBound b = of(shapes::cube(1.0, 1));
  EXPECT_EQ(b.pairs, 18u);
  EXPECT_EQ(b.cone_vertices, 8u);
  EXPECT_EQ(b.min_cut_edges, 7u);
  EXPECT_NEAR(b.bound, 11.0 / 18.0, 1e-12);
}

TEST(ContinuityBound, FinerCubeStillHasEightCones) {
  const ContinuityBound b = of(shapes::cube(1.0, 4));
  EXPECT_EQ(b.cone_vertices, 8u);
  EXPECT_EQ(b.min_cut_edges, 7u);
  EXPECT_GT(b.bound, 0.97);
}

TEST(ContinuityBound, SmoothSphereHasNoCones) {
  const ContinuityBound b = of(shapes::icosphere(1.0, 3));
  EXPECT_EQ(b.cone_vertices, 0u);
  EXPECT_EQ(b.bound, 1.0);
}

TEST(ContinuityBound, CoarseIcosahedronConesAreItsTwelveVertices) {
  // Angle sum 5 x 60 deg: a defect of pi/3 > pi/4 at each of 12 vertices.
  const ContinuityBound b = of(shapes::icosphere(1.0, 0));
  EXPECT_EQ(b.cone_vertices, 12u);
  EXPECT_EQ(b.min_cut_edges, 11u);
  EXPECT_NEAR(b.bound, 1 - 11.0 / 30.0, 1e-12);
}
