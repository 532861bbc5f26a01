// Halving an island for packing: two edge-connected halves of at least a
// third of the area each, cut where the island is narrowest, every corner
// keeping its UV, only the pairs across the cut lost.
#include "uvsolve/halve_island.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

namespace soupuv {
namespace {

using uvsolve::detail::UvLayout;

// A grid of nx x ny unit cells as one island (shared vertices), two
// triangles a cell.
UvLayout grid_island(int nx, int ny) {
  UvLayout L;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) L.uv.push_back(Vec2{double(i), double(j)});
  auto id = [nx](int i, int j) { return uint32_t(j * (nx + 1) + i); };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      L.corner_vertex.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      L.corner_vertex.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  L.island.assign(L.corner_vertex.size(), 0);
  L.island_count = 1;
  return L;
}

// Edges (vertex pairs) two triangles of the layout share.
size_t shared_edges(const UvLayout& L) {
  std::multiset<std::pair<uint32_t, uint32_t>> edges;
  for (const auto& t : L.corner_vertex)
    for (int k = 0; k < 3; ++k) edges.insert(std::minmax(t[k], t[(k + 1) % 3]));
  size_t n = 0;
  for (auto it = edges.begin(); it != edges.end(); it = edges.upper_bound(*it)) n += edges.count(*it) == 2;
  return n;
}

TEST(HalveIsland, LongGridIsCutAcrossItsLengthIntoTwoHalves) {
  const UvLayout before = grid_island(20, 6);
  UvLayout L = before;
  ASSERT_TRUE(uvsolve::detail::halve_island(L, 0));
  EXPECT_EQ(L.island_count, 2u);
  double area[2] = {0, 0};
  for (size_t t = 0; t < L.corner_vertex.size(); ++t) {
    ASSERT_LT(L.island[t], 2u);
    area[L.island[t]] += 0.5 * std::abs(uvsolve::detail::signed_area2(L, t));
    for (int k = 0; k < 3; ++k) {
      const Vec2 now = L.uv[L.corner_vertex[t][k]], was = before.uv[before.corner_vertex[t][k]];
      EXPECT_TRUE(now.x == was.x && now.y == was.y) << "corners keep their UVs";
    }
  }
  EXPECT_NEAR(area[0], 60.0, 3.0) << "about half the area each side";
  EXPECT_NEAR(area[1], 60.0, 3.0);
  // No vertex is shared by the two halves.
  std::vector<int> owner(L.uv.size(), -1);
  for (size_t t = 0; t < L.corner_vertex.size(); ++t)
    for (uint32_t v : L.corner_vertex[t]) {
      if (owner[v] < 0) owner[v] = int(L.island[t]);
      EXPECT_EQ(owner[v], int(L.island[t])) << "vertex " << v << " lies in both halves";
    }
  // Each half is one piece.
  for (uint32_t h = 0; h < 2; ++h) {
    std::vector<uint8_t> active(L.corner_vertex.size());
    for (size_t t = 0; t < active.size(); ++t) active[t] = L.island[t] == h;
    std::vector<uint32_t> component;
    EXPECT_EQ(uvsolve::detail::edge_components(L.corner_vertex, &active, component), 1u);
  }
  // The cut crosses the 6-cell width: it costs 6 to 8 shared edges (the
  // median line may step around a cell's diagonal), not the 20-cell length.
  const size_t lost = shared_edges(before) - shared_edges(L);
  EXPECT_GE(lost, 6u);
  EXPECT_LE(lost, 8u);
}

TEST(HalveIsland, ADumbbellIsCutThroughItsNeck) {
  // A 10 x 8 and a 6 x 8 block joined by a neck of 4 x 2 cells along the
  // bottom: a straight cut through the neck crosses two rows, through a
  // block eight (the area median lies in the larger block); the neck cut
  // leaves each side more than a third of the area.
  const UvLayout grid = grid_island(20, 8);
  UvLayout L;
  L.uv = grid.uv;
  for (size_t t = 0; t < grid.corner_vertex.size(); ++t) {
    const int cell = int(t / 2), i = cell % 20, j = cell / 20;
    if (i >= 10 && i < 14 && j >= 2) continue;
    L.corner_vertex.push_back(grid.corner_vertex[t]);
  }
  L.island.assign(L.corner_vertex.size(), 0);
  L.island_count = 1;
  const size_t edges_before = shared_edges(L);
  ASSERT_TRUE(uvsolve::detail::halve_island(L, 0));
  EXPECT_LE(edges_before - shared_edges(L), 6u) << "the cut crosses the neck";
  double area[2] = {0, 0};
  for (size_t t = 0; t < L.corner_vertex.size(); ++t)
    area[L.island[t]] += 0.5 * std::abs(uvsolve::detail::signed_area2(L, t));
  EXPECT_GE(area[0], (area[0] + area[1]) / 3);
  EXPECT_GE(area[1], (area[0] + area[1]) / 3);
}

TEST(HalveIsland, OneTriangleIsLeftAlone) {
  UvLayout L;
  L.uv = {Vec2{0, 0}, Vec2{1, 0}, Vec2{0, 1}};
  L.corner_vertex = {{0, 1, 2}};
  L.island = {0};
  L.island_count = 1;
  EXPECT_FALSE(uvsolve::detail::halve_island(L, 0));
  EXPECT_EQ(L.island_count, 1u);
  EXPECT_EQ(L.uv.size(), 3u);
}

TEST(HalveIsland, OtherIslandsAreUntouched) {
  UvLayout L = grid_island(4, 4);
  // A second island: the same grid moved away, its own vertices.
  const UvLayout other = grid_island(4, 4);
  const uint32_t base = uint32_t(L.uv.size());
  for (const Vec2& p : other.uv) L.uv.push_back(p + Vec2{10, 0});
  for (auto t : other.corner_vertex) {
    for (uint32_t& v : t) v += base;
    L.corner_vertex.push_back(t);
    L.island.push_back(1);
  }
  L.island_count = 2;
  const UvLayout before = L;
  ASSERT_TRUE(uvsolve::detail::halve_island(L, 1));
  EXPECT_EQ(L.island_count, 3u);
  for (size_t t = 0; t < 32; ++t) {
    EXPECT_EQ(L.island[t], 0u);
    EXPECT_EQ(L.corner_vertex[t], before.corner_vertex[t]);
  }
}

}  // namespace
}  // namespace soupuv
