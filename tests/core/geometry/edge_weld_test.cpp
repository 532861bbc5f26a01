// geometry::weld_by_edges (geometry/edge_weld.cpp): against its slow twin (every edge
// pair compared, no grid), and against the true adjacency of a noisy soup
// (the shared teapot: tests/core/pipeline/edge_weld_teapot_test.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <set>

#include "adjacent_pair_set.h"
#include "soupuv/quality/uv_metrics.h"
#include "geometry/pair_matching.h"
#include "soupuv/geometry/weld.h"
#include "testing/shapes.h"

using namespace soupuv;
using namespace soupuv::geometry;

namespace {

using soupuv::testing::PairSet;
using soupuv::testing::pair_set;

// The slow twin: the edges whose endpoints both lie within the tolerance of a
// reversed edge of another triangle, over all pairs, matched greedily
// (cheapest pair first). Where every edge has one clear partner (a closed
// noisy sphere) the least-cost matching and the greedy agree, so the
// neighbour pairs must too.
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

// A pipe whose sides are narrower than the spread of a vertex's noisy
// copies (up to 2 sqrt(3) noise amplitudes apart), like a bolt's shank in
// the corpus's CAD soups (bracket: rows 28 x 1.9 amplitudes): each long
// edge has the next row's about as close as its own partner. Over the same
// candidates (every edge pair running back within the tolerance), the
// least-cost matching the weld uses (pair_matching.h) pairs more edges with
// their true partner than the greedy, cheapest pair first, the rule before
// it (measured: 1,007 of the 1,088 edges against 876).
TEST(EdgeWeld, RowsNarrowerThanTheNoiseKeepMoreOfTheirPartners) {
  const TriMesh mesh = shapes::pipe(0.02, 0.3, 64, 6);  // sides 2.0e-3 wide, 0.05 long
  const Soup exact = shapes::to_soup(mesh, 0.0, 5);
  const double diag = bounding_box(exact).diagonal();
  const double amplitude = 2.0e-3 / 1.9;  // the sides are 1.9 amplitudes wide
  const Soup soup = shapes::to_soup(mesh, amplitude / diag, 5);
  const double tolerance = 4 * amplitude;
  const uint32_t corners = uint32_t(3 * soup.triangles.size());
  auto next = [](uint32_t c) { return c - c % 3 + (c % 3 + 1) % 3; };
  // Original vertex of every corner: the exact soup's positions, welded.
  const geometry::Weld truth = geometry::weld_corners(exact, 0.0);
  std::vector<CandidatePair> candidates;
  for (uint32_t e = 0; e < corners; ++e)
    for (uint32_t f = e + 1; f < corners; ++f) {
      if (e / 3 == f / 3) continue;
      const double a = norm2(soup.corner(e / 3, int(e % 3)) - soup.corner(next(f) / 3, int(next(f) % 3)));
      const double b = norm2(soup.corner(next(e) / 3, int(next(e) % 3)) - soup.corner(f / 3, int(f % 3)));
      if (a <= tolerance * tolerance && b <= tolerance * tolerance) candidates.push_back({e, f, a + b});
    }
  auto is_true = [&](const CandidatePair& p) {
    return truth.corner_vertex[p.a] == truth.corner_vertex[next(p.b)] &&
           truth.corner_vertex[next(p.a)] == truth.corner_vertex[p.b];
  };
  size_t original_edges = 0;
  for (const auto& p : geometry::edge_adjacency(truth, exact.triangles.size())) original_edges += p.a != p.b;
  // The greedy.
  std::vector<uint32_t> order(candidates.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t x, uint32_t y) { return candidates[x].cost < candidates[y].cost; });
  std::vector<uint8_t> used(corners, 0);
  size_t greedy_true = 0;
  for (uint32_t i : order) {
    const CandidatePair& p = candidates[i];
    if (used[p.a] || used[p.b]) continue;
    used[p.a] = used[p.b] = 1;
    greedy_true += is_true(p);
  }
  // The least-cost matching.
  const std::vector<uint8_t> chosen = least_cost_matching(corners, candidates, 2 * tolerance * tolerance, 2);
  size_t least_true = 0;
  for (size_t i = 0; i < candidates.size(); ++i) least_true += chosen[i] && is_true(candidates[i]);
  EXPECT_GT(double(least_true), 1.1 * double(greedy_true))
      << "of " << original_edges << " edges: least-cost " << least_true << ", greedy " << greedy_true;
}
