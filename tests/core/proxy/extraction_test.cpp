// Marching cubes (asymptotic decider) and our short-edge collapse against
// independent measurements: topology checks, the generalized winding number
// at every grid corner (the slow twin of "the surface separates inside from
// outside corners"), and topology invariants before and after collapsing.
#include <gtest/gtest.h>

#include <omp.h>

#include <cmath>
#include <random>

#include "soupuv/proxy/collapse_short_edges.h"
#include "soupuv/proxy/components.h"
#include "soupuv/proxy/lift_to_offset.h"
#include "soupuv/proxy/marching_cubes.h"
#include "soupuv/proxy/marching_tetrahedra.h"
#include "soupuv/proxy/mesh_checks.h"
#include "soupuv/proxy/narrow_band.h"
#include "soupuv/geometry/distance_bvh.h"
#include "testing/shapes.h"

namespace soupuv::proxy {
namespace {

double winding_number(const TriMesh& m, Vec3 p) {
  double sum = 0;
  for (const auto& f : m.faces) {
    Vec3 a = m.vertices[f[0]] - p, b = m.vertices[f[1]] - p, c = m.vertices[f[2]] - p;
    double la = norm(a), lb = norm(b), lc = norm(c);
    double num = dot(a, cross(b, c));
    double den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
    sum += 2 * std::atan2(num, den);
  }
  return sum / (4 * M_PI);
}

// A band of n^3 cells with random corner values (outside on the border so the
// level set stays in the grid); `zeros` adds exact zeros (the f == 0 rule).
NarrowBand random_band(int n, unsigned seed, bool zeros) {
  NarrowBand band;
  band.cell = 1.0;
  band.dims = {n, n, n};
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<std::pair<uint64_t, double>> corners;
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        bool border = i == 0 || j == 0 || k == 0 || i == n || j == n || k == n;
        double f = border ? 1.0 : (zeros && rng() % 7 == 0 ? 0.0 : u(rng));
        corners.push_back({grid_key(i, j, k), f});
      }
  std::sort(corners.begin(), corners.end());
  for (auto& [key, f] : corners) {
    band.corner_keys.push_back(key);
    band.corner_values.push_back(f);
  }
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) band.cells.push_back(grid_key(i, j, k));
  std::sort(band.cells.begin(), band.cells.end());
  return band;
}

void expect_closed_manifold(const TriMesh& mesh) {
  Topology t = check_topology(mesh);
  EXPECT_TRUE(t.closed);
  EXPECT_TRUE(t.oriented);
  EXPECT_TRUE(t.manifold);
  EXPECT_EQ(t.degenerate_faces, 0u);
}

// Random signs make every face and cube configuration occur, ambiguous faces
// on both sides of the decider included.
TEST(ProxyExtraction, MarchingCubesIsClosedManifoldForRandomSigns) {
  for (unsigned seed : {1u, 2u, 3u, 4u}) {
    SCOPED_TRACE(seed);
    NarrowBand band = random_band(10, seed, seed % 2 == 0);
    TriMesh mesh = marching_cubes(band, Progress::none());
    ASSERT_GT(mesh.faces.size(), 500u);
    expect_closed_manifold(mesh);
    EXPECT_GT(signed_volume(mesh), 0);
  }
}

// The surface separates the corners: winding number 1 around every inside
// corner, 0 around every outside one (so it is also outward-oriented).
TEST(ProxyExtraction, MarchingCubesSeparatesInsideFromOutsideCorners) {
  NarrowBand band = random_band(7, 11, false);
  TriMesh mesh = marching_cubes(band, Progress::none());
  size_t wrong = 0;
  for (size_t n = 0; n < band.corner_keys.size(); ++n) {
    double w = winding_number(mesh, band.corner_position(band.corner_keys[n]));
    double expected = band.corner_values[n] < 0 ? 1.0 : 0.0;
    wrong += std::fabs(w - expected) > 1e-6;
  }
  EXPECT_EQ(wrong, 0u);
}

TEST(ProxyExtraction, MarchingCubesMakesFewerTrianglesThanTetrahedra) {
  Soup soup = shapes::to_soup(shapes::icosphere(1.0, 3));
  geometry::DistanceBvh bvh(soup);
  // Unpruned, so the cavity's shell is there too: two shells to compare.
  NarrowBand band = build_narrow_band(bvh, bounding_box(soup), 0.1, 0.04, Progress::none(), false);
  TriMesh cubes = marching_cubes(band, Progress::none());
  TriMesh tets = marching_tetrahedra(band, Progress::none());
  expect_closed_manifold(cubes);
  // Two spheres: around the soup and the cavity d = o inside it.
  EXPECT_EQ(check_topology(cubes).euler(), 4);
  EXPECT_EQ(find_components(cubes).count, 2);
  EXPECT_LT(cubes.faces.size() * 2, tets.faces.size());
  // Same level set: the enclosed volumes agree to a few percent.
  EXPECT_NEAR(signed_volume(cubes), signed_volume(tets), 0.03 * signed_volume(tets));
}

TEST(ProxyExtraction, CollapseKeepsTopologyAndCoarsens) {
  // A genus-1 level set and a random-sign one (many components and handles).
  Soup torus = shapes::to_soup(shapes::torus(1.0, 0.3, 48, 16));
  geometry::DistanceBvh bvh(torus);
  NarrowBand smooth = build_narrow_band(bvh, bounding_box(torus), 0.1, 0.02, Progress::none());
  for (const NarrowBand* band : {&smooth}) {
    TriMesh raw = marching_cubes(*band, Progress::none());
    Topology before = check_topology(raw);
    CollapseStats stats;
    TriMesh coarse = collapse_short_edges(raw, 0.1, 0.25, &stats);
    expect_closed_manifold(coarse);
    Topology after = check_topology(coarse);
    EXPECT_EQ(after.euler(), before.euler());
    EXPECT_EQ(after.euler(), 0);  // genus 1
    EXPECT_EQ(find_components(coarse).count, find_components(raw).count);
    EXPECT_LT(coarse.faces.size() * 5, raw.faces.size());
    EXPECT_GT(stats.collapses, 0u);
    // Few edges stay shorter than the target (those the checks refused).
    size_t short_edges = 0, edges = 0;
    for (const auto& f : coarse.faces)
      for (int k = 0; k < 3; ++k, ++edges)
        short_edges += norm(coarse.vertices[f[k]] - coarse.vertices[f[(k + 1) % 3]]) < 0.1;
    EXPECT_LT(short_edges, edges / 10);
    EXPECT_NEAR(signed_volume(coarse), signed_volume(raw), 0.05 * signed_volume(raw));
  }
  NarrowBand noisy = random_band(10, 5, false);
  TriMesh raw = marching_cubes(noisy, Progress::none());
  TriMesh coarse = collapse_short_edges(raw, 0.6, 1.2);
  expect_closed_manifold(coarse);
  EXPECT_EQ(check_topology(coarse).euler(), check_topology(raw).euler());
  EXPECT_EQ(find_components(coarse).count, find_components(raw).count);
  EXPECT_LT(coarse.faces.size(), raw.faces.size());
}

// The collapse (serial) and marching cubes (static contiguous chunks) give
// the same mesh for 1, 2 and 3 threads.
TEST(ProxyExtraction, CollapseAndMarchingCubesDoNotDependOnTheThreadCount) {
  Soup torus = shapes::to_soup(shapes::torus(1.0, 0.3, 48, 16));
  geometry::DistanceBvh bvh(torus);
  NarrowBand band = build_narrow_band(bvh, bounding_box(torus), 0.1, 0.02, Progress::none());
  const int saved = omp_get_max_threads();
  std::vector<TriMesh> results;
  for (int threads : {1, 2, 3}) {
    omp_set_num_threads(threads);
    TriMesh raw = marching_cubes(band, Progress::none());
    results.push_back(collapse_short_edges(raw, 0.1, 0.25));
  }
  omp_set_num_threads(saved);
  ASSERT_GT(results[0].faces.size(), 100u);
  for (size_t r = 1; r < results.size(); ++r) {
    EXPECT_EQ(results[r].faces, results[0].faces);
    ASSERT_EQ(results[r].vertices.size(), results[0].vertices.size());
    for (size_t v = 0; v < results[0].vertices.size(); ++v)
      EXPECT_EQ(norm(results[r].vertices[v] - results[0].vertices[v]), 0.0);
  }
}

// A sphere of radius 0.6 around a soup sphere of radius 0.2 sits at d = 0.4;
// lifting to o = 0.7 in steps of at most 0.12 must reach d = o (and no more)
// in three rounds, and not before.
TEST(ProxyExtraction, LiftMovesSunkenVerticesOutToTheOffset) {
  Soup soup = shapes::to_soup(shapes::icosphere(0.2, 3));
  geometry::DistanceBvh bvh(soup);
  TriMesh proxy = shapes::icosphere(0.6, 3);
  TriMesh once = proxy;
  double ratio_once = lift_to_offset(once, bvh, 0.7, 0.12, 1);
  EXPECT_NEAR(ratio_once, (0.4 + 0.12) / 0.7, 0.02);
  double ratio = lift_to_offset(proxy, bvh, 0.7, 0.12, 3);
  EXPECT_GT(ratio, 0.99);
  double farthest = 0;
  for (const Vec3& v : proxy.vertices) farthest = std::max(farthest, bvh.distance(v));
  EXPECT_LT(farthest, 0.7 + 1e-9);  // lifted to the offset, never beyond
  expect_closed_manifold(proxy);
}

}  // namespace
}  // namespace soupuv::proxy
