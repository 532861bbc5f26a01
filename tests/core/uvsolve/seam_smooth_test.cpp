// Seam smoothing: triangles welded to another island on two or three edges
// join it where their image there is sound, as it is (no vertex moves) or
// with the island's vertices around it relaxed.
#include "uvsolve/seam_smooth.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>

#include "soupuv/geometry/weld.h"

namespace soupuv {
namespace {

using uvsolve::detail::UvLayout;

// An n x n grid of unit cells as a soup (two triangles a cell: lower
// {(i,j), (i+1,j), (i+1,j+1)}, upper {(i,j), (i+1,j+1), (i,j+1)}) and its
// layout: the map (x, y) -> 0.01 (x, y), every island with its own copy of
// a grid point.
struct Grid {
  int n;
  Soup soup;
  UvLayout layout;
  std::vector<geometry::AdjacentPair> pairs;
  uint32_t lower(int i, int j) const { return uint32_t(2 * (j * n + i)); }
  uint32_t upper(int i, int j) const { return lower(i, j) + 1; }
};

Grid make_grid(int n, const std::function<uint32_t(uint32_t triangle)>& island_of) {
  Grid g{n, {}, {}, {}};
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      for (const auto& q : {std::array<std::array<int, 2>, 3>{{{i, j}, {i + 1, j}, {i + 1, j + 1}}},
                            std::array<std::array<int, 2>, 3>{{{i, j}, {i + 1, j + 1}, {i, j + 1}}}}) {
        Tri t;
        for (int k = 0; k < 3; ++k) {
          g.soup.positions.push_back(Vec3{double(q[k][0]), double(q[k][1]), 0});
          t[k] = uint32_t(g.soup.positions.size() - 1);
        }
        g.soup.triangles.push_back(t);
        g.soup.origins.push_back({});
      }
  const geometry::Weld weld = geometry::weld_corners(g.soup, 1e-9);
  g.pairs = geometry::edge_adjacency(weld, g.soup.triangles.size());
  std::map<std::pair<uint32_t, uint32_t>, uint32_t> vertex;  // (weld vertex, island) -> layout vertex
  g.layout.corner_vertex.resize(g.soup.triangles.size());
  g.layout.island.resize(g.soup.triangles.size());
  uint32_t islands = 0;
  for (uint32_t t = 0; t < g.soup.triangles.size(); ++t) {
    const uint32_t island = island_of(t);
    islands = std::max(islands, island + 1);
    g.layout.island[t] = island;
    for (int k = 0; k < 3; ++k) {
      auto [it, fresh] = vertex.try_emplace({weld.corner_vertex[3 * t + k], island}, uint32_t(g.layout.uv.size()));
      if (fresh) {
        const Vec3 p = g.soup.corner(t, k);
        g.layout.uv.push_back(Vec2{0.01 * p.x, 0.01 * p.y});
      }
      g.layout.corner_vertex[t][k] = it->second;
    }
  }
  g.layout.island_count = islands;
  return g;
}

size_t kept_pairs(const Grid& g) {
  size_t kept = 0;
  for (const auto& p : g.pairs)
    kept += g.layout.corner_vertex[p.a][p.a_corner[0]] == g.layout.corner_vertex[p.b][p.b_corner[0]] &&
            g.layout.corner_vertex[p.a][p.a_corner[1]] == g.layout.corner_vertex[p.b][p.b_corner[1]];
  return kept;
}

TEST(SeamSmooth, TeethOfAZigzagSeamJoinTheOtherSide) {
  // Island 0: the cells left of x = 2, plus three teeth in column 2: the
  // lower triangles of rows 0 (welded to island 1 on two edges, the third
  // on the grid's border) and 2 (on all three), and the upper triangle of
  // row 5 (on two, the third to island 0). Island 1: the rest.
  const int n = 8;
  Grid probe = make_grid(n, [](uint32_t) { return 0u; });
  const std::vector<uint32_t> teeth{probe.lower(2, 0), probe.lower(2, 2), probe.upper(2, 5)};
  Grid g = make_grid(n, [&](uint32_t t) {
    const int cell = int(t / 2), i = cell % n;
    return (i < 2 || std::find(teeth.begin(), teeth.end(), t) != teeth.end()) ? 0u : 1u;
  });
  const std::vector<std::array<uint32_t, 3>> corners_before = g.layout.corner_vertex;
  const UvLayout before = g.layout;
  const size_t kept_before = kept_pairs(g);
  const auto f = uvsolve::detail::smooth_seams(g.soup, g.pairs, 0.01, 0.05, 1.25, 0.0, g.layout);
  // A move may make a neighbour a candidate for a while (the upper
  // triangle of cell (2, 1) joins island 0 before the tooth above it
  // leaves, and goes back after): count the outcome, not the moves.
  EXPECT_GE(f.moved, 3u);
  for (uint32_t t : teeth) EXPECT_EQ(g.layout.island[t], 1u) << "tooth " << t;
  for (uint32_t t = 0; t < g.layout.island.size(); ++t) {
    if (std::find(teeth.begin(), teeth.end(), t) != teeth.end()) continue;
    EXPECT_EQ(g.layout.island[t], before.island[t]);
    EXPECT_EQ(g.layout.corner_vertex[t], corners_before[t]) << "only the teeth change vertices";
  }
  // No vertex moved: every corner keeps its UV.
  for (uint32_t t = 0; t < g.layout.island.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const Vec2 now = g.layout.uv[g.layout.corner_vertex[t][k]], was = before.uv[before.corner_vertex[t][k]];
      EXPECT_NEAR(now.x, was.x, 1e-15);
      EXPECT_NEAR(now.y, was.y, 1e-15);
    }
  // The teeth close 2, 3 and 2 pairs and open 0, 0 and 1.
  EXPECT_EQ(kept_pairs(g), kept_before + 2 + 3 + 1);
  EXPECT_EQ(g.layout.island_count, 2u);
}

TEST(SeamSmooth, AToothWhoseNotchIsFoldedJoinsWithTheNotchRelaxed) {
  const int n = 6;
  Grid probe = make_grid(n, [](uint32_t) { return 0u; });
  const uint32_t tooth = probe.lower(2, 2);
  Grid g = make_grid(n, [&](uint32_t t) { return (int(t / 2) % n < 2 || t == tooth) ? 0u : 1u; });
  // Island 1's copy of the tooth's corner (3, 3) is pulled across the
  // tooth's other corners: there the tooth would be flipped as it is.
  const uint32_t corner = g.layout.corner_vertex[probe.upper(2, 2)][1];  // (3, 3) in island 1
  g.layout.uv[corner] = Vec2{0.025, 0.02};
  const UvLayout before = g.layout;
  const size_t kept_before = kept_pairs(g);
  const auto f = uvsolve::detail::smooth_seams(g.soup, g.pairs, 0.01, 0.05, 1.25, 0.0, g.layout);
  EXPECT_GE(f.relaxed, 1u);
  EXPECT_EQ(g.layout.island[tooth], 1u);
  EXPECT_GT(kept_pairs(g), kept_before);
  // Island 1 holds no folded triangle (the pulled corner folded two of
  // its own; the relaxation opened them with the notch).
  for (uint32_t t = 0; t < g.layout.island.size(); ++t) {
    if (g.layout.island[t] != 1) continue;
    EXPECT_GT(uvsolve::detail::signed_area2(g.layout, t), 0.0) << "triangle " << t;
  }
  // Only island 1's vertices within two rings of the notch moved: the
  // corners of cells from column 5 on are where they were.
  for (int j = 0; j < n; ++j) {
    const uint32_t t = probe.upper(5, j);
    for (int k = 0; k < 3; ++k) {
      const Vec2 now = g.layout.uv[g.layout.corner_vertex[t][k]], was = before.uv[before.corner_vertex[t][k]];
      EXPECT_EQ(now.x, was.x);
      EXPECT_EQ(now.y, was.y);
    }
  }
}

TEST(SeamSmooth, AToothWhosePlaceTheIslandCoversElsewhereStays) {
  const int n = 6;
  Grid probe = make_grid(n, [](uint32_t) { return 0u; });
  const uint32_t tooth = probe.lower(2, 2), far = probe.lower(0, 5);
  // `far`, in island 0's columns, belongs to island 1 with its own
  // vertices (none of its grid points is island 1's elsewhere).
  Grid g = make_grid(n, [&](uint32_t t) {
    if (t == far) return 1u;
    return (int(t / 2) % n < 2 || t == tooth) ? 0u : 1u;
  });
  // Laid over the tooth's place in island 1, much larger than it.
  const auto& cv = g.layout.corner_vertex[far];
  g.layout.uv[cv[0]] = Vec2{0.0, 0.0};
  g.layout.uv[cv[1]] = Vec2{0.06, 0.0};
  g.layout.uv[cv[2]] = Vec2{0.06, 0.06};
  const auto f = uvsolve::detail::smooth_seams(g.soup, g.pairs, 0.01, 0.05, 1.25, 0.0, g.layout);
  EXPECT_GE(f.refused_overlap, 1u);
  EXPECT_EQ(g.layout.island[tooth], 0u);
}

}  // namespace
}  // namespace soupuv
