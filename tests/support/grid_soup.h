// grid_soup(n, noise): an n x n grid of quads in the unit square (z = 0),
// two triangles each, as a soup with per-copy noise (the weld and metric
// suites' flat test case).
#pragma once

#include "soupuv/soup.h"
#include "testing/shapes.h"

namespace soupuv::testing {

inline Soup grid_soup(int n, double noise) {
  TriMesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.vertices.push_back({double(i) / n, double(j) / n, 0});
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      int a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
      m.faces.push_back({a, b, c});
      m.faces.push_back({a, c, d});
    }
  return shapes::to_soup(m, noise, 3);
}

}  // namespace soupuv::testing
