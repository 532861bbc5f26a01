// geometry::extend_weld (geometry/weld.cpp): a corner weld that starts from the groups of
// another weld. Against its slow twin (every corner pair compared, no grid),
// and the rules it shares with geometry::weld_corners: start groups are never split,
// two corners of one triangle never joined.
#include <gtest/gtest.h>

#include <algorithm>

#include "soupuv/geometry/weld.h"
#include "testing/shapes.h"
#include "soupuv/union_find.h"

using namespace soupuv;
using namespace soupuv::geometry;

namespace {

// The slow twin: the start's groups, then all corner pairs within the
// tolerance (and, with edge_fraction > 0, within that fraction of both
// triangles' shortest edges), nearest first, each joined unless the two sets
// share a triangle.
std::vector<uint32_t> slow_extend(const Soup& soup, const geometry::Weld& start, double tolerance,
                                  double edge_fraction = 0) {
  auto shortest2 = [&](uint32_t t) {
    const Vec3 a = soup.corner(t, 0), b = soup.corner(t, 1), c = soup.corner(t, 2);
    return std::min({norm2(b - a), norm2(c - b), norm2(a - c)});
  };
  const uint32_t corners = uint32_t(3 * soup.triangles.size());
  UnionFind uf(corners);
  for (uint32_t a = 0; a < corners; ++a)
    for (uint32_t b = a + 1; b < corners; ++b)
      if (start.corner_vertex[a] == start.corner_vertex[b]) uf.unite(a, b);
  struct Pair { double d2; uint32_t a, b; };
  std::vector<Pair> pairs;
  for (uint32_t a = 0; a < corners; ++a)
    for (uint32_t b = a + 1; b < corners; ++b) {
      const double d2 = norm2(soup.corner(a / 3, a % 3) - soup.corner(b / 3, b % 3));
      if (edge_fraction > 0 &&
          d2 > edge_fraction * edge_fraction * std::min(shortest2(a / 3), shortest2(b / 3)))
        continue;
      if (d2 <= tolerance * tolerance) pairs.push_back({d2, a, b});
    }
  std::stable_sort(pairs.begin(), pairs.end(), [](const Pair& x, const Pair& y) { return x.d2 < y.d2; });
  auto share_a_triangle = [&](uint32_t ra, uint32_t rb) {
    for (uint32_t c = 0; c < corners; ++c)
      for (uint32_t e = 0; e < corners; ++e)
        if (c / 3 == e / 3 && uf.find(c) == ra && uf.find(e) == rb) return true;
    return false;
  };
  for (const Pair& p : pairs) {
    const uint32_t ra = uf.find(p.a), rb = uf.find(p.b);
    if (ra != rb && !share_a_triangle(ra, rb)) uf.unite(ra, rb);
  }
  std::vector<uint32_t> root(corners);
  for (uint32_t c = 0; c < corners; ++c) root[c] = uf.find(c);
  return root;
}

void expect_same_partition(const geometry::Weld& w, const std::vector<uint32_t>& root) {
  const size_t corners = root.size();
  for (size_t a = 0; a < corners; ++a)
    for (size_t b = a + 1; b < corners; ++b)
      ASSERT_EQ(w.corner_vertex[a] == w.corner_vertex[b], root[a] == root[b]) << a << " " << b;
}

}  // namespace

// A noisy sphere whose copies lie up to ~3.5 noise apart: a tolerance of 2
// noise units leaves some copies apart, and a start weld (the edge weld at a
// tight tolerance, which joins some of those) must come through unchanged.
TEST(ExtendWeld, MatchesItsSlowTwinOnANoisySphere) {
  const Soup soup = shapes::to_soup(shapes::icosphere(1.0, 1), 2e-2, 5);  // 80 triangles
  const double diag = bounding_box(soup).diagonal();
  const geometry::Weld start = geometry::weld_by_edges(soup, 0.05 * diag);
  const double tolerance = 0.04 * diag;
  const geometry::Weld w = geometry::extend_weld(soup, start, tolerance);
  expect_same_partition(w, slow_extend(soup, start, tolerance));
  // The start's groups survive, and the extension joined more.
  for (size_t a = 0; a < start.corner_vertex.size(); ++a)
    for (size_t b = a + 1; b < start.corner_vertex.size(); ++b) {
      if (start.corner_vertex[a] == start.corner_vertex[b]) {
        EXPECT_EQ(w.corner_vertex[a], w.corner_vertex[b]);
      }
    }
  EXPECT_LT(w.vertex_count, start.vertex_count);
  EXPECT_LT(w.vertex_count, geometry::weld_corners(soup, tolerance).vertex_count + 1);
}

// A tolerance of several edges, bounded per pair by a fraction of the
// triangles' shortest edges (as the seeds' extension is): the weld queries
// each corner only within its own triangle's bound and must find the same
// pairs.
TEST(ExtendWeld, MatchesItsSlowTwinWhereTheEdgeFractionBinds) {
  const Soup soup = shapes::to_soup(shapes::icosphere(1.0, 1), 5e-2, 9);  // 80 triangles
  const double diag = bounding_box(soup).diagonal();
  const geometry::Weld start = geometry::weld_by_edges(soup, 0.01 * diag);
  geometry::Weld singletons;
  singletons.corner_vertex.resize(3 * soup.triangles.size());
  for (uint32_t c = 0; c < singletons.corner_vertex.size(); ++c) singletons.corner_vertex[c] = c;
  singletons.vertex_count = static_cast<uint32_t>(singletons.corner_vertex.size());
  const double tolerance = 0.5 * diag;  // far beyond every edge
  for (const double fraction : {0.5, 1.0}) {
    expect_same_partition(geometry::extend_weld(soup, start, tolerance, fraction),
                          slow_extend(soup, start, tolerance, fraction));
    expect_same_partition(geometry::weld_corners(soup, tolerance, fraction),
                          slow_extend(soup, singletons, tolerance, fraction));
  }
}

// Starting from nothing it is geometry::weld_corners.
TEST(ExtendWeld, FromSingletonsIsTheCornerWeld) {
  const Soup soup = shapes::to_soup(shapes::icosphere(1.0, 2), 2e-3, 7);
  const double diag = bounding_box(soup).diagonal();
  geometry::Weld singletons;
  for (uint32_t c = 0; c < 3 * soup.triangles.size(); ++c) singletons.corner_vertex.push_back(c);
  singletons.vertex_count = uint32_t(singletons.corner_vertex.size());
  const geometry::Weld a = geometry::extend_weld(soup, singletons, 5e-3 * diag, 1.0);
  const geometry::Weld b = geometry::weld_corners(soup, 5e-3 * diag, 1.0);
  EXPECT_EQ(a.corner_vertex, b.corner_vertex);
  EXPECT_EQ(a.vertex_count, 162u);  // the icosphere's vertices
}

// Distance never joins two corners of one triangle, even when the start
// already put one of them with a copy of the other's neighbour.
TEST(ExtendWeld, NeverCollapsesATriangle) {
  Soup s;
  const double e = 1e-3;
  s.positions = {{0, 0, 0}, {e, 0, 0}, {0, e, 0},           // a tiny triangle
                 {0, 0, 0}, {e, 0, 0}, {0.5 * e, -e, 0}};  // its neighbour
  s.triangles = {{0, 1, 2}, {3, 4, 5}};
  s.origins.resize(2);
  geometry::Weld start;
  start.corner_vertex = {0, 1, 2, 0, 3, 4};  // corner 3 is corner 0's copy
  start.vertex_count = 5;
  const geometry::Weld w = geometry::extend_weld(s, start, 10 * e);
  for (int t = 0; t < 2; ++t) {
    EXPECT_NE(w.corner_vertex[3 * t], w.corner_vertex[3 * t + 1]);
    EXPECT_NE(w.corner_vertex[3 * t], w.corner_vertex[3 * t + 2]);
    EXPECT_NE(w.corner_vertex[3 * t + 1], w.corner_vertex[3 * t + 2]);
  }
  EXPECT_EQ(w.corner_vertex[0], w.corner_vertex[3]);
  EXPECT_EQ(w.corner_vertex[1], w.corner_vertex[4]);  // the nearest pair distance adds
}
