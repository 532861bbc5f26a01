// The island relaxation (transfer/island_relax.h) and its SLIM solver
// (transfer/slim.h): the solver against a plain slow gradient descent on a
// tiny mesh (its slow twin), a stretched strip relaxed toward L2 ~ 1, and the
// relaxation's guarantees on hand-made maps: continuous pairs stay
// continuous, nothing flips, no overlap is introduced, rejected islands keep
// their UVs bit for bit.
#include <gtest/gtest.h>

#include <cmath>

#include "soupuv/quality/uv_metrics.h"
#include "testing/shapes.h"
#include "soupuv/transfer/island_relax.h"
#include "transfer/slim.h"
#include "transfer/sym_dirichlet.h"
#include "uv_grid_case.h"

using namespace soupuv;
using namespace soupuv::transfer;

namespace {

// A w x h grid in the plane z = 0 (unit cells), as a soup (corners split).
TriMesh grid_mesh(int w, int h) {
  TriMesh m;
  for (int j = 0; j <= h; ++j)
    for (int i = 0; i <= w; ++i) m.vertices.push_back({double(i), double(j), 0});
  auto id = [w](int i, int j) { return j * (w + 1) + i; };
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      m.faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.faces.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

// The solvers' slow-twin problem: a 3 x 2 grid bent onto z = 0.4 x^2 at
// scale 0.1, started from the flat grid squeezed along x and sheared (every
// triangle positive), with two corners fixed (one would leave a rotation
// free: the energies are invariant to it).
struct BentGrid {
  std::vector<std::array<uint32_t, 3>> tris;
  std::vector<detail::RestTriangle> rest;
  std::vector<Vec2> start;
  std::vector<uint8_t> fixed;
};

BentGrid bent_grid() {
  const TriMesh m = grid_mesh(3, 2);
  BentGrid g;
  for (const auto& f : m.faces) g.tris.push_back({uint32_t(f[0]), uint32_t(f[1]), uint32_t(f[2])});
  std::vector<Vec3> p = m.vertices;
  for (Vec3& v : p) v.z = 0.4 * v.x * v.x;
  for (const auto& t : g.tris) g.rest.push_back(detail::rest_triangle(p[t[0]], p[t[1]], p[t[2]], 0.1, 1));
  for (const Vec3& v : m.vertices) g.start.push_back({0.2 + 0.05 * v.x + 0.01 * v.y, 0.2 + 0.1 * v.y});
  g.fixed.assign(g.start.size(), 0);
  g.fixed[0] = g.fixed[3] = 1;
  return g;
}

using Uvs = std::vector<std::array<Vec2, 3>>;

Uvs map_corners(const Soup& soup, Vec2 (*f)(Vec3)) {
  Uvs uvs(soup.triangles.size());
  for (size_t t = 0; t < uvs.size(); ++t)
    for (int k = 0; k < 3; ++k) uvs[t][k] = f(soup.corner(t, k));
  return uvs;
}

quality::UvMetrics metrics(const Soup& soup, const quality::Weld& weld, const Uvs& uvs) {
  return quality::uv_metrics(soup, uvs, quality::edge_adjacency(weld, soup.triangles.size()));
}

// The pairs continuous before (the metric's own test) must stay so.
void expect_continuous_pairs_kept(const Soup& soup, const quality::Weld& weld, const Uvs& before,
                                  const Uvs& after) {
  const double texel = 1.0 / 1024;
  const double scale = metrics(soup, weld, before).uv_per_length;
  for (const auto& p : quality::edge_adjacency(weld, soup.triangles.size())) {
    auto continuous = [&](const Uvs& uvs) {
      for (int i = 0; i < 2; ++i) {
        const double d_uv = norm(uvs[p.a][p.a_corner[i]] - uvs[p.b][p.b_corner[i]]);
        const double d_3d = norm(soup.corner(p.a, p.a_corner[i]) - soup.corner(p.b, p.b_corner[i]));
        if (!(d_uv <= texel + 2 * d_3d * scale)) return false;
      }
      return true;
    };
    if (continuous(before)) {
      EXPECT_TRUE(continuous(after)) << "pair " << p.a << "-" << p.b;
    }
  }
}

}  // namespace

// The slow twin: SLIM's result against a plain gradient descent on the same
// symmetric Dirichlet energy (per-vertex gradients from sym_dirichlet.h,
// backtracking, thousands of steps) on a tiny mesh with two corners fixed
// (one would leave a rotation free: the energy is invariant to it).
TEST(Slim, ReachesThePlainGradientDescentsMinimum) {
  const BentGrid grid = bent_grid();
  const auto& [tris, rest, start, fixed] = grid;

  std::vector<Vec2> fast = start;
  detail::SlimOptions so;
  so.max_iterations = 200;
  so.min_relative_decrease = 1e-12;
  const detail::SlimResult r = detail::slim_relax(tris, rest, fixed, fast, so);
  ASSERT_TRUE(r.started);
  EXPECT_LT(r.energy_after, r.energy_before);

  std::vector<Vec2> slow = start;
  double e = detail::mesh_energy(tris, rest, slow);
  for (int it = 0; it < 200000; ++it) {
    std::vector<Vec2> g(slow.size(), Vec2{0, 0});
    for (size_t t = 0; t < tris.size(); ++t) {
      const std::array<Vec2, 3> uv{slow[tris[t][0]], slow[tris[t][1]], slow[tris[t][2]]};
      for (int k = 0; k < 3; ++k) {
        Vec2 gk;
        double curvature;
        detail::gradient(rest[t], uv, k, gk, curvature);
        g[tris[t][k]] = g[tris[t][k]] + gk;
      }
    }
    g[0] = g[3] = {0, 0};
    double step = 1e-3;
    std::vector<Vec2> next(slow.size());
    double en = e;
    for (int h = 0; h < 40; ++h, step *= 0.5) {
      for (size_t v = 0; v < slow.size(); ++v) next[v] = slow[v] - g[v] * step;
      en = detail::mesh_energy(tris, rest, next);
      if (en < e) break;
    }
    if (!(en < e)) break;
    slow.swap(next);
    e = en;
  }
  EXPECT_NEAR(r.energy_after, e, 1e-4 * e);
  for (size_t v = 0; v < slow.size(); ++v) EXPECT_LT(norm(fast[v] - slow[v]), 1e-3) << v;
}

// The L2 descent's slow twin: a plain gradient descent on the same metric
// form F = S U (mesh_l2_form), with central finite-difference gradients, on
// a tiny bent mesh with two corners fixed; both end at the same F.
TEST(Slim, L2DescentReachesTheFiniteDifferenceDescentsMinimum) {
  const BentGrid grid = bent_grid();
  const auto& [tris, rest, start, fixed] = grid;
  // Some of "the rest of the map", held fixed.
  const double others_s = 0.02, others_u = 0.05;

  std::vector<Vec2> fast = start;
  detail::SlimOptions so;
  so.max_iterations = 2000;
  so.min_relative_decrease = 1e-14;
  const detail::SlimResult r = detail::l2_relax(tris, rest, fixed, fast, others_s, others_u, so);
  ASSERT_TRUE(r.started);
  EXPECT_LT(r.energy_after, r.energy_before);
  EXPECT_NEAR(r.energy_after, detail::mesh_l2_form(tris, rest, fast, others_s, others_u), 1e-12);

  std::vector<Vec2> slow = start;
  double e = detail::mesh_l2_form(tris, rest, slow, others_s, others_u);
  const double h = 1e-7;
  for (int it = 0; it < 100000; ++it) {
    std::vector<Vec2> g(slow.size(), Vec2{0, 0});
    for (size_t v = 0; v < slow.size(); ++v) {
      if (fixed[v]) continue;
      for (int axis = 0; axis < 2; ++axis) {
        auto plus = slow, minus = slow;
        (axis ? plus[v].y : plus[v].x) += h;
        (axis ? minus[v].y : minus[v].x) -= h;
        const double d = (detail::mesh_l2_form(tris, rest, plus, others_s, others_u) -
                          detail::mesh_l2_form(tris, rest, minus, others_s, others_u)) / (2 * h);
        (axis ? g[v].y : g[v].x) = d;
      }
    }
    double step = 1.0;
    std::vector<Vec2> next(slow.size());
    double en = e;
    for (int k = 0; k < 60; ++k, step *= 0.5) {
      for (size_t v = 0; v < slow.size(); ++v) next[v] = slow[v] - g[v] * step;
      en = detail::mesh_l2_form(tris, rest, next, others_s, others_u);
      if (en < e) break;
    }
    if (!(en < e) || (e - en) < 1e-15 * e) break;
    slow.swap(next);
    e = en;
  }
  EXPECT_NEAR(r.energy_after, e, 1e-4 * e);
  EXPECT_LE(r.energy_after, e * (1 + 1e-6));
}

// The gradient the slow twin uses, against finite differences.
TEST(Slim, EnergyGradientMatchesFiniteDifferences) {
  const detail::RestTriangle r =
      detail::rest_triangle({0, 0, 0}, {1, 0.2, 0.1}, {0.3, 0.9, -0.2}, 0.5, 1);
  const std::array<Vec2, 3> uv{Vec2{0.1, 0.1}, Vec2{0.5, 0.2}, Vec2{0.2, 0.6}};
  for (int k = 0; k < 3; ++k) {
    Vec2 g;
    double curvature;
    detail::gradient(r, uv, k, g, curvature);
    const double h = 1e-7;
    for (int axis = 0; axis < 2; ++axis) {
      auto plus = uv, minus = uv;
      (axis ? plus[k].y : plus[k].x) += h;
      (axis ? minus[k].y : minus[k].x) -= h;
      const double fd = (detail::energy(r, plus) - detail::energy(r, minus)) / (2 * h);
      EXPECT_NEAR(axis ? g.y : g.x, fd, 1e-5 * std::max(1.0, std::abs(fd)));
    }
  }
}

// A strip mapped stretched 2x along its length relaxes to an isometry.
TEST(IslandRelax, StretchedStripRelaxesTowardL2One) {
  const Soup soup = shapes::to_soup(grid_mesh(8, 2), 0.0);
  const quality::Weld weld = quality::weld_corners(soup, 1e-9);
  Uvs uvs = map_corners(soup, [](Vec3 p) { return Vec2{0.05 + 0.1 * p.x, 0.3 + 0.05 * p.y}; });
  const Uvs before = uvs;
  const double l2_before = metrics(soup, weld, uvs).stretch_l2;
  ASSERT_GT(l2_before, 1.1);
  const IslandRelaxResult r = relax_islands(soup, weld, uvs);
  EXPECT_EQ(r.islands, 1u);
  EXPECT_EQ(r.relaxed, 1u);
  const quality::UvMetrics m = metrics(soup, weld, uvs);
  EXPECT_LT(m.stretch_l2, 1.01);
  EXPECT_NEAR(r.stretch_l2_after, m.stretch_l2, 1e-9);
  EXPECT_NEAR(r.stretch_l2_before, l2_before, 1e-9);
  EXPECT_EQ(m.flipped, 0u);
  EXPECT_EQ(m.continuity, 1.0);
  EXPECT_LE(r.overlap_texels_after, r.overlap_texels_before);
  expect_continuous_pairs_kept(soup, weld, before, uvs);
}

// Two islands of one grid (a cut down the middle) each stretched: the cut
// stays a cut, every continuous pair stays continuous, nothing flips.
TEST(IslandRelax, CutsStayAndContinuousPairsStayContinuous) {
  soupuv::testing::UvGridCase c;
  // Stretch along x, and open a cut at x = 4 by moving the right half.
  for (size_t t = 0; t < c.uvs.size(); ++t) {
    const bool right = c.soup.corner(t, 0).x + c.soup.corner(t, 1).x + c.soup.corner(t, 2).x > 12;
    for (int k = 0; k < 3; ++k) {
      const Vec3 p = c.soup.corner(t, k);
      c.uvs[t][k] = {0.05 + 0.06 * p.x + (right ? 0.3 : 0), 0.05 + 0.1 * p.y};
    }
  }
  const Uvs before = c.uvs;
  const quality::UvMetrics m0 = metrics(c.soup, c.weld, before);
  ASSERT_LT(m0.continuity, 1.0);
  const IslandRelaxResult r = relax_islands(c.soup, c.weld, c.uvs);
  EXPECT_EQ(r.islands, 2u);
  EXPECT_GE(r.relaxed, 1u) << r.diagnostics().dump();
  const quality::UvMetrics m1 = metrics(c.soup, c.weld, c.uvs);
  EXPECT_EQ(m1.continuity, m0.continuity);
  EXPECT_EQ(m1.islands, m0.islands);
  EXPECT_EQ(m1.flipped, 0u);
  EXPECT_LT(m1.stretch_l2, m0.stretch_l2);
  EXPECT_LE(r.overlap_texels_after, r.overlap_texels_before);
  expect_continuous_pairs_kept(c.soup, c.weld, before, c.uvs);
}

// An island whose relaxed shape would grow over its neighbour is rejected
// (its UVs bit for bit), and the overlap does not grow.
TEST(IslandRelax, AnIslandThatWouldOverlapIsRejected) {
  // Left island: a 4 x 8 strip squeezed to half its width in x; right
  // island: an isometric 4 x 8 strip just right of it. Relaxed in place,
  // the left one doubles in width into the right one.
  soupuv::testing::UvGridCase c;
  for (size_t t = 0; t < c.uvs.size(); ++t) {
    const bool right = c.soup.corner(t, 0).x + c.soup.corner(t, 1).x + c.soup.corner(t, 2).x > 12;
    for (int k = 0; k < 3; ++k) {
      const Vec3 p = c.soup.corner(t, k);
      c.uvs[t][k] = right ? Vec2{0.251 + 0.1 * (p.x - 4), 0.05 + 0.1 * p.y}
                          : Vec2{0.05 + 0.05 * p.x, 0.05 + 0.1 * p.y};
    }
  }
  const Uvs before = c.uvs;
  IslandRelaxOptions o;
  o.min_island_triangles = 1;
  const IslandRelaxResult r = relax_islands(c.soup, c.weld, c.uvs, o);
  ASSERT_EQ(r.islands, 2u);
  EXPECT_EQ(r.rejected_overlap, 1u) << r.diagnostics().dump();
  EXPECT_EQ(r.overlap_texels_before, 0);
  EXPECT_EQ(r.overlap_texels_after, 0);
  for (size_t t = 0; t < c.uvs.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(c.uvs[t][k].x, before[t][k].x);
      EXPECT_EQ(c.uvs[t][k].y, before[t][k].y);
    }
}

// A folded triangle stays out of the energy: its corners do not move and no
// other triangle flips.
TEST(IslandRelax, FlippedTrianglesStayFixedAndNothingNewFlips) {
  soupuv::testing::UvGridCase c;
  for (auto& t : c.uvs)
    for (Vec2& p : t) p = {0.05 + (p.x - 0.05) * 0.7, p.y};  // squeezed: room to relax
  // Fold one interior vertex over its neighbours.
  const Vec3 folded{4, 4, 0};
  for (size_t t = 0; t < c.uvs.size(); ++t)
    for (int k = 0; k < 3; ++k)
      if (norm(c.soup.corner(t, k) - folded) < 1e-9) c.uvs[t][k] = c.uvs[t][k] + Vec2{0.09, 0.0};
  const quality::UvMetrics m0 = metrics(c.soup, c.weld, c.uvs);
  ASSERT_GT(m0.flipped, 0u);
  const IslandRelaxResult r = relax_islands(c.soup, c.weld, c.uvs);
  const quality::UvMetrics m1 = metrics(c.soup, c.weld, c.uvs);
  EXPECT_LE(m1.flipped, m0.flipped);
  EXPECT_EQ(m1.continuity, m0.continuity);
  EXPECT_LE(r.overlap_texels_after, r.overlap_texels_before);
}

// A second weld that joins distinct vertices (far too loose) chained with the
// first could put two corners of one triangle into one island vertex; such
// joins are refused, and whatever the loose weld does to the islands (here:
// distinct vertices joined, so the snapped islands fold and are rejected),
// nothing collapses or flips and no continuous pair is cut.
TEST(IslandRelax, ASecondLooseWeldNeverCollapsesATriangle) {
  soupuv::testing::UvGridCase c;
  for (auto& t : c.uvs)
    for (Vec2& p : t) p = {0.05 + (p.x - 0.05) * 0.7, p.y};
  const Uvs before = c.uvs;
  const quality::Weld loose = quality::weld_corners(c.soup, 1.5);
  IslandRelaxOptions o;
  o.also_weld = &loose;
  const IslandRelaxResult r = relax_islands(c.soup, c.weld, c.uvs, o);
  EXPECT_EQ(r.relaxed + r.rejected_flipped + r.rejected_no_gain + r.rejected_overlap +
                r.rejected_outside + r.skipped_fixed + r.skipped_small,
            r.islands);
  const quality::UvMetrics m = metrics(c.soup, c.weld, c.uvs);
  EXPECT_EQ(m.flipped, 0u);
  EXPECT_EQ(m.continuity, 1.0);
  expect_continuous_pairs_kept(c.soup, c.weld, before, c.uvs);
}
