// A flat 8 x 8 grid soup mapped isometrically (UV = 0.05 + 0.1 * (x, y)) on
// one chart: the hand-made starting map of the UV repair and re-weld tests,
// which then move, split or fold chosen vertices.
#pragma once

#include <array>
#include <vector>

#include "soupuv/mesh.h"
#include "soupuv/geometry/weld.h"
#include "testing/shapes.h"
#include "soupuv/soup.h"

namespace soupuv::testing {

constexpr int kGridCells = 8;     // grid cells per side
constexpr double kGridUvScale = 0.1;  // UV units per 3D length

inline TriMesh uv_grid_mesh() {
  TriMesh m;
  for (int j = 0; j <= kGridCells; ++j)
    for (int i = 0; i <= kGridCells; ++i) m.vertices.push_back({double(i), double(j), 0});
  auto id = [](int i, int j) { return j * (kGridCells + 1) + i; };
  for (int j = 0; j < kGridCells; ++j)
    for (int i = 0; i < kGridCells; ++i) {
      m.faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.faces.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

inline Vec2 grid_isometric_uv(Vec3 p) { return {0.05 + kGridUvScale * p.x, 0.05 + kGridUvScale * p.y}; }

struct UvGridCase {
  Soup soup = shapes::to_soup(uv_grid_mesh(), 0.0);
  geometry::Weld weld = geometry::weld_corners(soup, 1e-9);
  std::vector<int> chart = std::vector<int>(soup.triangles.size(), 0);
  std::vector<std::array<Vec2, 3>> uvs;
  UvGridCase() {
    for (size_t t = 0; t < soup.triangles.size(); ++t)
      uvs.push_back({grid_isometric_uv(soup.corner(t, 0)), grid_isometric_uv(soup.corner(t, 1)),
                     grid_isometric_uv(soup.corner(t, 2))});
  }
};

}  // namespace soupuv::testing
