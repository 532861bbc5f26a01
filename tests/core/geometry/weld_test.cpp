// Welding (soupuv/geometry/weld.h): the corner weld against its slow twin,
// the edge adjacency of a grid, and no triangle collapsed by a weld.
#include <gtest/gtest.h>

#include "soupuv/geometry/weld.h"
#include "grid_soup.h"
#include "testing/shapes.h"

using namespace soupuv;
using soupuv::testing::grid_soup;

TEST(Weld, MatchesBruteForce) {
  Soup s = grid_soup(12, 1e-3);
  const double tol = 4e-3;
  geometry::Weld w = geometry::weld_corners(s, tol);
  // Slow twin: O(n^2) pairs within the tolerance, closed transitively.
  size_t c = s.triangles.size() * 3;
  std::vector<uint32_t> label(c);
  for (size_t i = 0; i < c; ++i) label[i] = uint32_t(i);
  bool changed = true;
  while (changed) {
    changed = false;
    for (size_t i = 0; i < c; ++i)
      for (size_t j = 0; j < c; ++j) {
        if (norm(s.corner(i / 3, i % 3) - s.corner(j / 3, j % 3)) > tol) continue;
        uint32_t l = std::min(label[i], label[j]);
        if (label[i] != l || label[j] != l) { label[i] = label[j] = l; changed = true; }
      }
  }
  for (size_t i = 0; i < c; ++i)
    for (size_t j = i + 1; j < c; ++j)
      EXPECT_EQ(label[i] == label[j], w.corner_vertex[i] == w.corner_vertex[j]) << i << " " << j;
  EXPECT_EQ(w.vertex_count, 13u * 13u);
}

TEST(Weld, AdjacencyOfGridIsInteriorEdges) {
  const int n = 6;
  Soup s = grid_soup(n, 0);
  auto pairs = geometry::edge_adjacency(geometry::weld_corners(s, 0.0), s.triangles.size());
  // Interior edges of an n x n grid split into triangles: diagonals n^2 plus
  // 2 n (n - 1) grid-line edges.
  EXPECT_EQ(pairs.size(), size_t(n * n + 2 * n * (n - 1)));
  for (const auto& p : pairs)
    for (int i = 0; i < 2; ++i)
      EXPECT_EQ(norm(s.corner(p.a, p.a_corner[i]) - s.corner(p.b, p.b_corner[i])), 0.0);
}

TEST(Weld, NeverCollapsesATriangle) {
  Soup s;
  const double e = 1e-3;  // edge length, below the tolerance
  s.positions = {{0, 0, 0}, {e, 0, 0}, {0, e, 0},           // the tiny triangle
                 {0, 0, 0}, {e, 0, 0}, {0.5 * e, -e, 0}};  // its neighbour (shares an edge)
  s.triangles = {{0, 1, 2}, {3, 4, 5}};
  s.origins.resize(2);
  geometry::Weld w = geometry::weld_corners(s, 10 * e);
  EXPECT_NE(w.corner_vertex[0], w.corner_vertex[1]);
  EXPECT_NE(w.corner_vertex[0], w.corner_vertex[2]);
  EXPECT_NE(w.corner_vertex[1], w.corner_vertex[2]);
  EXPECT_NE(w.corner_vertex[3], w.corner_vertex[4]);
  // Nearest first: each corner of the shared edge joins its exact twin.
  EXPECT_EQ(w.corner_vertex[0], w.corner_vertex[3]);
  EXPECT_EQ(w.corner_vertex[1], w.corner_vertex[4]);
}
