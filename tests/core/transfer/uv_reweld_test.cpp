// The re-weld after the UV repair (transfer/uv_reweld.h) on hand-made maps of
// a flat grid soup: copies of a vertex split on one chart are joined at the
// best common UV; a split that is a real cut (joining would fold or stretch
// its triangles) and copies on two charts are left bit for bit.
#include <gtest/gtest.h>

#include "soupuv/quality/uv_metrics.h"
#include "soupuv/transfer/uv_reweld.h"

#include "uv_grid_case.h"

using namespace soupuv;
using namespace soupuv::transfer;

namespace {

constexpr int kN = soupuv::testing::kGridCells;
constexpr double kScale = soupuv::testing::kGridUvScale;

Vec2 isometric(Vec3 p) { return soupuv::testing::grid_isometric_uv(p); }

struct Case : soupuv::testing::UvGridCase {
  double centroid_x(size_t t) const {
    return (soup.corner(t, 0).x + soup.corner(t, 1).x + soup.corner(t, 2).x) / 3;
  }
  // Moves the copies of grid vertex (x, y) held by triangles right of x.
  void split_vertex(double x, double y, Vec2 shift) {
    for (size_t t = 0; t < soup.triangles.size(); ++t)
      for (int k = 0; k < 3; ++k)
        if (norm(soup.corner(t, k) - Vec3{x, y, 0}) < 1e-9 && centroid_x(t) > x) uvs[t][k] = uvs[t][k] + shift;
  }
  quality::UvMetrics metrics() const {
    return quality::uv_metrics(soup, uvs, quality::edge_adjacency(weld, soup.triangles.size()));
  }
};

}  // namespace

TEST(UvReweld, SplitCopiesAreJoinedAtTheBestCommonUv) {
  Case c;
  c.split_vertex(4, 4, {0.3 * kScale, 0.1 * kScale});
  const auto before = c.uvs;
  ASSERT_LT(c.metrics().continuity_1texel, 1.0);
  const UvReweldResult r = reweld_uvs(c.soup, c.weld, c.chart, kScale, c.uvs);
  EXPECT_EQ(r.split_vertices, 1u);
  EXPECT_EQ(r.joined_vertices, 1u);
  EXPECT_EQ(r.joins, 1u);
  EXPECT_EQ(r.refused, 0u);
  // The unmoved copies sat at the isometric point, the energy's minimum: the
  // moved ones go back there, and nothing else moves.
  for (size_t t = 0; t < c.uvs.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      if (norm(c.soup.corner(t, k) - Vec3{4, 4, 0}) < 1e-9)
        EXPECT_LT(norm(c.uvs[t][k] - isometric({4, 4, 0})), 1e-12);
      else
        EXPECT_EQ(norm(c.uvs[t][k] - before[t][k]), 0.0);
    }
  EXPECT_EQ(r.moved_corners, 3u);  // the copies in the three triangles right of (4, 4)
  EXPECT_EQ(c.metrics().continuity_1texel, 1.0);
  EXPECT_EQ(c.metrics().flipped, 0u);
}

// The right half of the chart drawn 0.5 further right: a cut through the
// chart's interior. Joining a vertex on it at any candidate would stretch
// the triangles on one side across the gap, so nothing moves.
TEST(UvReweld, ARealCutIsLeftAlone) {
  Case c;
  for (size_t t = 0; t < c.soup.triangles.size(); ++t)
    if (c.centroid_x(t) > 4)
      for (auto& uv : c.uvs[t]) uv.x += 0.5;
  const auto before = c.uvs;
  const UvReweldResult r = reweld_uvs(c.soup, c.weld, c.chart, kScale, c.uvs);
  EXPECT_EQ(r.split_vertices, size_t(kN + 1));  // the vertices on x = 4
  EXPECT_EQ(r.joins, 0u);
  EXPECT_EQ(r.refused, size_t(kN + 1));
  EXPECT_EQ(r.moved_corners, 0u);
  for (size_t t = 0; t < c.uvs.size(); ++t)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(norm(c.uvs[t][k] - before[t][k]), 0.0);
}

// The same layout, but the right half is another chart: its copies are a
// seam's two sides, not a split, and are never compared.
TEST(UvReweld, CopiesOnTwoChartsAreNotJoined) {
  Case c;
  for (size_t t = 0; t < c.soup.triangles.size(); ++t)
    if (c.centroid_x(t) > 4) {
      c.chart[t] = 1;
      for (auto& uv : c.uvs[t]) uv.x += 0.02;
    }
  const UvReweldResult r = reweld_uvs(c.soup, c.weld, c.chart, kScale, c.uvs);
  EXPECT_EQ(r.split_vertices, 0u);
  EXPECT_EQ(r.moved_corners, 0u);
}

// Copies moved past their right neighbour fold their own triangles: the join
// takes the candidate that folds nothing (the left copies' UV), never the
// mean or the moved UV, which would fold one side or the other.
TEST(UvReweld, FoldedCopiesAreJoinedWhereNothingFolds) {
  Case c;
  c.split_vertex(4, 4, {2.5 * kScale, 0});  // beyond the vertex at (5, 4)
  ASSERT_GT(c.metrics().flipped, 0u);
  reweld_uvs(c.soup, c.weld, c.chart, kScale, c.uvs);
  EXPECT_EQ(c.metrics().flipped, 0u);
  EXPECT_EQ(c.metrics().continuity_1texel, 1.0);
}
