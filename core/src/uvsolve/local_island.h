// One island of the layout as a small mesh of its own (private to the UV
// solve): the solvers (ARAP in untangle.cpp, SLIM in island_solve.cpp) work
// on local vertex numbers and each triangle's rest shape.
//
// Input : the soup, the rest scale (UV units per 3D length), the island's
//         triangles and the layout.
// Output: its layout vertices (global, sorted), the triangles in local
//         numbers, their rest shapes (flattened at the scale, positive) and
//         the vertices' UVs; write_back() puts moved UVs into the layout.
#pragma once

#include <algorithm>
#include <array>
#include <vector>

#include "transfer/sym_dirichlet.h"
#include "uvsolve/uv_layout.h"

namespace soupuv::uvsolve::detail {

struct LocalIsland {
  std::vector<uint32_t> global;
  std::vector<std::array<uint32_t, 3>> triangles;
  std::vector<transfer::detail::RestTriangle> rest;
  std::vector<Vec2> uv;
};

inline LocalIsland local_island(const Soup& soup, double uv_per_length, const std::vector<uint32_t>& tris,
                                const UvLayout& L) {
  LocalIsland m;
  for (uint32_t t : tris) m.global.insert(m.global.end(), L.corner_vertex[t].begin(), L.corner_vertex[t].end());
  std::sort(m.global.begin(), m.global.end());
  m.global.erase(std::unique(m.global.begin(), m.global.end()), m.global.end());
  m.triangles.resize(tris.size());
  m.rest.resize(tris.size());
  for (size_t j = 0; j < tris.size(); ++j) {
    for (int k = 0; k < 3; ++k)
      m.triangles[j][k] =
          uint32_t(std::lower_bound(m.global.begin(), m.global.end(), L.corner_vertex[tris[j]][k]) - m.global.begin());
    m.rest[j] = transfer::detail::rest_triangle(soup.corner(tris[j], 0), soup.corner(tris[j], 1),
                                                soup.corner(tris[j], 2), uv_per_length, 1.0);
  }
  m.uv.resize(m.global.size());
  for (size_t v = 0; v < m.global.size(); ++v) m.uv[v] = L.uv[m.global[v]];
  return m;
}

inline void write_back(const LocalIsland& m, UvLayout& L) {
  for (size_t v = 0; v < m.global.size(); ++v) L.uv[m.global[v]] = m.uv[v];
}

}  // namespace soupuv::uvsolve::detail
