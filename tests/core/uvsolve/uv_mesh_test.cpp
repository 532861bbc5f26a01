// build_uv_mesh's topology: whatever the weld joined, the layout is an
// oriented surface (no edge used twice the same way, none three times).
#include "uvsolve/uv_mesh.h"

#include <gtest/gtest.h>

#include <map>

#include "soupuv/geometry/weld.h"

namespace soupuv {
namespace {

// A strip of 2 x n unit squares in the plane, two triangles each, as a soup
// with its identity map as the transferred UVs.
struct Strip {
  Soup soup;
  std::vector<std::array<Vec2, 3>> uv;
};

Strip strip(int n) {
  Strip s;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < 2; ++j) {
      const double x = i, y = j;
      const Vec3 p[4] = {{x, y, 0}, {x + 1, y, 0}, {x + 1, y + 1, 0}, {x, y + 1, 0}};
      for (const auto& q : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
        Tri t;
        std::array<Vec2, 3> w;
        for (int k = 0; k < 3; ++k) {
          s.soup.positions.push_back(p[q[k]]);
          t[k] = uint32_t(s.soup.positions.size() - 1);
          w[k] = {0.01 * p[q[k]].x, 0.01 * p[q[k]].y};
        }
        s.soup.triangles.push_back(t);
        s.soup.origins.push_back({});
        s.uv.push_back(w);
      }
    }
  return s;
}

// Directed edge uses of the layout: (a, b) -> count.
std::map<std::pair<uint32_t, uint32_t>, int> directed_edges(const uvsolve::detail::UvLayout& L) {
  std::map<std::pair<uint32_t, uint32_t>, int> uses;
  for (const auto& t : L.corner_vertex)
    for (int k = 0; k < 3; ++k) ++uses[{t[k], t[(k + 1) % 3]}];
  return uses;
}

TEST(UvMesh, SoundWeldGivesOneIsland) {
  const Strip s = strip(6);
  const geometry::Weld weld = geometry::weld_corners(s.soup, 1e-9);
  const auto L = uvsolve::detail::build_uv_mesh(s.soup, weld, s.uv, std::vector<int>(3 * s.soup.triangles.size(), 0),
                                                1.0 / 1024, 0.01);
  EXPECT_EQ(L.island_count, 1u);
  EXPECT_EQ(L.uv.size(), size_t(3 * 7)) << "one layout vertex per grid vertex";
}

TEST(UvMesh, CornerWeldedToTheWrongVertexIsDetachedNotGlued) {
  // The weld puts one corner of a triangle on its neighbour's far vertex
  // (what noise past the shortest edge does): two triangles then use an edge
  // the same way. The layout must not glue through it.
  const Strip s = strip(6);
  geometry::Weld weld = geometry::weld_corners(s.soup, 1e-9);
  // Triangle 4 is (1,0) (2,0) (2,1); its corner (2,1) goes to the vertex
  // (3,1) (corner 2 of triangle 8, (2,0) (3,0) (3,1)). Its edge (2,0)->(3,1)
  // is then used by triangle 9 the same way and by triangle 8 back.
  const uint32_t wrong = weld.corner_vertex[3 * 8 + 2];
  weld.corner_vertex[3 * 4 + 2] = wrong;
  const auto L = uvsolve::detail::build_uv_mesh(s.soup, weld, s.uv, std::vector<int>(3 * s.soup.triangles.size(), 0),
                                                1.0 / 1024, 0.01);
  for (const auto& [edge, count] : directed_edges(L)) EXPECT_EQ(count, 1) << edge.first << "->" << edge.second;
  std::map<std::pair<uint32_t, uint32_t>, int> undirected;
  for (const auto& [edge, count] : directed_edges(L))
    undirected[{std::min(edge.first, edge.second), std::max(edge.first, edge.second)}] += count;
  for (const auto& [edge, count] : undirected) EXPECT_LE(count, 2);
  // Everything but the detached triangle stays one island.
  std::map<uint32_t, int> sizes;
  for (uint32_t i : L.island) ++sizes[i];
  int largest = 0;
  for (const auto& [island, size] : sizes) largest = std::max(largest, size);
  EXPECT_GE(largest, int(s.soup.triangles.size()) - 1);
}

}  // namespace
}  // namespace soupuv
