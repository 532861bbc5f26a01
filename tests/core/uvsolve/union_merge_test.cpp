// Joining islands by flattening their union (union_merge.h): a flat sheet
// cut into two halves laid out apart is joined into one island with no
// flipped triangle; a sheet large enough that flattening the union would
// cost more than 2.5 times the soup's size in the budget's units (above the
// knee a flattening costs more per triangle) is left in two islands,
// untried; a sphere in two hemispheres, whose union is closed, becomes one
// island with half the equator left open (and stays in two without the
// slit).
#include "uvsolve/union_merge.h"

#include <gtest/gtest.h>

#include "two_islands.h"

namespace soupuv {
namespace {

using test::kScale;
using test::TwoIslands;

// The n x n sheet's cells left of the middle are island 0, the others 1.
TwoIslands halves(int n) {
  return test::two_islands(test::grid_sheet(n), [n](size_t t) { return uint32_t(2 * int(t / 2 / n) >= n); });
}

uvsolve::detail::UnionMergeFigures merge(TwoIslands& h, bool slit = true) {
  return uvsolve::detail::merge_by_reflattening(h.soup, kScale, h.pairs, /*cell=*/0.5, /*max_stretch=*/1.25,
                                                /*solve_iterations=*/10, /*attempts_per_island=*/4, slit,
                                                /*threads=*/1, h.layout);
}

TEST(UnionMerge, TwoHalvesOfASheetBecomeOneIslandWithoutFlips) {
  TwoIslands h = halves(30);  // 1,800 triangles: below the knee
  const auto f = merge(h);
  EXPECT_EQ(f.joined, 1u);
  EXPECT_EQ(h.layout.island_count, 1u);
  EXPECT_EQ(test::flipped_triangles(h.layout), 0u);
  EXPECT_DOUBLE_EQ(uvsolve::detail::kept_pair_share(h.pairs, h.layout), 1.0);
}

TEST(UnionMerge, AUnionCostingSeveralTimesTheSoupIsNotFlattened) {
  // 20,000 triangles: the union is the whole soup, and above the knee its
  // flattening counts 20,000 x sqrt(20,000 / 3,000) = 51,640 > 2.5 x 20,000.
  TwoIslands h = halves(100);
  const auto f = merge(h);
  EXPECT_EQ(f.attempts, 0u);
  EXPECT_EQ(f.joined, 0u);
  EXPECT_EQ(h.layout.island_count, 2u);
}

// The hemispheres of a 16 x 32 sphere: 32 pairs along the equator.
TwoIslands hemispheres() {
  Soup s = test::uv_sphere(16, 32);
  std::vector<uint32_t> island(s.triangles.size());
  for (size_t t = 0; t < s.triangles.size(); ++t) {
    double z = 0;
    for (uint32_t v : s.triangles[t]) z += s.positions[v].z;
    island[t] = z < 0;
  }
  return test::two_islands(std::move(s), [island](size_t t) { return island[t]; });
}

TEST(UnionMerge, TwoHalvesOfAClosedSurfaceBecomeOneIslandOpenAlongHalfTheirSeam) {
  TwoIslands h = hemispheres();
  ASSERT_EQ(test::seam_pairs(h.pairs, h.layout), 32u);
  const size_t pairs = h.pairs.size();
  const auto f = merge(h);
  EXPECT_EQ(f.joined, 1u);
  EXPECT_EQ(h.layout.island_count, 1u);
  EXPECT_EQ(test::flipped_triangles(h.layout), 0u);
  // Half the equator's pairs stay cut (the slit), the other half joined.
  const double kept = uvsolve::detail::kept_pair_share(h.pairs, h.layout);
  EXPECT_DOUBLE_EQ(kept * double(pairs), double(pairs - 16));
}

TEST(UnionMerge, AClosedUnionWithoutTheSlitIsRefused) {
  TwoIslands h = hemispheres();
  const auto f = merge(h, /*slit=*/false);
  EXPECT_EQ(f.joined, 0u);
  EXPECT_EQ(h.layout.island_count, 2u);
}

// The hemispheres with the two southern triangles below one equator edge
// left out: their union is a disk (a sphere with a small hole), and their
// seam a path of 31 pairs, not a loop.
TwoIslands hemispheres_with_a_hole() {
  Soup s = test::uv_sphere(16, 32);
  Soup kept;
  kept.positions = s.positions;
  std::vector<uint32_t> island;
  for (const Tri& t : s.triangles) {
    double z = 0;
    bool below_first_edge = true;
    for (uint32_t v : t) {
      const Vec3 p = s.positions[v];
      z += p.z;
      // Segments 0 and 1 of the equator and the ring below it.
      below_first_edge = below_first_edge && p.z <= 1e-9 && p.x > 0.95 && p.y >= -1e-9;
    }
    if (below_first_edge) continue;
    kept.triangles.push_back(t);
    island.push_back(z < 0);
  }
  kept.origins.resize(kept.triangles.size());
  return test::two_islands(std::move(kept), [island](size_t t) { return island[t]; });
}

TEST(UnionMerge, TwoHalvesOfANearlyClosedSurfaceAreJoinedWithPartOfTheirSeamOpen) {
  TwoIslands h = hemispheres_with_a_hole();
  ASSERT_EQ(h.soup.triangles.size(), test::uv_sphere(16, 32).triangles.size() - 2);
  ASSERT_EQ(test::seam_pairs(h.pairs, h.layout), 31u);
  const size_t pairs = h.pairs.size();
  const auto f = merge(h);
  EXPECT_EQ(f.joined, 1u);
  EXPECT_EQ(f.slit, 1u);
  EXPECT_EQ(h.layout.island_count, 1u);
  EXPECT_EQ(test::flipped_triangles(h.layout), 0u);
  const double kept = uvsolve::detail::kept_pair_share(h.pairs, h.layout);
  EXPECT_GT(kept * double(pairs), double(pairs - 31)) << "more of the seam joined than before";
}

}  // namespace
}  // namespace soupuv
