// Flattening a piece from its own shape (piece_flatten.h): a flat sheet is
// kept within the budget; an open box (five faces of a cube) cannot be laid
// flat within it, and its refusal names the stretch it was heading for,
// which union_merge's forecast uses: at least 1 and above the budget.
#include "uvsolve/piece_flatten.h"

#include <gtest/gtest.h>

#include <map>
#include <numeric>

namespace soupuv {
namespace {

using uvsolve::detail::Outcome;
using uvsolve::detail::UvLayout;

// n x n cells on each listed face of the unit cube (face: axis 0-2, side
// 0/1), shared vertices, outward winding; one island.
struct Shape {
  Soup soup;
  UvLayout layout;
};

Shape cube_faces(int n, const std::vector<std::pair<int, int>>& faces) {
  Shape s;
  std::map<std::array<int, 3>, uint32_t> id;
  auto vertex = [&](std::array<int, 3> g) {
    auto [it, fresh] = id.emplace(g, uint32_t(s.soup.positions.size()));
    if (fresh) s.soup.positions.push_back(Vec3{g[0] / double(n), g[1] / double(n), g[2] / double(n)});
    return it->second;
  };
  for (auto [axis, side] : faces) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        auto at = [&](int a, int b) {
          std::array<int, 3> g{};
          g[axis] = side * n, g[u] = a, g[v] = b;
          return vertex(g);
        };
        const uint32_t p = at(i, j), q = at(i + 1, j), r = at(i + 1, j + 1), w = at(i, j + 1);
        if (side == 1) {
          s.soup.triangles.push_back({p, q, r}), s.soup.triangles.push_back({p, r, w});
        } else {
          s.soup.triangles.push_back({p, r, q}), s.soup.triangles.push_back({p, w, r});
        }
      }
  }
  for (const Tri& t : s.soup.triangles) s.layout.corner_vertex.push_back({t[0], t[1], t[2]});
  s.layout.uv.assign(s.soup.positions.size(), Vec2{0, 0});
  s.layout.island.assign(s.soup.triangles.size(), 0);
  s.layout.island_count = 1;
  return s;
}

Outcome flatten_all(const Shape& s, double max_stretch, double& floor) {
  std::vector<uint32_t> tris(s.soup.triangles.size());
  std::iota(tris.begin(), tris.end(), 0u);
  const uvsolve::detail::PieceMesh m = uvsolve::detail::piece_mesh(s.soup, 64.0, tris, s.layout);
  uvsolve::detail::Piece out;
  return uvsolve::detail::flatten(m, tris, 0.05, max_stretch, 10, out, &floor);
}

TEST(PieceFlatten, AFlatSheetIsKept) {
  double floor = -1;
  EXPECT_EQ(flatten_all(cube_faces(6, {{2, 1}}), 1.25, floor), Outcome::kept);
  EXPECT_EQ(floor, -1) << "no refusal, no floor";
}

TEST(PieceFlatten, AnOpenBoxIsRefusedForStretchWithItsFloorAboveTheBudget) {
  const Shape box = cube_faces(6, {{0, 0}, {0, 1}, {1, 0}, {1, 1}, {2, 0}});
  double floor = -1;
  ASSERT_EQ(flatten_all(box, 1.05, floor), Outcome::stretch);
  EXPECT_GE(floor, 1.0);
  EXPECT_GT(floor, 1.05);
}

}  // namespace
}  // namespace soupuv
