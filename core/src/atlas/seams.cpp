#include "atlas/seams.h"

#include <algorithm>
#include <cmath>
#include <queue>

namespace soupuv::atlas {

std::vector<double> laplacian_magnitude(const TriMesh& mesh) {
  const size_t nv = mesh.vertices.size();
  std::vector<Vec3> laplace(nv, Vec3{0, 0, 0});
  std::vector<double> area(nv, 0);
  for (const auto& f : mesh.faces) {
    Vec3 p[3] = {mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]]};
    double a = 0.5 * norm(cross(p[1] - p[0], p[2] - p[0]));
    for (int k = 0; k < 3; ++k) {
      area[f[k]] += a / 3;
      // Corner k weighs the opposite edge (i, j) by half its cotangent.
      int i = (k + 1) % 3, j = (k + 2) % 3;
      Vec3 u = p[i] - p[k], v = p[j] - p[k];
      double s = norm(cross(u, v));
      double w = s > 0 ? 0.5 * dot(u, v) / s : 0.0;
      laplace[f[i]] += w * (p[j] - p[i]);
      laplace[f[j]] += w * (p[i] - p[j]);
    }
  }
  std::vector<double> magnitude(nv, 0);
  for (size_t v = 0; v < nv; ++v)
    magnitude[v] = area[v] > 0 ? norm(laplace[v]) / area[v] : 0.0;
  return magnitude;
}

SeamPaths trace_seam_hints(const TriMesh& mesh, const MeshTopology& t,
                           const std::vector<SeamHint>& hints, double alpha, double beta) {
  SeamPaths out;
  if (hints.empty()) return out;
  const int nv = static_cast<int>(mesh.vertices.size());
  const int ne = static_cast<int>(t.edge_vertices.size());
  std::vector<double> lap = laplacian_magnitude(mesh);
  double lap_max = *std::max_element(lap.begin(), lap.end());
  if (!(lap_max > 0)) lap_max = 1;
  const double a = alpha * t.mean_edge_length, b = beta * t.mean_edge_length;

  // Vertex -> incident edges (CSR).
  std::vector<int> start(nv + 1, 0), incident(2 * ne);
  for (const auto& e : t.edge_vertices) { ++start[e[0] + 1]; ++start[e[1] + 1]; }
  for (int v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (int e = 0; e < ne; ++e) {
    incident[fill[t.edge_vertices[e][0]]++] = e;
    incident[fill[t.edge_vertices[e][1]]++] = e;
  }
  std::vector<double> cost(ne);
  for (int e = 0; e < ne; ++e) {
    int x = t.edge_vertices[e][0], y = t.edge_vertices[e][1];
    cost[e] = norm(mesh.vertices[x] - mesh.vertices[y]) +
              a * (1 - (lap[x] + lap[y]) / (2 * lap_max)) +
              b * std::fabs(lap[x] - lap[y]) / lap_max;
  }
  auto nearest_vertex = [&](Vec3 p) {
    int best = 0;
    double d = INFINITY;
    for (int v = 0; v < nv; ++v)
      if (double dv = norm2(mesh.vertices[v] - p); dv < d) { d = dv; best = v; }
    return best;
  };

  std::vector<char> used(ne, 0);
  std::vector<double> dist(nv);
  std::vector<int> via(nv);
  for (size_t h = 0; h < hints.size(); ++h) {
    std::vector<int> blocked;  // edges of this hint's earlier segments
    for (size_t s = 0; s + 1 < hints[h].points.size(); ++s) {
      int src = nearest_vertex(hints[h].points[s]);
      int dst = nearest_vertex(hints[h].points[s + 1]);
      if (src == dst) continue;
      std::fill(dist.begin(), dist.end(), INFINITY);
      std::fill(via.begin(), via.end(), -1);
      using Item = std::pair<double, int>;
      std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
      dist[src] = 0;
      queue.push({0, src});
      while (!queue.empty()) {
        auto [d, v] = queue.top();
        queue.pop();
        if (v == dst) break;
        if (d > dist[v]) continue;
        for (int k = start[v]; k < start[v + 1]; ++k) {
          int e = incident[k];
          if (used[e]) continue;
          int w = t.edge_vertices[e][0] == v ? t.edge_vertices[e][1] : t.edge_vertices[e][0];
          if (d + cost[e] < dist[w]) {
            dist[w] = d + cost[e];
            via[w] = e;
            queue.push({dist[w], w});
          }
        }
      }
      if (!std::isfinite(dist[dst])) {
        out.warnings.push_back("seam hint " + std::to_string(h) + ": point " +
                               std::to_string(s + 1) + " cannot be reached without crossing "
                               "the hint's earlier segments; segment skipped");
        continue;
      }
      for (int v = dst; v != src;) {
        int e = via[v];
        blocked.push_back(e);
        out.edges.push_back(e);
        v = t.edge_vertices[e][0] == v ? t.edge_vertices[e][1] : t.edge_vertices[e][0];
      }
      for (int e : blocked) used[e] = 1;
    }
    // Infinite cost applies within a hint; the next hint may cross this one.
    for (int e : blocked) used[e] = 0;
  }
  std::sort(out.edges.begin(), out.edges.end());
  out.edges.erase(std::unique(out.edges.begin(), out.edges.end()), out.edges.end());
  return out;
}

}  // namespace soupuv::atlas
