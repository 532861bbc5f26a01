// Shared seeds (pipeline/shared_seeds.h): one seed per welded position,
// whose scale, the length its line's start offset is a fraction of, is the
// mean edge of the triangles that meet there.
#include <gtest/gtest.h>

#include <map>

#include "pipeline/shared_seeds.h"
#include "pipeline_support.h"

using namespace soupuv;

TEST(SharedSeeds, EachSeedsScaleIsTheMeanEdgeOfItsTriangles) {
  // A large and a small cube, apart: their seeds' scales differ by the size ratio.
  TriMesh small = shapes::cube(0.2, 2);
  shapes::translate(small, {3, 0, 0});
  const Soup soup = shapes::merge(shapes::to_soup(shapes::cube(2.0, 2)), shapes::to_soup(small));
  const geometry::Weld weld = geometry::weld_corners(soup, 1e-6);
  const field::Orientation orientation =
      field::consistent_orientation(soup, geometry::edge_adjacency(weld, soup.triangles.size()));
  const pipeline::SharedSeeds s = pipeline::shared_seeds(soup, weld, orientation);
  ASSERT_LT(s.seeds.size(), 3 * soup.triangles.size());
  std::map<uint32_t, std::pair<double, int>> sums;  // group -> edge sum, triangles
  for (size_t c = 0; c < s.group_of_corner.size(); ++c) {
    const size_t t = c / 3;
    const double edge = (norm(soup.corner(t, 1) - soup.corner(t, 0)) + norm(soup.corner(t, 2) - soup.corner(t, 1)) +
                         norm(soup.corner(t, 0) - soup.corner(t, 2))) / 3;
    auto& [sum, count] = sums[s.group_of_corner[c]];
    sum += edge;
    ++count;
  }
  double small_scale = 0, large_scale = 0;
  for (const auto& [g, sc] : sums) {
    EXPECT_NEAR(s.seeds[g].scale, sc.first / sc.second, 1e-12) << "group " << g;
    (s.seeds[g].position.x > 2 ? small_scale : large_scale) = std::max(
        s.seeds[g].position.x > 2 ? small_scale : large_scale, s.seeds[g].scale);
  }
  EXPECT_NEAR(large_scale / small_scale, 10.0, 1e-9);
}
