// Joining islands by flattening their union (union_merge.h): a flat sheet
// cut into two halves laid out apart is joined into one island with no
// flipped triangle; a sheet large enough that flattening the union would
// cost more than 2.5 times the soup's size in the budget's units (above the
// knee a flattening costs more per triangle) is left in two islands,
// untried.
#include "uvsolve/union_merge.h"

#include <gtest/gtest.h>

#include "soupuv/geometry/weld.h"

namespace soupuv {
namespace {

using uvsolve::detail::UvLayout;

constexpr double kScale = 64.0;  // UV units per unit length

struct Halves {
  Soup soup;
  UvLayout layout;
  std::vector<geometry::AdjacentPair> pairs;
};

// An n x n sheet in z = 0; the cells left of the middle are island 0,
// laid out isometrically, the others island 1, laid out the same way but
// moved far to the right (their own layout vertices), so the seam between
// them is open.
Halves halves(int n) {
  Halves h;
  auto id = [&](int i, int j) { return uint32_t(i * (n + 1) + j); };
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) h.soup.positions.push_back(Vec3{double(i) / n, double(j) / n, 0});
  const uint32_t np = uint32_t(h.soup.positions.size());
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const uint32_t island = 2 * i >= n;
      const uint32_t p = id(i, j), q = id(i + 1, j), r = id(i + 1, j + 1), w = id(i, j + 1);
      for (const Tri& t : {Tri{p, q, r}, Tri{p, r, w}}) {
        h.soup.triangles.push_back(t);
        h.soup.origins.push_back({});
        const uint32_t off = island * np;
        h.layout.corner_vertex.push_back({t[0] + off, t[1] + off, t[2] + off});
        h.layout.island.push_back(island);
      }
    }
  h.layout.island_count = 2;
  h.layout.uv.resize(2 * np);
  for (uint32_t v = 0; v < np; ++v) {
    const Vec3 x = h.soup.positions[v];
    h.layout.uv[v] = {kScale * x.x, kScale * x.y};
    h.layout.uv[np + v] = {1000 + kScale * x.x, kScale * x.y};
  }
  geometry::Weld weld;
  for (const Tri& t : h.soup.triangles)
    for (uint32_t v : t) weld.corner_vertex.push_back(v);
  weld.vertex_count = np;
  h.pairs = geometry::edge_adjacency(weld, h.soup.triangles.size());
  return h;
}

uvsolve::detail::UnionMergeFigures merge(Halves& h) {
  return uvsolve::detail::merge_by_reflattening(h.soup, kScale, h.pairs, /*cell=*/0.5, /*max_stretch=*/1.25,
                                                /*solve_iterations=*/10, /*attempts_per_island=*/4,
                                                /*threads=*/1, h.layout);
}

TEST(UnionMerge, TwoHalvesOfASheetBecomeOneIslandWithoutFlips) {
  Halves h = halves(30);  // 1,800 triangles: below the knee
  const auto f = merge(h);
  EXPECT_EQ(f.joined, 1u);
  EXPECT_EQ(h.layout.island_count, 1u);
  for (size_t t = 0; t < h.layout.corner_vertex.size(); ++t) {
    const auto& c = h.layout.corner_vertex[t];
    const Vec2 a = h.layout.uv[c[0]], b = h.layout.uv[c[1]], d = h.layout.uv[c[2]];
    EXPECT_GT(cross(b - a, d - a), 0) << "triangle " << t;
  }
}

TEST(UnionMerge, AUnionCostingSeveralTimesTheSoupIsNotFlattened) {
  // 20,000 triangles: the union is the whole soup, and above the knee its
  // flattening counts 20,000 x sqrt(20,000 / 3,000) = 51,640 > 2.5 x 20,000.
  Halves h = halves(100);
  const auto f = merge(h);
  EXPECT_EQ(f.attempts, 0u);
  EXPECT_EQ(f.joined, 0u);
  EXPECT_EQ(h.layout.island_count, 2u);
}

}  // namespace
}  // namespace soupuv
