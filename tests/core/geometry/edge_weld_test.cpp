// geometry::weld_by_edges (geometry/edge_weld.cpp): against its slow twin (every edge
// pair compared, no grid), and against the true adjacency of a noisy soup
// (the shared teapot: tests/core/pipeline/edge_weld_teapot_test.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "adjacent_pair_set.h"
#include "soupuv/quality/uv_metrics.h"
#include "soupuv/geometry/weld.h"
#include "testing/shapes.h"

using namespace soupuv;
using namespace soupuv::geometry;

namespace {

using soupuv::testing::PairSet;
using soupuv::testing::pair_set;

// The slow twin: the edges whose endpoints both lie within the tolerance of a
// reversed edge of another triangle, over all pairs. Only the candidate
// search differs from the grid version (the greedy matching is the same
// rule), so the neighbour pairs must agree on a soup without the overlap
// and ambiguity cases: a closed noisy sphere.
PairSet slow_edge_pairs(const Soup& soup, double tolerance) {
  struct Match { double cost; uint32_t e, f; };
  const uint32_t corners = uint32_t(3 * soup.triangles.size());
  auto pos = [&](uint32_t c) { return soup.corner(c / 3, int(c % 3)); };
  auto next = [](uint32_t c) { return c - c % 3 + (c % 3 + 1) % 3; };
  std::vector<Match> all;
  for (uint32_t e = 0; e < corners; ++e)
    for (uint32_t f = e + 1; f < corners; ++f) {
      if (e / 3 == f / 3) continue;
      const double a = norm2(pos(e) - pos(next(f))), b = norm2(pos(next(e)) - pos(f));
      if (a <= tolerance * tolerance && b <= tolerance * tolerance) all.push_back({a + b, e, f});
    }
  std::sort(all.begin(), all.end(), [](const Match& x, const Match& y) { return x.cost < y.cost; });
  std::vector<uint8_t> used(corners, 0);
  PairSet s;
  for (const Match& m : all) {
    if (used[m.e] || used[m.f]) continue;
    used[m.e] = used[m.f] = 1;
    s.insert({std::min(m.e / 3, m.f / 3), std::max(m.e / 3, m.f / 3)});
  }
  return s;
}

}  // namespace

TEST(EdgeWeld, MatchesItsSlowTwinOnANoisySphere) {
  const TriMesh mesh = shapes::icosphere(1.0, 2);  // 320 triangles, edges ~0.2
  const Soup soup = shapes::to_soup(mesh, 3e-3, 3);  // noise: fraction of the diagonal
  const double tolerance = 0.05;
  const PairSet fast = pair_set(geometry::edge_adjacency(geometry::weld_by_edges(soup, tolerance), soup.triangles.size()));
  EXPECT_EQ(fast, slow_edge_pairs(soup, tolerance));
  EXPECT_EQ(fast.size(), 480u);  // every edge of the closed icosphere
}

TEST(EdgeWeld, RecoversANoisyTorusExactly) {
  const TriMesh mesh = shapes::torus_with(1.0, 0.5, 3200);
  const Soup soup = shapes::to_soup(mesh, 1e-3, 1);
  const Soup exact = shapes::to_soup(mesh, 0.0, 1);
  const double diag = bounding_box(soup).diagonal();
  const PairSet truth = pair_set(geometry::edge_adjacency(geometry::weld_corners(exact, 0.0), exact.triangles.size()));
  const PairSet got =
      pair_set(geometry::edge_adjacency(geometry::weld_by_edges(soup, 4e-3 * diag), soup.triangles.size()));
  EXPECT_EQ(got, truth);
}
