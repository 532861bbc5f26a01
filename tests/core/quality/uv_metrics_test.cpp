#include <gtest/gtest.h>

#include <random>

#include "soupuv/quality/uv_metrics.h"
#include "soupuv/geometry/weld.h"
#include "grid_soup.h"
#include "testing/shapes.h"

using namespace soupuv;
using soupuv::testing::grid_soup;
using namespace soupuv::quality;

namespace {


CornerUvs planar_uvs(const Soup& s, double scale) {
  CornerUvs uv(s.triangles.size());
  for (size_t t = 0; t < s.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      Vec3 p = s.corner(t, k);
      uv[t][k] = {0.05 + scale * p.x, 0.05 + scale * p.y};
    }
  return uv;
}

}  // namespace



TEST(UvMetrics, PlanarMapIsPerfect) {
  Soup s = grid_soup(10, 1e-3);
  auto adj = metric_adjacency(s, nullptr, 5e-3);
  UvMetrics m = uv_metrics(s, planar_uvs(s, 0.8), adj);
  EXPECT_EQ(m.coverage, 1.0);
  EXPECT_EQ(m.flipped, 0u);
  // Not exactly 1: the noise tilts triangles out of the projection plane.
  EXPECT_NEAR(m.stretch_l2, 1.0, 1e-4);
  EXPECT_EQ(m.continuity, 1.0);
  EXPECT_EQ(m.islands, 1u);
  EXPECT_NEAR(m.uv_per_length, 0.8, 1e-3);
  // The copies lie up to ~3.5e-3 apart (noise), i.e. > 1 texel at 1024 in UV:
  // the plain 1-texel figure sees them as cuts, the noise-aware one does not.
  EXPECT_LT(m.continuity_1texel, 0.5);
}

TEST(UvMetrics, AnisotropicScaleIsStretched) {
  Soup s = grid_soup(4, 0);
  CornerUvs uv = planar_uvs(s, 0.4);
  for (auto& t : uv)
    for (auto& p : t) p.y = 0.05 + 2 * (p.y - 0.05);  // 2:1 stretch
  UvMetrics m = uv_metrics(s, uv, metric_adjacency(s, nullptr, 0));
  // Singular values 1/0.4 and 1/0.8 with normalisation sqrt(2 * 0.16):
  // sqrt((6.25 + 1.5625) / 2) * sqrt(0.32) = 1.118...
  EXPECT_NEAR(m.stretch_l2, std::sqrt((6.25 + 1.5625) / 2) * std::sqrt(0.32), 1e-9);
}

// Hand-computed against Sander et al. 2001: the Jacobian goes from UV onto
// the surface, weighted by 3D area, times sqrt(sum A_uv / sum A_3d) (the
// map's own optimal scale, not the atlas's texel scale). Two unit right
// triangles: one mapped at UV scale 0.4, one squeezed 10x more across.
// Singular values (UV -> 3D): 2.5, 2.5 and 2.5, 25; UV areas 0.08, 0.008.
// L2 = sqrt((0.5 * 6.25 + 0.5 * (6.25 + 625) / 2) / 1 * 0.088) = 3.7633...
// The opposite direction (3D -> UV) would give 1.1697 instead.
TEST(UvMetrics, StretchIsSanderL2FromUvToSurface) {
  Soup s;
  s.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}, {3, 0, 0}, {2, 1, 0}};
  s.triangles = {{0, 1, 2}, {3, 4, 5}};
  s.origins.resize(2);
  CornerUvs uv = {{Vec2{0.05, 0.05}, Vec2{0.45, 0.05}, Vec2{0.05, 0.45}},
                  {Vec2{0.5, 0.05}, Vec2{0.9, 0.05}, Vec2{0.5, 0.09}}};
  const double expected = std::sqrt((0.5 * 6.25 + 0.5 * 315.625) * 0.088);
  UvMetrics m = uv_metrics(s, uv, {});
  EXPECT_NEAR(m.stretch_l2, expected, 1e-9);
  EXPECT_NEAR(m.stretch_l2, 3.76331, 1e-5);
  // The atlas's texel scale is for continuity only: the stretch is the same.
  UvMetricsOptions at_atlas_scale;
  at_atlas_scale.uv_per_length = 5;
  EXPECT_NEAR(uv_metrics(s, uv, {}, at_atlas_scale).stretch_l2, expected, 1e-9);
  // Uniformly rescaling the UVs changes nothing either.
  CornerUvs half = uv;
  for (auto& t : half)
    for (auto& p : t) p = p * 0.5;
  EXPECT_NEAR(uv_metrics(s, half, {}).stretch_l2, expected, 1e-9);
  // Companions: the area-weighted median is the good triangle's stretch
  // 2.5 * sqrt(0.088); the worst triangle (the "worst 1 %") carries
  // 157.8125 / 160.9375 of the squared sum.
  EXPECT_NEAR(m.stretch_median, 2.5 * std::sqrt(0.088), 1e-9);
  EXPECT_NEAR(m.stretch_l2_worst1pct_share, 157.8125 / 160.9375, 1e-9);
}

TEST(UvMetrics, SeamsFlipsAndOutOfRangeAreCounted) {
  Soup s = grid_soup(8, 0);
  auto adj = metric_adjacency(s, nullptr, 0);
  CornerUvs uv = planar_uvs(s, 0.8);
  // Move the right half of the grid away in UV: one seam along x = 0.5.
  for (size_t t = 0; t < s.triangles.size(); ++t) {
    Vec3 c = (s.corner(t, 0) + s.corner(t, 1) + s.corner(t, 2)) / 3.0;
    if (c.x > 0.5)
      for (auto& p : uv[t]) p.y += 0.1;
  }
  std::swap(uv[0][1], uv[0][2]);  // one flipped triangle
  for (auto& p : uv[5]) p.x += 1.0;  // one triangle outside [0,1]^2
  UvMetrics m = uv_metrics(s, uv, adj);
  EXPECT_EQ(m.flipped, 1u);
  EXPECT_NEAR(m.coverage, 1.0 - 3.0 / (3 * s.triangles.size()), 1e-12);
  EXPECT_LT(m.continuity, 1.0);
  EXPECT_GT(m.continuity, 0.8);
  EXPECT_GE(m.islands, 2u);
  EXPECT_LE(m.islands, 4u);
}

TEST(UvMetrics, PerTriangleChartsAreIslands) {
  Soup s = grid_soup(5, 0);
  CornerUvs uv(s.triangles.size());
  for (size_t t = 0; t < uv.size(); ++t) {
    double x = 0.02 * double(t % 40), y = 0.02 * double(t / 40);
    uv[t] = {Vec2{x, y}, Vec2{x + 0.01, y}, Vec2{x, y + 0.01}};
  }
  UvMetrics m = uv_metrics(s, uv, metric_adjacency(s, nullptr, 0));
  EXPECT_EQ(m.islands, s.triangles.size());
  EXPECT_EQ(m.continuity, 0.0);
}

TEST(UvMetrics, OriginalMeshGivesExactAdjacency) {
  TriMesh sphere = shapes::icosphere(1.0, 2);
  Soup noisy = shapes::to_soup(sphere, 1e-3, 7);
  Soup original;
  original.positions = sphere.vertices;
  for (auto f : sphere.faces) original.triangles.push_back({uint32_t(f[0]), uint32_t(f[1]), uint32_t(f[2])});
  auto adj = metric_adjacency(noisy, &original, 0);
  EXPECT_EQ(adj.size(), sphere.faces.size() * 3 / 2);
}

// A triangle smaller than the tolerance must keep three vertices: the weld
// never joins two corners of one triangle, even through a chain of twins.

// What the L2 stretch does with degenerate triangles (uv_metrics.h): a 3D
// sliver mapped faithfully costs nothing extra (its weight is its tiny 3D
// area and its map is an isometry); a zero-area 3D triangle is left out; a
// UV triangle collapsed to nothing is counted as flipped, not in the sum; but
// a sliver squeezed flatter in UV than in 3D is real distortion and shows.
TEST(UvMetrics, DegenerateTrianglesNeitherBlowUpNorHide) {
  Soup s = grid_soup(4, 0.0);
  const size_t grid = s.triangles.size();
  auto add = [&](Vec3 a, Vec3 b, Vec3 c) {
    const uint32_t i = uint32_t(s.positions.size());
    s.positions.insert(s.positions.end(), {a, b, c});
    s.triangles.push_back({i, i + 1, i + 2});
    s.origins.push_back({});
  };
  add({0.2, 0.2, 0}, {0.4, 0.2, 0}, {0.3, 0.2 + 1e-7, 0});  // 3D sliver, aspect 5e-6
  CornerUvs uv = planar_uvs(s, 0.5);
  UvMetrics faithful = uv_metrics(s, uv, {});
  EXPECT_EQ(faithful.flipped, 0u);
  EXPECT_NEAR(faithful.stretch_l2, 1.0, 1e-6);

  // The same sliver 100x flatter in UV than in 3D: stretch 100 on its own,
  // still tiny in the area-weighted sum, but nonzero.
  uv[grid][2].y = 0.05 + 0.5 * (0.2 + 1e-9);
  UvMetrics squeezed = uv_metrics(s, uv, {});
  EXPECT_GT(squeezed.stretch_l2, faithful.stretch_l2 + 1e-9);
  EXPECT_GT(squeezed.stretch_linf, 50.0);

  // A UV triangle of exactly zero area: flipped, out of the L2 sum.
  uv[grid][2] = uv[grid][0];
  UvMetrics collapsed = uv_metrics(s, uv, {});
  EXPECT_EQ(collapsed.flipped, 1u);
  EXPECT_NEAR(collapsed.stretch_l2, 1.0, 1e-6);

  // A zero-area 3D triangle: no weight, no map; neither flipped nor stretched
  // (its UV area still counts in the global scale: texture spent on nothing).
  add({0.5, 0.5, 0}, {0.6, 0.5, 0}, {0.7, 0.5, 0});
  uv.push_back({Vec2{0.3, 0.3}, Vec2{0.35, 0.3}, Vec2{0.3, 0.35}});
  uv[grid] = planar_uvs(s, 0.5)[grid];
  UvMetrics zero = uv_metrics(s, uv, {});
  EXPECT_EQ(zero.flipped, 0u);
  EXPECT_GE(zero.stretch_l2, 1.0);
  EXPECT_LT(zero.stretch_l2, 1.01);
}
