// The proxy's building blocks against their slow twins: BVH distance and
// inside tests against brute force, the narrow band against a dense grid,
// marching tetrahedra's topology on hard sign patterns, the topology checker
// on meshes with known defects.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "soupuv/proxy/components.h"
#include "soupuv/proxy/marching_tetrahedra.h"
#include "soupuv/proxy/mesh_checks.h"
#include "soupuv/proxy/narrow_band.h"
#include "soupuv/proxy/taubin_smooth.h"
#include "soupuv/geometry/closest_point.h"
#include "soupuv/geometry/distance_bvh.h"
#include "testing/shapes.h"

namespace soupuv::proxy {
namespace {

double brute_distance(const Soup& s, Vec3 p) {
  double best = INFINITY;
  for (size_t t = 0; t < s.triangles.size(); ++t)
    best = std::min(best, geometry::point_triangle_distance(p, s.corner(t, 0), s.corner(t, 1), s.corner(t, 2)));
  return best;
}

// Generalized winding number: the slow, grazing-proof twin of ray parity.
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

TEST(ProxyParts, BvhDistanceMatchesBruteForce) {
  Soup soup = shapes::to_soup(shapes::torus(1.0, 0.3, 24, 12), 0.01, 3);
  geometry::DistanceBvh bvh(soup);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.6, 1.6);
  for (int i = 0; i < 400; ++i) {
    Vec3 p{u(rng), u(rng), u(rng) * 0.5};
    double exact = brute_distance(soup, p);
    EXPECT_NEAR(bvh.distance(p), exact, 1e-12);
    // Band query: exact inside the band, below lo / equal to hi outside it.
    for (double lo : {-0.2, 0.1}) {  // a negative lo never stops early
      double hi = 0.3;
      double banded = bvh.distance(p, lo, hi);
      if (exact < lo) EXPECT_LT(banded, lo);
      else if (exact > hi) EXPECT_EQ(banded, hi);
      else EXPECT_NEAR(banded, exact, 1e-12);
      // A warm start (any triangle id, even a far or invalid one) changes
      // nothing but the speed.
      uint32_t warm = uint32_t(rng() % (bvh.size() + 5));
      double warmed = bvh.distance(p, lo, hi, &warm);
      if (exact < lo) EXPECT_LT(warmed, lo);
      else if (exact > hi) EXPECT_EQ(warmed, hi);
      else EXPECT_NEAR(warmed, exact, 1e-12);
    }
  }
}

// Nearest-candidate culling: a box's gathered list with radius d(center) +
// half-diagonal holds the closest triangle of every point in the box, so the
// restricted distance equals brute force there (band semantics included).
TEST(ProxyParts, GatheredCandidatesGiveExactDistancesInTheirBox) {
  Soup soup = shapes::to_soup(shapes::torus(1.0, 0.3, 24, 12), 0.01, 3);
  geometry::DistanceBvh bvh(soup);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.6, 1.6), s(0.01, 0.4), t(0.0, 1.0);
  size_t total = 0;
  for (int b = 0; b < 60; ++b) {
    Vec3 c{u(rng), u(rng), u(rng) * 0.5};
    double half = s(rng);
    Box3 box{c - Vec3{half, half, half}, c + Vec3{half, half, half}};
    geometry::CandidateList list;
    bvh.gather(box, bvh.distance(c) + std::sqrt(3.0) * half, list);
    total += list.size();
    EXPECT_LT(list.size(), bvh.size());
    for (int i = 0; i < 20; ++i) {
      // Corners of the box included: the narrow band evaluates them.
      Vec3 p = i < 8 ? Vec3{i & 1 ? box.hi.x : box.lo.x, i & 2 ? box.hi.y : box.lo.y, i & 4 ? box.hi.z : box.lo.z}
                     : box.lo + Vec3{t(rng) * 2 * half, t(rng) * 2 * half, t(rng) * 2 * half};
      double exact = brute_distance(soup, p);
      EXPECT_NEAR(bvh.distance_among(p, list), exact, 1e-12);
      double lo = exact - 0.05, hi = exact + 0.05;
      uint32_t warm = uint32_t(rng() % (bvh.size() + 5));
      EXPECT_NEAR(bvh.distance_among(p, list, lo, hi, &warm), exact, 1e-12);
      EXPECT_LT(bvh.distance_among(p, list, exact + 0.01, exact + 0.1), exact + 0.01);
      if (exact > 0.02) {
        EXPECT_EQ(bvh.distance_among(p, list, 0, exact - 0.01), exact - 0.01);
      }
    }
  }
  EXPECT_GT(total, 0u);
}

// A parent's list narrowed to a child box (geometry::DistanceBvh::narrow, what the
// narrow band does for the cells under one grandparent) is as good as a
// list gathered for the child itself: exact distances everywhere in the child.
TEST(ProxyParts, NarrowedCandidatesGiveExactDistancesInTheChildBox) {
  Soup soup = shapes::to_soup(shapes::torus(1.0, 0.3, 24, 12), 0.01, 3);
  geometry::DistanceBvh bvh(soup);
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-1.6, 1.6), s(0.02, 0.3), t(0.0, 1.0);
  size_t parent_total = 0, child_total = 0;
  for (int b = 0; b < 60; ++b) {
    Vec3 c{u(rng), u(rng), u(rng) * 0.5};
    double half = s(rng);
    Box3 parent{c - Vec3{half, half, half}, c + Vec3{half, half, half}};
    geometry::CandidateList parent_list, child_list;
    bvh.gather(parent, bvh.distance(c) + std::sqrt(3.0) * half, parent_list);
    // One octant of the parent, with its own (smaller) radius.
    Vec3 lo{t(rng) < 0.5 ? parent.lo.x : c.x, t(rng) < 0.5 ? parent.lo.y : c.y, t(rng) < 0.5 ? parent.lo.z : c.z};
    Box3 child{lo, lo + Vec3{half, half, half}};
    bvh.narrow(parent_list, child, bvh.distance(child.center()) + std::sqrt(3.0) * half / 2, child_list);
    parent_total += parent_list.size();
    child_total += child_list.size();
    for (int i = 0; i < 20; ++i) {
      Vec3 p = child.lo + Vec3{t(rng) * half, t(rng) * half, t(rng) * half};
      double exact = brute_distance(soup, p);
      EXPECT_NEAR(bvh.distance_among(p, child_list), exact, 1e-12);
      uint32_t warm = uint32_t(rng() % (bvh.size() + 5));
      EXPECT_NEAR(bvh.distance_among(p, child_list, exact - 0.05, exact + 0.05, &warm), exact, 1e-12);
    }
  }
  EXPECT_LT(child_total, parent_total);  // narrowing drops candidates
}

TEST(ProxyParts, BvhContainsMatchesWindingNumber) {
  TriMesh torus = shapes::torus(1.0, 0.4, 32, 16);
  geometry::DistanceBvh bvh(torus);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  int inside = 0;
  for (int i = 0; i < 500; ++i) {
    Vec3 p{u(rng), u(rng), u(rng) * 0.5};
    bool expected = winding_number(torus, p) > 0.5;
    EXPECT_EQ(bvh.contains(p), expected) << p.x << " " << p.y << " " << p.z;
    inside += expected;
  }
  EXPECT_GT(inside, 30);  // the sample really probes both sides
}

TEST(ProxyParts, TopologyOfKnownMeshes) {
  TriMesh cube = shapes::cube(1.0, 3);
  Topology t = check_topology(cube);
  EXPECT_TRUE(t.closed && t.oriented && t.manifold);
  EXPECT_EQ(t.euler(), 2);
  Topology torus = check_topology(shapes::torus(1, 0.3, 12, 8));
  EXPECT_TRUE(torus.manifold);
  EXPECT_EQ(torus.euler(), 0);

  TriMesh open = cube;
  open.faces.pop_back();
  EXPECT_FALSE(check_topology(open).closed);
  TriMesh flipped = cube;
  std::swap(flipped.faces[0][1], flipped.faces[0][2]);
  Topology f = check_topology(flipped);
  EXPECT_TRUE(f.closed);
  EXPECT_FALSE(f.oriented);
  // Two cubes sharing one vertex (a pinch): closed and oriented, not manifold.
  TriMesh a = shapes::cube(1.0, 1), b = shapes::cube(1.0, 1);
  shapes::translate(b, {1, 1, 1});
  TriMesh pinch = a;
  int shared_a = -1, shared_b = -1;
  for (size_t i = 0; i < a.vertices.size(); ++i)
    if (norm(a.vertices[i] - Vec3{0.5, 0.5, 0.5}) < 1e-12) shared_a = int(i);
  for (size_t i = 0; i < b.vertices.size(); ++i)
    if (norm(b.vertices[i] - Vec3{0.5, 0.5, 0.5}) < 1e-12) shared_b = int(i);
  ASSERT_GE(shared_a, 0);
  ASSERT_GE(shared_b, 0);
  int base = int(pinch.vertices.size());
  pinch.vertices.insert(pinch.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (auto fb : b.faces) {
    for (int& v : fb) v = v == shared_b ? shared_a : v + base;
    pinch.faces.push_back(fb);
  }
  Topology p = check_topology(pinch);
  EXPECT_TRUE(p.closed);
  EXPECT_FALSE(p.manifold);
  // A zero-area face is counted.
  TriMesh degenerate = cube;
  degenerate.vertices[degenerate.faces[0][2]] = degenerate.vertices[degenerate.faces[0][1]];
  EXPECT_GE(check_topology(degenerate).degenerate_faces, 1u);
}

TEST(ProxyParts, NarrowBandKeepsEveryCrossingCellOfADenseGrid) {
  Soup soup = shapes::to_soup(shapes::cube(1.0, 2), 0.002, 5);
  geometry::DistanceBvh bvh(soup);
  Box3 box = bounding_box(soup);
  double offset = 0.08, cell = 1.0 / 40;
  // Without pruning: the closed cube's inner shell is in the band too.
  NarrowBand band = build_narrow_band(bvh, box, offset, cell, Progress::none(), false);
  // Dense twin: every cell whose corners change sign must be in the band.
  size_t dense_cells = 0, crossing = 0, missing = 0;
  for (int k = 0; k < band.dims[2]; ++k)
    for (int j = 0; j < band.dims[1]; ++j)
      for (int i = 0; i < band.dims[0]; ++i) {
        ++dense_cells;
        int in = 0;
        for (int v = 0; v < 8; ++v) {
          Vec3 p = band.origin + Vec3{(i + (v & 1)) * cell, (j + ((v >> 1) & 1)) * cell, (k + (v >> 2)) * cell};
          in += brute_distance(soup, p) - offset < 0;
        }
        if (in == 0 || in == 8) continue;
        ++crossing;
        missing += !std::binary_search(band.cells.begin(), band.cells.end(), grid_key(i, j, k));
      }
  EXPECT_GT(crossing, 500u);
  EXPECT_EQ(missing, 0u);
  EXPECT_EQ(band.cells.size(), crossing);  // and nothing else
  // Corner values near the level set equal the brute-force field; farther
  // ones only need the right sign.
  for (size_t n = 0; n < band.corner_keys.size(); n += 7) {
    double exact = brute_distance(soup, band.corner_position(band.corner_keys[n])) - offset;
    if (std::fabs(exact) < 1.7 * cell)  // the band is exact within sqrt(3) h
      EXPECT_NEAR(band.corner_values[n], exact, 1e-12);
    else
      EXPECT_EQ(band.corner_values[n] < 0, exact < 0);
  }
}

// Pruning keeps exactly the crossing cells of the outer shell: those the
// dense twin's flood fill from the border (through f > 0 corners) touches.
TEST(ProxyParts, PrunedNarrowBandKeepsTheOuterShellOnly) {
  Soup soup = shapes::to_soup(shapes::cube(1.0, 2), 0.002, 5);
  geometry::DistanceBvh bvh(soup);
  Box3 box = bounding_box(soup);
  double offset = 0.08, cell = 1.0 / 40;
  NarrowBand full = build_narrow_band(bvh, box, offset, cell, Progress::none(), false);
  NarrowBand outer = build_narrow_band(bvh, box, offset, cell, Progress::none(), true);
  EXPECT_GT(outer.pruned_cells, 0u);
  EXPECT_EQ(full.pruned_cells, 0u);
  // Dense twin: corners with f > 0 flooded from the border (6-connected);
  // a crossing cell belongs to the outer shell when it has a flooded corner.
  const int nx = full.dims[0] + 1, ny = full.dims[1] + 1, nz = full.dims[2] + 1;
  auto id = [&](int i, int j, int k) { return size_t(i) + size_t(nx) * (size_t(j) + size_t(ny) * size_t(k)); };
  std::vector<char> positive(size_t(nx) * ny * nz), flooded(positive.size(), 0);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        positive[id(i, j, k)] =
            brute_distance(soup, full.origin + Vec3{i * cell, j * cell, k * cell}) - offset >= 0;
  std::vector<std::array<int, 3>> queue{{0, 0, 0}};
  flooded[0] = 1;
  for (size_t q = 0; q < queue.size(); ++q) {
    auto [i, j, k] = queue[q];
    const int step[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (const auto& s : step) {
      int a = i + s[0], b = j + s[1], c = k + s[2];
      if (a < 0 || b < 0 || c < 0 || a >= nx || b >= ny || c >= nz) continue;
      if (!positive[id(a, b, c)] || flooded[id(a, b, c)]) continue;
      flooded[id(a, b, c)] = 1;
      queue.push_back({a, b, c});
    }
  }
  size_t outer_crossing = 0;
  for (uint64_t key : full.cells) {
    auto c = grid_coords(key);
    bool touches = false;
    for (int v = 0; v < 8; ++v) touches |= flooded[id(c[0] + (v & 1), c[1] + ((v >> 1) & 1), c[2] + (v >> 2))];
    if (!touches) continue;
    ++outer_crossing;
    EXPECT_TRUE(std::binary_search(outer.cells.begin(), outer.cells.end(), key));
  }
  EXPECT_GT(outer_crossing, 300u);
  EXPECT_LT(outer.cells.size(), full.cells.size());
  // The cavity is gone: no kept cell is a crossing cell of the inner shell only.
  EXPECT_EQ(outer.cells.size(), outer_crossing);
}

// Halving the cell size must multiply the work by about 4 (the surface), not
// 8 (the volume).
TEST(ProxyParts, NarrowBandGrowsWithTheSurfaceNotTheVolume) {
  Soup soup = shapes::to_soup(shapes::icosphere(1.0, 3), 1e-3, 2);
  geometry::DistanceBvh bvh(soup);
  Box3 box = bounding_box(soup);
  // Unpruned: pruning the inner shell kicks in at the finer cell only.
  NarrowBand coarse = build_narrow_band(bvh, box, 0.03, 0.02, Progress::none(), false);
  NarrowBand fine = build_narrow_band(bvh, box, 0.03, 0.01, Progress::none(), false);
  double cells = double(fine.cells.size()) / coarse.cells.size();
  double corners = double(fine.corner_keys.size()) / coarse.corner_keys.size();
  double evaluations = double(fine.distance_evaluations) / coarse.distance_evaluations;
  EXPECT_NEAR(cells, 4.0, 0.6);
  EXPECT_LT(corners, 6.0);
  EXPECT_LT(evaluations, 6.0);
  size_t dense = size_t(fine.dims[0] + 1) * (fine.dims[1] + 1) * (fine.dims[2] + 1);
  EXPECT_LT(fine.corner_keys.size(), dense / 4);
}

// Marching tetrahedra on a hand-made band with random signs: the hardest
// inputs for ambiguity (every cube pattern occurs), still closed and manifold.
TEST(ProxyParts, MarchingTetrahedraIsManifoldForRandomSigns) {
  NarrowBand band;
  band.cell = 1.0;
  band.dims = {10, 10, 10};
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int k = 0; k <= 10; ++k)
    for (int j = 0; j <= 10; ++j)
      for (int i = 0; i <= 10; ++i) {
        band.corner_keys.push_back(grid_key(i, j, k));
        bool border = i == 0 || j == 0 || k == 0 || i == 10 || j == 10 || k == 10;
        // Outside on the border so the level set cannot leave the grid;
        // exact zeros too, to test the f == 0 convention.
        double f = border ? 1.0 : (rng() % 7 == 0 ? 0.0 : u(rng));
        band.corner_values.push_back(f);
      }
  std::vector<std::pair<uint64_t, double>> sorted;
  for (size_t n = 0; n < band.corner_keys.size(); ++n) sorted.push_back({band.corner_keys[n], band.corner_values[n]});
  std::sort(sorted.begin(), sorted.end());
  for (size_t n = 0; n < sorted.size(); ++n) {
    band.corner_keys[n] = sorted[n].first;
    band.corner_values[n] = sorted[n].second;
  }
  for (int k = 0; k < 10; ++k)
    for (int j = 0; j < 10; ++j)
      for (int i = 0; i < 10; ++i) band.cells.push_back(grid_key(i, j, k));
  std::sort(band.cells.begin(), band.cells.end());
  TriMesh mesh = marching_tetrahedra(band, Progress::none());
  ASSERT_GT(mesh.faces.size(), 1000u);
  Topology t = check_topology(mesh);
  EXPECT_TRUE(t.closed);
  EXPECT_TRUE(t.oriented);
  EXPECT_TRUE(t.manifold);
  EXPECT_EQ(t.degenerate_faces, 0u);
  // Outward: every component encloses the inside corners, so volumes are
  // positive for outer components and negative for cavities; the total is
  // the (positive) inside volume.
  EXPECT_GT(signed_volume(mesh), 0);
}

TEST(ProxyParts, ComponentsFindNestedShells) {
  TriMesh outer = shapes::icosphere(2.0, 2), inner = shapes::icosphere(1.0, 2), far = shapes::icosphere(1.0, 2);
  for (auto& f : inner.faces) std::swap(f[1], f[2]);  // a cavity faces inwards
  shapes::translate(far, {10, 0, 0});
  TriMesh all = outer;
  for (const TriMesh* m : {&inner, &far}) {
    int base = int(all.vertices.size());
    all.vertices.insert(all.vertices.end(), m->vertices.begin(), m->vertices.end());
    for (auto f : m->faces) all.faces.push_back({f[0] + base, f[1] + base, f[2] + base});
  }
  Components c = find_components(all);
  ASSERT_EQ(c.count, 3);
  int inner_count = 0;
  for (int i = 0; i < 3; ++i) inner_count += c.inner[i];
  EXPECT_EQ(inner_count, 1);
  EXPECT_TRUE(c.inner[c.face_component[outer.faces.size()]]);
  EXPECT_LT(c.volume[c.face_component[outer.faces.size()]], 0);
}

TEST(ProxyParts, TaubinSmoothingDoesNotShrinkASphere) {
  TriMesh sphere = shapes::icosphere(1.0, 3);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-0.02, 0.02);
  for (Vec3& v : sphere.vertices) v += Vec3{u(rng), u(rng), u(rng)};
  double before = signed_volume(sphere);
  TriMesh laplace = sphere;
  taubin_smooth(laplace, 10, 0.5, 0.0);  // mu = 0: plain Laplacian, shrinks
  taubin_smooth(sphere, 10);
  EXPECT_NEAR(signed_volume(sphere) / before, 1.0, 0.02);
  EXPECT_LT(signed_volume(laplace) / before, 0.97);
}

}  // namespace
}  // namespace soupuv::proxy
