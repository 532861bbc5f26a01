#include <gtest/gtest.h>

#include <map>

#include "soupuv/errors.h"
#include "soupuv/progress.h"
#include "testing/shapes.h"
#include "soupuv/soup.h"

using namespace soupuv;

TEST(Soup, HashIgnoresVertexSharingButSeesGeometry) {
  TriMesh cube = shapes::cube(1.0, 2);
  Soup split = shapes::to_soup(cube);
  Soup shared;
  shared.positions = cube.vertices;
  for (auto f : cube.faces)
    shared.triangles.push_back({uint32_t(f[0]), uint32_t(f[1]), uint32_t(f[2])});
  EXPECT_EQ(geometry_hash(split), geometry_hash(shared));
  split.positions[0].x += 1e-12;
  EXPECT_NE(geometry_hash(split), geometry_hash(shared));
}

TEST(Soup, SharingStatsTellSoupFromMesh) {
  TriMesh sphere = shapes::icosphere(1.0, 2);
  Soup soup = shapes::to_soup(sphere);
  EXPECT_TRUE(sharing_stats(soup).is_soup);
  Soup mesh;
  mesh.positions = sphere.vertices;
  for (auto f : sphere.faces) mesh.triangles.push_back({uint32_t(f[0]), uint32_t(f[1]), uint32_t(f[2])});
  SharingStats s = sharing_stats(mesh);
  EXPECT_FALSE(s.is_soup);
  EXPECT_DOUBLE_EQ(s.shared_index_fraction, 1.0);
  EXPECT_EQ(s.distinct_vertex_indices, sphere.vertices.size());
}

namespace {
// Closed outward mesh: signed volume positive and every edge used twice, once per direction.
void expect_closed_outward(const TriMesh& m) {
  double volume = 0;
  std::map<std::pair<int, int>, int> edges;
  for (auto f : m.faces) {
    volume += dot(m.vertices[f[0]], cross(m.vertices[f[1]], m.vertices[f[2]])) / 6.0;
    for (int k = 0; k < 3; ++k) edges[{f[k], f[(k + 1) % 3]}]++;
  }
  EXPECT_GT(volume, 0);
  for (auto& [e, count] : edges) {
    EXPECT_EQ(count, 1);
    EXPECT_EQ(edges.count({e.second, e.first}), 1u);
  }
}
}  // namespace

TEST(Shapes, AreClosedAndOutward) {
  expect_closed_outward(shapes::uv_sphere(1, 8, 16));
  expect_closed_outward(shapes::icosphere(1, 2));
  expect_closed_outward(shapes::torus(1, 0.5, 20, 10));
  expect_closed_outward(shapes::cube(2, 5));
  expect_closed_outward(shapes::cylinder(1, 2, 24, 6, 3));
  EXPECT_EQ(shapes::cube(1, 20).faces.size(), 4800u);
  EXPECT_EQ(shapes::torus_with(1, 0.5, 5000).faces.size(), 5000u);
}

TEST(Progress, CancelThrows) {
  Progress p;
  p.update("x", 0.5);
  p.cancel();
  try {
    p.update("x", 0.6);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::canceled);
  }
}
