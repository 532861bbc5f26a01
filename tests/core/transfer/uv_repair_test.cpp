// Local UV repair on hand-made maps of a flat grid soup: a vertex whose
// copies converged onto a neighbour (the sliver fans that converging field
// lines make), a folded vertex, and two charts that must not be merged.
#include <gtest/gtest.h>

#include <set>

#include "soupuv/quality/uv_metrics.h"
#include "soupuv/transfer/uv_repair.h"

#include "uv_grid_case.h"

using namespace soupuv;
using namespace soupuv::transfer;

namespace {

constexpr double kScale = soupuv::testing::kGridUvScale;

Vec2 isometric(Vec3 p) { return soupuv::testing::grid_isometric_uv(p); }

struct Case : soupuv::testing::UvGridCase {
  // Every copy of the grid vertex at (x, y) gets `uv`.
  void move_vertex(double x, double y, Vec2 uv) {
    for (size_t t = 0; t < soup.triangles.size(); ++t)
      for (int k = 0; k < 3; ++k)
        if (norm(soup.corner(t, k) - Vec3{x, y, 0}) < 1e-9) uvs[t][k] = uv;
  }
  quality::UvMetrics metrics() const { return quality::uv_metrics(soup, uvs, {}); }
};

// Grid vertices (as 3D points) used by any triangle that has a corner at p.
std::set<std::pair<int, int>> one_ring(const Soup& soup, Vec3 p) {
  std::set<std::pair<int, int>> ring;
  for (size_t t = 0; t < soup.triangles.size(); ++t) {
    bool touches = false;
    for (int k = 0; k < 3; ++k) touches |= norm(soup.corner(t, k) - p) < 1e-9;
    if (touches)
      for (int k = 0; k < 3; ++k) ring.insert({int(soup.corner(t, k).x), int(soup.corner(t, k).y)});
  }
  return ring;
}

}  // namespace

TEST(UvRepair, ConvergedCornersAreSpreadAgainWithoutMovingGoodVertices) {
  Case c;
  // The copies of (4, 4) converged almost onto (5, 4): its fan of triangles
  // is a set of slivers and folds.
  c.move_vertex(4, 4, isometric({5, 4, 0}) + Vec2{-1e-8, 2e-9});
  const auto before = c.metrics();
  ASSERT_GT(before.flipped, 0u);
  ASSERT_GT(before.stretch_l2, 2.0);
  const auto original = c.uvs;

  UvRepairResult r = repair_uvs(c.soup, c.weld, c.chart, kScale, c.uvs);
  const auto after = c.metrics();
  EXPECT_EQ(after.flipped, 0u);
  EXPECT_LT(after.stretch_l2, 1.0 + 1e-6);
  EXPECT_EQ(r.bad_triangles_after, 0u);
  EXPECT_EQ(r.repaired_patches, 1u);
  EXPECT_GE(r.repaired_vertices, 1u);

  // The isometric map is the energy's minimum, so the moved vertex goes
  // back to where it belongs; and only vertices of the bad triangles'
  // neighbourhood (one ring around (4, 4)) may move at all.
  const auto ring = one_ring(c.soup, {4, 4, 0});
  size_t moved = 0;
  for (size_t t = 0; t < c.soup.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const Vec3 p = c.soup.corner(t, k);
      if (!ring.count({int(p.x), int(p.y)})) {
        EXPECT_EQ(c.uvs[t][k].x, original[t][k].x);
        EXPECT_EQ(c.uvs[t][k].y, original[t][k].y);
      } else {
        EXPECT_LT(norm(c.uvs[t][k] - isometric(p)), 1e-3 * kScale) << p.x << " " << p.y;
        moved += c.uvs[t][k].x != original[t][k].x || c.uvs[t][k].y != original[t][k].y;
      }
    }
  EXPECT_GT(moved, 0u);
}

TEST(UvRepair, FoldedVertexIsUnfoldedFromATutteStart) {
  Case c;
  // (3, 3) reflected through (4, 4): its triangles fold over their neighbours,
  // and the mean of its copies (all at the same wrong place) folds too.
  c.move_vertex(3, 3, isometric({5.2, 4.9, 0}));
  ASSERT_GT(c.metrics().flipped, 0u);
  UvRepairResult r = repair_uvs(c.soup, c.weld, c.chart, kScale, c.uvs);
  EXPECT_EQ(c.metrics().flipped, 0u);
  EXPECT_EQ(r.failed_patches, 0u);
  EXPECT_LT(c.metrics().stretch_l2, 1.0 + 1e-6);
}

TEST(UvRepair, GoodMapIsLeftBitForBit) {
  Case c;
  const auto original = c.uvs;
  UvRepairResult r = repair_uvs(c.soup, c.weld, c.chart, kScale, c.uvs);
  EXPECT_EQ(r.bad_triangles, 0u);
  EXPECT_EQ(r.repaired_vertices, 0u);
  for (size_t t = 0; t < c.uvs.size(); ++t)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(norm(c.uvs[t][k] - original[t][k]), 0.0);
}

TEST(UvRepair, VerticesOnTwoChartsStayApart) {
  Case c;
  // Triangles right of x = 4 form chart 1, drawn 0.05 further right in UV:
  // the copies of a vertex on the seam belong to two UV vertices.
  for (size_t t = 0; t < c.soup.triangles.size(); ++t) {
    const double cx = (c.soup.corner(t, 0).x + c.soup.corner(t, 1).x + c.soup.corner(t, 2).x) / 3;
    if (cx > 4) {
      c.chart[t] = 1;
      for (auto& uv : c.uvs[t]) uv.x += 0.05;
    }
  }
  // Break a seam vertex on chart 0 only.
  for (size_t t = 0; t < c.soup.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k)
      if (c.chart[t] == 0 && norm(c.soup.corner(t, k) - Vec3{4, 4, 0}) < 1e-9)
        c.uvs[t][k] = isometric({3, 4, 0}) + Vec2{1e-4, 0};
  const auto original = c.uvs;
  repair_uvs(c.soup, c.weld, c.chart, kScale, c.uvs);
  EXPECT_EQ(c.metrics().flipped, 0u);
  for (size_t t = 0; t < c.soup.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      if (c.chart[t] == 1) {  // chart 1 was good: untouched, seam copies included
        EXPECT_EQ(c.uvs[t][k].x, original[t][k].x);
        EXPECT_EQ(c.uvs[t][k].y, original[t][k].y);
      }
    }
}

// A chart island of one grid cell (its two triangles on chart 1, the rest on
// chart 0) whose UVs are mirrored and shrunk: no corner is fixed, so the
// copies' mean keeps the fold, Tutte collapses everything to a point and
// unfolding has nothing to start from. The island start (one triangle laid
// down isometrically, the rest unfolded from it) or the untangling start
// (Garanzha et al.) gets it flip-free, each on its own; without both the
// patch fails.
TEST(UvRepair, MirroredChartIslandNeedsTheIslandOrUntanglingStart) {
  auto make = [] {
    Case c;
    for (size_t t = 0; t < c.soup.triangles.size(); ++t) {
      const Vec3 centre = (c.soup.corner(t, 0) + c.soup.corner(t, 1) + c.soup.corner(t, 2)) / 3.0;
      if (centre.x > 3 && centre.x < 4 && centre.y > 3 && centre.y < 4) {
        c.chart[t] = 1;
        for (int k = 0; k < 3; ++k) {
          const Vec3 p = c.soup.corner(t, k);
          c.uvs[t][k] = Vec2{0.7, 0.7} + 1e-3 * Vec2{-(p.x - 3.5), p.y - 3.5};  // mirrored in x
        }
      }
    }
    return c;
  };
  Case with = make();
  ASSERT_EQ(with.metrics().flipped, 2u);
  UvRepairResult r = repair_uvs(with.soup, with.weld, with.chart, kScale, with.uvs);
  EXPECT_EQ(with.metrics().flipped, 0u);
  EXPECT_EQ(r.failed_patches, 0u);

  for (bool island : {true, false}) {
    Case one = make();
    UvRepairOptions o;
    o.island_start = island;
    o.untangle = !island;
    UvRepairResult r1 = repair_uvs(one.soup, one.weld, one.chart, kScale, one.uvs, o);
    EXPECT_EQ(one.metrics().flipped, 0u) << "island start " << island;
    EXPECT_EQ(r1.failed_patches, 0u) << "island start " << island;
  }

  Case without = make();
  UvRepairOptions o;
  o.untangle = false;
  o.island_start = false;
  UvRepairResult r0 = repair_uvs(without.soup, without.weld, without.chart, kScale, without.uvs, o);
  EXPECT_EQ(without.metrics().flipped, 2u);
  EXPECT_EQ(r0.failed_patches, 1u);
}

// A triangle whose corner landed on another chart (corner_chart) keeps that
// chart's far-away UV; the repair moves the corner onto its triangle's chart
// next to its copies there. only_triangles limits which bad triangles seed
// patches: an empty list leaves the map as it is.
TEST(UvRepair, SplitCornerIsBroughtBackAndOnlyTrianglesLimitsTheSeeds) {
  auto make = [] {
    Case c;
    // Triangle 20's corner 1 landed on chart 1, far away in UV.
    c.uvs[20][1] = Vec2{0.95, 0.95};
    return c;
  };
  Case split = make();
  std::vector<int> corner_chart(3 * split.soup.triangles.size(), 0);
  corner_chart[3 * 20 + 1] = 1;
  const Vec3 p = split.soup.corner(20, 1);
  UvRepairOptions o;
  o.corner_chart = &corner_chart;
  const std::vector<uint32_t> none;
  o.only_triangles = &none;
  const auto untouched = split.uvs;
  repair_uvs(split.soup, split.weld, split.chart, kScale, split.uvs, o);
  for (size_t t = 0; t < untouched.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(split.uvs[t][k].x, untouched[t][k].x);
      EXPECT_EQ(split.uvs[t][k].y, untouched[t][k].y);
    }

  o.only_triangles = nullptr;
  UvRepairResult r = repair_uvs(split.soup, split.weld, split.chart, kScale, split.uvs, o);
  EXPECT_EQ(r.failed_patches, 0u);
  EXPECT_LT(norm(split.uvs[20][1] - isometric(p)), 0.02);  // next to its copies again
  EXPECT_EQ(split.metrics().flipped, 0u);
}
