#include <gtest/gtest.h>

#include <random>

#include "soupuv/geometry/weld.h"
#include "testing/shapes.h"
#include "soupuv/field/orient.h"

using namespace soupuv;
using namespace soupuv::field;

namespace {

// Reverses the winding of a random ~third of the triangles.
void scramble_winding(Soup& s, unsigned seed) {
  std::mt19937 rng(seed);
  for (auto& t : s.triangles)
    if (rng() % 3 == 0) std::swap(t[1], t[2]);
}

Soup plate(int n) {
  TriMesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.vertices.push_back({double(i) / n, double(j) / n, 0});
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      int a = j * (n + 1) + i;
      m.faces.push_back({a, a + 1, a + n + 2});
      m.faces.push_back({a, a + n + 2, a + n + 1});
    }
  return shapes::to_soup(m, 1e-4, 4);
}

// One line per corner, leaving on `side(t, k)` relative to the input normal.
template <class F>
field::FieldLines lines_with_sides(const Soup& s, F side) {
  field::FieldLines fl;
  for (size_t t = 0; t < s.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      Vec3 p = s.corner(t, k), n = triangle_normal(s, t);
      fl.points.push_back(p + 1e-3 * side(t, k) * n);
      fl.points.push_back(p + 1e-1 * side(t, k) * n);
      fl.offsets.push_back(uint32_t(fl.points.size()));
      fl.ends.push_back(field::LineEnd::escaped);
      fl.corner.push_back(uint32_t(3 * t + k));
    }
  return fl;
}

}  // namespace

TEST(Orient, SphereWindingIsRestoredOutward) {
  Soup s = shapes::to_soup(shapes::icosphere(1.0, 2), 1e-4, 3);
  scramble_winding(s, 1);
  auto adj = geometry::edge_adjacency(geometry::weld_corners(s, 1e-3), s.triangles.size());
  Orientation o = consistent_orientation(s, adj);
  EXPECT_EQ(o.components, 1u);
  EXPECT_EQ(o.conflicting_edges, 0u);
  size_t scrambled = 0;
  for (size_t t = 0; t < s.triangles.size(); ++t) {
    Vec3 c = (s.corner(t, 0) + s.corner(t, 1) + s.corner(t, 2)) / 3.0;
    bool outward = dot(triangle_normal(s, t), c) > 0;
    scrambled += !outward;
    EXPECT_EQ(o.flip[t], outward ? 1 : -1) << t;
  }
  EXPECT_EQ(o.flipped_triangles, scrambled);
}

TEST(Orient, PlateGetsOneSideFromTheMajorityOfCorners) {
  Soup s = plate(10);
  scramble_winding(s, 2);
  auto adj = geometry::edge_adjacency(geometry::weld_corners(s, 1e-3), s.triangles.size());
  Orientation o = consistent_orientation(s, adj);
  ASSERT_EQ(o.components, 1u);
  // |E| picks +z for 70 % of the corners (random), -z for the rest: sides
  // relative to each triangle's own (scrambled) normal.
  std::mt19937 rng(9);
  field::FieldLines free = lines_with_sides(s, [&](size_t t, int) {
    int up = (rng() % 10) < 7 ? 1 : -1;
    return triangle_normal(s, t).z > 0 ? up : -up;
  });
  SideChoice sc = component_sides(s, o, free);
  EXPECT_GT(sc.mixed_triangles_before, s.triangles.size() / 4);
  for (size_t t = 0; t < s.triangles.size(); ++t) {
    // Every triangle now traces towards +z, whatever its winding.
    EXPECT_GT(sc.triangle_side[t] * triangle_normal(s, t).z, 0) << t;
  }
  field::FieldLines after = lines_with_sides(s, [&](size_t t, int) { return sc.triangle_side[t]; });
  EXPECT_EQ(mixed_side_triangles(s, after), 0u);
}

TEST(Orient, MoebiusStripReportsConflicts) {
  // A Moebius strip cannot be oriented: at least one edge must disagree.
  TriMesh m;
  const int n = 24;
  for (int i = 0; i < n; ++i) {
    double a = 2 * M_PI * i / n, h = a / 2;
    for (int s = -1; s <= 1; s += 2)
      m.vertices.push_back({(1 + 0.3 * s * std::cos(h)) * std::cos(a), (1 + 0.3 * s * std::cos(h)) * std::sin(a),
                            0.3 * s * std::sin(h)});
  }
  for (int i = 0; i < n; ++i) {
    int a0 = 2 * i, a1 = 2 * i + 1;
    int b0 = 2 * ((i + 1) % n), b1 = 2 * ((i + 1) % n) + 1;
    if (i == n - 1) std::swap(b0, b1);  // the half twist
    m.faces.push_back({a0, b0, b1});
    m.faces.push_back({a0, b1, a1});
  }
  Soup s = shapes::to_soup(m);
  auto adj = geometry::edge_adjacency(geometry::weld_corners(s, 0), s.triangles.size());
  Orientation o = consistent_orientation(s, adj);
  EXPECT_EQ(o.components, 1u);
  EXPECT_GE(o.conflicting_edges, 1u);
}
