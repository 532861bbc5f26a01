// Soups of two islands for the uvsolve tests: the soup's triangles split
// between island 0 and island 1, each island with layout vertices of its
// own (the seam between them open), laid out by the soup's (x, y) at kScale
// UV units per unit length, island 1 moved 1,000 units along u; the weld
// joins every soup edge two triangles share (vertex ids are the weld).
#pragma once

#include <cmath>
#include <utility>
#include <functional>
#include <vector>

#include "soupuv/geometry/weld.h"
#include "soupuv/soup.h"
#include "uvsolve/uv_layout.h"

namespace soupuv::test {

constexpr double kScale = 64.0;  // UV units per unit length

struct TwoIslands {
  Soup soup;
  uvsolve::detail::UvLayout layout;
  std::vector<geometry::AdjacentPair> pairs;
};

// An n x n sheet of the unit square in z = 0, two triangles per cell,
// counter-clockwise seen from +z; cell (i, j) holds triangles 2 (i n + j)
// and 2 (i n + j) + 1.
inline Soup grid_sheet(int n) {
  Soup s;
  auto id = [&](int i, int j) { return uint32_t(i * (n + 1) + j); };
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) s.positions.push_back(Vec3{double(i) / n, double(j) / n, 0});
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const uint32_t p = id(i, j), q = id(i + 1, j), r = id(i + 1, j + 1), w = id(i, j + 1);
      s.triangles.push_back({p, q, r});
      s.triangles.push_back({p, r, w});
    }
  s.origins.resize(s.triangles.size());
  return s;
}

// The unit sphere by latitude rings and longitude segments (poles as
// single vertices), outward counter-clockwise.
inline Soup uv_sphere(int rings, int segments) {
  Soup s;
  const double pi = std::acos(-1.0);
  s.positions.push_back({0, 0, 1});
  for (int r = 1; r < rings; ++r)
    for (int k = 0; k < segments; ++k) {
      const double th = pi * r / rings, ph = 2 * pi * k / segments;
      s.positions.push_back({std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)});
    }
  s.positions.push_back({0, 0, -1});
  const uint32_t south = uint32_t(s.positions.size() - 1);
  auto at = [&](int r, int k) { return uint32_t(1 + (r - 1) * segments + (k % segments)); };
  for (int k = 0; k < segments; ++k) s.triangles.push_back({0, at(1, k), at(1, k + 1)});
  for (int r = 1; r + 1 < rings; ++r)
    for (int k = 0; k < segments; ++k) {
      s.triangles.push_back({at(r, k), at(r + 1, k), at(r + 1, k + 1)});
      s.triangles.push_back({at(r, k), at(r + 1, k + 1), at(r, k + 1)});
    }
  for (int k = 0; k < segments; ++k) s.triangles.push_back({at(rings - 1, k), south, at(rings - 1, k + 1)});
  for (Tri& t : s.triangles) {  // outward
    const Vec3 a = s.positions[t[0]], b = s.positions[t[1]], c = s.positions[t[2]];
    if (dot(cross(b - a, c - a), a + b + c) < 0) std::swap(t[1], t[2]);
  }
  s.origins.resize(s.triangles.size());
  return s;
}

inline TwoIslands two_islands(Soup soup, const std::function<uint32_t(size_t triangle)>& island_of) {
  TwoIslands h;
  h.soup = std::move(soup);
  const uint32_t np = uint32_t(h.soup.positions.size());
  for (size_t t = 0; t < h.soup.triangles.size(); ++t) {
    const uint32_t island = island_of(t);
    const Tri& c = h.soup.triangles[t];
    h.layout.corner_vertex.push_back({c[0] + island * np, c[1] + island * np, c[2] + island * np});
    h.layout.island.push_back(island);
  }
  h.layout.island_count = 2;
  h.layout.uv.resize(2 * np);
  for (uint32_t v = 0; v < np; ++v) {
    const Vec3 x = h.soup.positions[v];
    h.layout.uv[v] = {kScale * x.x, kScale * x.y};
    h.layout.uv[np + v] = {1000 + kScale * x.x, kScale * x.y};
  }
  geometry::Weld weld;
  for (const Tri& t : h.soup.triangles)
    for (uint32_t v : t) weld.corner_vertex.push_back(v);
  weld.vertex_count = np;
  h.pairs = geometry::edge_adjacency(weld, h.soup.triangles.size());
  return h;
}

// Every triangle counter-clockwise in its island's layout.
inline size_t flipped_triangles(const uvsolve::detail::UvLayout& L) {
  size_t flipped = 0;
  for (size_t t = 0; t < L.corner_vertex.size(); ++t) {
    const auto& c = L.corner_vertex[t];
    flipped += !(cross(L.uv[c[1]] - L.uv[c[0]], L.uv[c[2]] - L.uv[c[0]]) > 0);
  }
  return flipped;
}

// Welded pairs whose two triangles lie in different islands.
inline size_t seam_pairs(const std::vector<geometry::AdjacentPair>& pairs, const uvsolve::detail::UvLayout& L) {
  size_t n = 0;
  for (const auto& p : pairs) n += L.island[p.a] != L.island[p.b];
  return n;
}

}  // namespace soupuv::test
