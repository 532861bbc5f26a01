// lay_sliver_stacks: a flat band of slivers thinner than the noise becomes one
// grid island with no flipped and no overlapping triangle, each true edge's
// copies within a couple of rows; a band the noise does not scramble, and an
// exact one, keep their islands.
#include "uvsolve/sliver_stack.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "soupuv/geometry/weld.h"

namespace soupuv {
namespace {

using uvsolve::detail::UvLayout;

struct Band {
  Soup soup;  // noisy
  std::vector<geometry::AdjacentPair> pairs;
  UvLayout layout;
  double row = 0;  // true row height
};

// A sheet of columns x strips quads, corner (i, j) at point(i, j), each
// quad split into two slivers; every corner then moved by uniform noise of
// amplitude `noise` per coordinate. The weld's pairs are the true ones;
// every triangle starts as its own counter-clockwise island.
template <class Point>
Band sheet(int columns, int strips, double row, double noise, unsigned seed, Point point) {
  Band b;
  b.row = row;
  Soup exact;
  auto add = [&](Vec3 x, Vec3 y, Vec3 z) {
    for (const Vec3& q : {x, y, z}) exact.positions.push_back(q);
    const uint32_t base = uint32_t(exact.positions.size() - 3);
    exact.triangles.push_back(Tri{base, base + 1, base + 2});
    exact.origins.push_back({});
  };
  for (int i = 0; i < columns; ++i)
    for (int j = 0; j < strips; ++j) {
      add(point(i, j), point(i, j + 1), point(i + 1, j));
      add(point(i + 1, j), point(i, j + 1), point(i + 1, j + 1));
    }
  b.pairs = geometry::edge_adjacency(geometry::weld_corners(exact, 1e-9), exact.triangles.size());
  b.soup = exact;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-noise, noise);
  for (Vec3& q : b.soup.positions) q += Vec3{u(rng), u(rng), u(rng)};
  for (size_t t = 0; t < exact.triangles.size(); ++t) {
    for (const Vec2& q : {Vec2{0, 0}, Vec2{1, 0}, Vec2{0, 1}}) b.layout.uv.push_back(Vec2{3.0 * double(t), 0} + q);
    const uint32_t base = uint32_t(3 * t);
    b.layout.corner_vertex.push_back({base, base + 1, base + 2});
    b.layout.island.push_back(uint32_t(t));
  }
  b.layout.island_count = uint32_t(exact.triangles.size());
  return b;
}

// A flat band: columns x rows quads of width 0.05 and height `row` in the
// x-z plane.
Band band(int columns, int rows, double row, double noise, unsigned seed) {
  return sheet(columns, rows, row, noise, seed, [&](int i, int k) { return Vec3{0.05 * i, 0, row * k}; });
}

// A thin bar along x: its cross-section a square of `rows` rows of height
// `row` a side, each side a band as above, the four sides welded at the
// bar's edges.
Band bar(int columns, int rows, double row, double noise, unsigned seed) {
  const double side = rows * row;
  auto loop = [&](int j) {  // point j of the cross-section's 4 rows points
    j %= 4 * rows;
    const double f = (j % rows) * row;
    switch (j / rows) {
      case 0: return Vec2{0, f};
      case 1: return Vec2{f, side};
      case 2: return Vec2{side, side - f};
      default: return Vec2{side - f, 0};
    }
  };
  return sheet(columns, 4 * rows, row, noise, seed, [&](int i, int j) {
    const Vec2 q = loop(j);
    return Vec3{0.05 * i, q.x, q.y};
  });
}

bool inside(const UvLayout& L, size_t t, Vec2 q) {
  const auto& v = L.corner_vertex[t];
  for (int k = 0; k < 3; ++k)
    if (cross(L.uv[v[(k + 1) % 3]] - L.uv[v[k]], q - L.uv[v[k]]) <= 0) return false;
  return true;
}

Vec2 centroid(const UvLayout& L, size_t t) {
  const auto& v = L.corner_vertex[t];
  return (1.0 / 3) * (L.uv[v[0]] + L.uv[v[1]] + L.uv[v[2]]);
}

TEST(SliverStack, ABandThinnerThanTheNoiseBecomesOneGridWithoutFlipsOrLaps) {
  // Rows 0.8 noise amplitudes tall: the weld cannot order them.
  const double noise = 0.0025;
  Band b = band(12, 30, 0.8 * noise, noise, 7);
  const auto f = uvsolve::detail::lay_sliver_stacks(b.soup, b.pairs, 1.0, b.layout);
  EXPECT_NEAR(f.noise, noise, 0.25 * noise);  // RMS copy distance / sqrt 2
  ASSERT_EQ(f.stacks, 1u);
  const size_t n = b.soup.triangles.size();
  EXPECT_GE(f.triangles, size_t(0.9 * n));
  for (size_t t = 0; t < n; ++t) EXPECT_GT(uvsolve::detail::signed_area2(b.layout, t), 0) << "triangle " << t;
  // One island holds the stack; no triangle's centroid lies in another's.
  std::vector<size_t> in_stack;
  std::vector<size_t> per_island(b.layout.island_count, 0);
  for (size_t t = 0; t < n; ++t) ++per_island[b.layout.island[t]];
  const uint32_t stack = uint32_t(std::max_element(per_island.begin(), per_island.end()) - per_island.begin());
  for (size_t t = 0; t < n; ++t)
    if (b.layout.island[t] == stack) in_stack.push_back(t);
  EXPECT_EQ(in_stack.size(), f.triangles);
  for (size_t i : in_stack)
    for (size_t j : in_stack)
      if (i != j) {
        EXPECT_FALSE(inside(b.layout, j, centroid(b.layout, i))) << i << " laps " << j;
      }
  // Each true edge's two copies of an endpoint stay within two rows of
  // the grid (rank errors of the noisy heights), most within one.
  double v_lo = INFINITY, v_hi = -INFINITY;
  for (size_t t : in_stack)
    for (uint32_t v : b.layout.corner_vertex[t]) v_lo = std::min(v_lo, b.layout.uv[v].y), v_hi = std::max(v_hi, b.layout.uv[v].y);
  const double grid_row = (v_hi - v_lo) / 30;
  size_t edges = 0, within_one = 0;
  for (const auto& p : b.pairs) {
    if (b.layout.island[p.a] != stack || b.layout.island[p.b] != stack) continue;
    for (int k = 0; k < 2; ++k) {
      const double gap = norm(b.layout.uv[b.layout.corner_vertex[p.a][p.a_corner[k]]] -
                              b.layout.uv[b.layout.corner_vertex[p.b][p.b_corner[k]]]);
      EXPECT_LE(gap, 2.5 * grid_row);
      ++edges;
      within_one += gap <= 1.01 * grid_row;
    }
  }
  EXPECT_GE(double(within_one), 0.9 * double(edges));
}

TEST(SliverStack, ABandTheNoiseDoesNotScrambleKeepsItsIslands) {
  const double noise = 0.0025;
  Band b = band(12, 30, 3 * noise, noise, 7);
  const UvLayout before = b.layout;
  const auto f = uvsolve::detail::lay_sliver_stacks(b.soup, b.pairs, 1.0, b.layout);
  EXPECT_EQ(f.stacks, 0u);
  EXPECT_EQ(b.layout.island, before.island);
  EXPECT_EQ(b.layout.corner_vertex, before.corner_vertex);
}

TEST(SliverStack, AnExactBandKeepsItsIslands) {
  Band b = band(12, 30, 0.002, 0, 7);
  const UvLayout before = b.layout;
  const auto f = uvsolve::detail::lay_sliver_stacks(b.soup, b.pairs, 1.0, b.layout);
  EXPECT_EQ(f.noise, 0);
  EXPECT_EQ(f.stacks, 0u);
  EXPECT_EQ(b.layout.island, before.island);
}

TEST(SliverStack, EachFlatSideOfAThinBarIsLaidAsItsOwnStack) {
  const double noise = 0.0025;
  Band b = bar(12, 12, 0.8 * noise, noise, 11);
  const auto f = uvsolve::detail::lay_sliver_stacks(b.soup, b.pairs, 1.0, b.layout);
  EXPECT_EQ(f.stacks, 4u);
  EXPECT_GE(f.triangles, size_t(0.8 * b.soup.triangles.size()));
  std::vector<std::vector<size_t>> by_island(b.layout.island_count);
  for (size_t t = 0; t < b.soup.triangles.size(); ++t) {
    EXPECT_GT(uvsolve::detail::signed_area2(b.layout, t), 0) << "triangle " << t;
    by_island[b.layout.island[t]].push_back(t);
  }
  for (const auto& island : by_island)
    for (size_t i : island)
      for (size_t j : island)
        if (i != j) {
        EXPECT_FALSE(inside(b.layout, j, centroid(b.layout, i))) << i << " laps " << j;
      }
}

TEST(SliverStack, AStackItsIslandsAlreadyHoldInOnePieceStays) {
  // The band as one island on the weld's own vertices: every pair inside
  // it kept, none for the grid to gain.
  const double noise = 0.0025;
  Band b = band(12, 30, 0.8 * noise, noise, 7);
  const geometry::Weld w = geometry::weld_corners(band(12, 30, 0.8 * noise, 0, 7).soup, 1e-9);
  b.layout.uv.assign(w.vertex_count, Vec2{0, 0});
  for (size_t t = 0; t < b.soup.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) b.layout.corner_vertex[t][k] = w.corner_vertex[3 * t + k];
    b.layout.island[t] = 0;
  }
  b.layout.island_count = 1;
  const UvLayout before = b.layout;
  const auto f = uvsolve::detail::lay_sliver_stacks(b.soup, b.pairs, 1.0, b.layout);
  EXPECT_EQ(f.stacks, 0u);
  EXPECT_EQ(f.kept_by_islands, 1u);
  EXPECT_EQ(b.layout.corner_vertex, before.corner_vertex);
}

}  // namespace
}  // namespace soupuv
