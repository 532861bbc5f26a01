// Independent checks of a finished atlas for the tests: they rebuild chart
// topology from the UVs alone and test overlap exactly, instead of trusting
// the library's own bookkeeping.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <tuple>
#include <vector>

#include "soupuv/atlas/build_atlas.h"

namespace atlas_checks {

using soupuv::Vec2;

struct ChartTopology {
  int euler = 0;
  int boundary_loops = 0;
};

// A chart's vertices are the distinct (mesh vertex, UV) pairs of its corners;
// an edge is interior when two faces of the chart use it with the same UVs.
inline std::vector<ChartTopology> chart_topology(const soupuv::TriMesh& mesh,
                                                 const soupuv::atlas::Atlas& atlas) {
  using Key = std::tuple<int, double, double>;
  std::vector<std::map<Key, int>> vertex_ids(atlas.chart_count);
  std::vector<std::map<std::pair<int, int>, int>> edge_use(atlas.chart_count);
  std::vector<int> faces(atlas.chart_count, 0);
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    int c = atlas.face_chart[f];
    ++faces[c];
    int id[3];
    for (int k = 0; k < 3; ++k) {
      Key key{mesh.faces[f][k], atlas.face_uvs[f][k].x, atlas.face_uvs[f][k].y};
      auto it = vertex_ids[c].emplace(key, static_cast<int>(vertex_ids[c].size())).first;
      id[k] = it->second;
    }
    for (int k = 0; k < 3; ++k) ++edge_use[c][{std::min(id[k], id[(k + 1) % 3]), std::max(id[k], id[(k + 1) % 3])}];
  }
  std::vector<ChartTopology> out(atlas.chart_count);
  for (int c = 0; c < atlas.chart_count; ++c) {
    int v = static_cast<int>(vertex_ids[c].size());
    int e = static_cast<int>(edge_use[c].size());
    out[c].euler = v - e + faces[c];
    // Boundary edges form loops; count them as connected components of the
    // boundary graph (a vertex on two loops would join them and fail the test).
    std::map<int, std::vector<int>> adj;
    for (auto& [edge, uses] : edge_use[c])
      if (uses == 1) { adj[edge.first].push_back(edge.second); adj[edge.second].push_back(edge.first); }
    std::set<int> seen;
    for (auto& [start, _] : adj) {
      if (seen.count(start)) continue;
      ++out[c].boundary_loops;
      std::vector<int> stack{start};
      seen.insert(start);
      while (!stack.empty()) {
        int x = stack.back();
        stack.pop_back();
        if (adj[x].size() != 2) out[c].boundary_loops += 100;  // not a simple loop
        for (int y : adj[x])
          if (seen.insert(y).second) stack.push_back(y);
      }
    }
  }
  return out;
}

inline double signed_area(const std::array<Vec2, 3>& p) {
  return 0.5 * soupuv::cross(p[1] - p[0], p[2] - p[0]);
}

// Exact test whether two triangles' interiors intersect (separating axis over
// the six edge normals); shared edges and vertices alone do not count.
inline bool interiors_overlap(const std::array<Vec2, 3>& a, const std::array<Vec2, 3>& b) {
  const double eps = 1e-12;
  for (const auto* t : {&a, &b})
    for (int k = 0; k < 3; ++k) {
      Vec2 e = (*t)[(k + 1) % 3] - (*t)[k];
      Vec2 n{-e.y, e.x};
      double amin = INFINITY, amax = -INFINITY, bmin = INFINITY, bmax = -INFINITY;
      for (const Vec2& p : a) { amin = std::min(amin, soupuv::dot(n, p)); amax = std::max(amax, soupuv::dot(n, p)); }
      for (const Vec2& p : b) { bmin = std::min(bmin, soupuv::dot(n, p)); bmax = std::max(bmax, soupuv::dot(n, p)); }
      double scale = soupuv::norm(n) * 1.0;
      if (amax <= bmin + eps * scale || bmax <= amin + eps * scale) return false;
    }
  return true;
}

// Pairs of faces whose UV interiors overlap, by a uniform grid and the exact
// test above: the slow twin of the rasterised overlap figure.
inline long long overlapping_pairs(const soupuv::atlas::Atlas& atlas) {
  const int g = 256;
  std::vector<std::vector<int>> cells(g * g);
  long long pairs = 0;
  std::set<std::pair<int, int>> tested;
  for (size_t f = 0; f < atlas.face_uvs.size(); ++f) {
    const auto& t = atlas.face_uvs[f];
    int x0 = std::clamp(static_cast<int>(std::min({t[0].x, t[1].x, t[2].x}) * g), 0, g - 1);
    int x1 = std::clamp(static_cast<int>(std::max({t[0].x, t[1].x, t[2].x}) * g), 0, g - 1);
    int y0 = std::clamp(static_cast<int>(std::min({t[0].y, t[1].y, t[2].y}) * g), 0, g - 1);
    int y1 = std::clamp(static_cast<int>(std::max({t[0].y, t[1].y, t[2].y}) * g), 0, g - 1);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        for (int o : cells[y * g + x])
          if (tested.insert({o, static_cast<int>(f)}).second &&
              interiors_overlap(atlas.face_uvs[o], t))
            ++pairs;
        cells[y * g + x].push_back(static_cast<int>(f));
      }
  }
  return pairs;
}

}  // namespace atlas_checks
