// The discontinuity breakdown: every pair uv_metrics calls discontinuous gets
// exactly one cause, and the causes follow what the transfer reported.
#include <gtest/gtest.h>

#include <cmath>

#include "soupuv/quality/discontinuity.h"
#include "soupuv/quality/uv_metrics.h"

using namespace soupuv;
using namespace soupuv::quality;

namespace {

// Four triangles in a row (a strip), split into a soup.
Soup strip() {
  Soup s;
  for (int i = 0; i < 4; ++i) {
    Vec3 a{double(i), 0, 0}, b{double(i + 1), 0, 0}, c{double(i), 1, 0}, d{double(i + 1), 1, 0};
    uint32_t base = uint32_t(s.positions.size());
    s.positions.insert(s.positions.end(), {a, b, d, a, d, c});
    s.triangles.push_back({base, base + 1, base + 2});
    s.triangles.push_back({base + 3, base + 4, base + 5});
  }
  s.origins.resize(s.triangles.size());
  return s;
}

}  // namespace

TEST(Discontinuity, EveryCutPairGetsOneCause) {
  Soup s = strip();
  const size_t n = s.triangles.size();
  CornerUvs uv(n);
  for (size_t t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k) uv[t][k] = {0.1 + 0.1 * s.corner(t, k).x, 0.1 + 0.1 * s.corner(t, k).y};
  auto pairs = geometry::edge_adjacency(geometry::weld_corners(s, 0.0), n);
  ASSERT_EQ(pairs.size(), 7u);
  CornerLanding land;
  land.missed.assign(3 * n, 0);
  land.first_chart.assign(3 * n, 0);
  land.final_chart.assign(3 * n, 0);
  // Pairs: (0,1) (2,3) (4,5) (6,7) within the cells, (0,3) (2,5) (4,7)
  // across. Triangle 3 moved far and its corners landed on chart 1 (split:
  // its pairs with 0 and 2); triangle 5 moved on the same chart (diverged:
  // with 2 and 4); triangle 7's corner 0 moved and its line missed (with 4, 6).
  for (int k = 0; k < 3; ++k) uv[3][k].x += 0.5, land.first_chart[9 + k] = 1, land.final_chart[9 + k] = 1;
  for (int k = 0; k < 3; ++k) uv[5][k].y += 0.3;
  uv[7][0].x += 0.2;
  land.missed[21] = 1;
  UvMetricsOptions mo;
  mo.uv_per_length = 0.1;
  UvMetrics m = uv_metrics(s, uv, pairs, mo);
  DiscontinuityBreakdown b = discontinuity_breakdown(s, uv, pairs, land, mo.texture_size, 0.1);
  EXPECT_EQ(b.pairs, pairs.size());
  EXPECT_EQ(b.discontinuous, size_t(std::llround((1 - m.continuity) * double(pairs.size()))));
  EXPECT_EQ(b.discontinuous, b.missed + b.split + b.corrected + b.diverged);
  EXPECT_EQ(b.discontinuous, 6u);
  EXPECT_EQ(b.split, 2u);
  EXPECT_EQ(b.diverged, 2u);
  EXPECT_EQ(b.missed, 2u);
  EXPECT_EQ(b.corrected, 0u);
  EXPECT_EQ(b.flipped, m.flipped);
}

// Diverged pairs once more by why, when the landing knows each corner's line
// (soup copies that started apart, or one line whose copies moved apart).
TEST(Discontinuity, DivergedPairsSayWhy) {
  Soup s = strip();
  const size_t n = s.triangles.size();
  CornerUvs uv(n);
  for (size_t t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k) uv[t][k] = {0.1 + 0.1 * s.corner(t, k).x, 0.1 + 0.1 * s.corner(t, k).y};
  const geometry::Weld weld = geometry::weld_corners(s, 0.0);
  auto pairs = geometry::edge_adjacency(weld, n);
  CornerLanding land;
  land.missed.assign(3 * n, 0);
  land.first_chart.assign(3 * n, 0);
  land.final_chart.assign(3 * n, 0);
  land.line = weld.corner_vertex;  // copies share a line ...
  for (int k = 0; k < 3; ++k) land.line[3 + k] = 100 + k;  // ... but triangle 1 has its own
  for (int k = 0; k < 3; ++k) uv[1][k].y += 0.3;  // its lines went elsewhere: pair (0,1)
  for (int k = 0; k < 3; ++k) uv[7][k].y += 0.3;  // one line, apart anyway: (4,7), (6,7)
  for (int k = 0; k < 3; ++k) uv[5][k].x += 0.3;  // moved after landing: (2,5), (4,5)
  DiscontinuityBreakdown b = discontinuity_breakdown(s, uv, pairs, land, 1024, 0.1);
  EXPECT_EQ(b.diverged, 5u);
  EXPECT_EQ(b.diverged_apart_lines, 1u);
  EXPECT_EQ(b.diverged_one_line, 4u);
  // Without the optional data the split is not made.
  land.line.clear();
  b = discontinuity_breakdown(s, uv, pairs, land, 1024, 0.1);
  EXPECT_EQ(b.diverged, 5u);
  EXPECT_EQ(b.diverged_apart_lines + b.diverged_one_line, 0u);
}

// A UV sliver carries the squared L2 stretch sum; the worst-1 % breakdown puts
// it down to what its corners saw, and its share agrees with uv_metrics'.
TEST(Discontinuity, WorstStretchTrianglesGetACause) {
  Soup s = strip();
  const size_t n = s.triangles.size();
  CornerUvs uv(n);
  for (size_t t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k) uv[t][k] = {0.1 + 0.1 * s.corner(t, k).x, 0.1 + 0.1 * s.corner(t, k).y};
  uv[6][2].y = 0.101;  // triangle 6's third corner nearly onto its first edge
  auto pairs = geometry::edge_adjacency(geometry::weld_corners(s, 0.0), n);
  CornerLanding land;
  land.missed.assign(3 * n, 0);
  land.first_chart.assign(3 * n, 0);
  land.final_chart.assign(3 * n, 0);
  UvMetrics m = uv_metrics(s, uv, pairs);
  DiscontinuityBreakdown b = discontinuity_breakdown(s, uv, pairs, land, 1024, m.uv_per_length);
  ASSERT_EQ(b.worst_stretch_triangles, 1u);  // 1 % of 8, at least one
  EXPECT_EQ(b.worst_stretch_one_chart, 1u);
  EXPECT_NEAR(b.worst_stretch_share_one_chart, m.stretch_l2_worst1pct_share, 1e-12);
  EXPECT_GT(b.worst_stretch_share_one_chart, 0.9);
  land.final_chart[3 * 6 + 2] = 1;  // §8 moved the sliver's corner
  b = discontinuity_breakdown(s, uv, pairs, land, 1024, m.uv_per_length);
  EXPECT_EQ(b.worst_stretch_corrected, 1u);
  EXPECT_EQ(b.worst_stretch_one_chart, 0u);
}
