// Taubin smoothing with the uniform umbrella operator. See
// soupuv/proxy/taubin_smooth.h.
#include "soupuv/proxy/taubin_smooth.h"

#include <algorithm>
#include <vector>

namespace soupuv::proxy {

void taubin_smooth(TriMesh& mesh, int iterations, double lambda, double mu) {
  const size_t nv = mesh.vertices.size();
  if (iterations <= 0 || nv == 0) return;
  // Neighbour lists (CSR) from the faces' edges; each edge seen from both
  // faces, so deduplicate per vertex.
  std::vector<std::vector<int>> adjacency(nv);
  for (const auto& t : mesh.faces)
    for (int k = 0; k < 3; ++k) {
      adjacency[t[k]].push_back(t[(k + 1) % 3]);
      adjacency[t[k]].push_back(t[(k + 2) % 3]);
    }
  std::vector<int> start(nv + 1, 0), neighbours;
  for (size_t v = 0; v < nv; ++v) {
    auto& a = adjacency[v];
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
    start[v + 1] = start[v] + int(a.size());
    neighbours.insert(neighbours.end(), a.begin(), a.end());
    std::vector<int>().swap(a);
  }
  std::vector<Vec3> next(nv);
  auto step = [&](double factor) {
#pragma omp parallel for schedule(static)
    for (long v = 0; v < long(nv); ++v) {
      int b = start[v], e = start[v + 1];
      if (b == e) {
        next[v] = mesh.vertices[v];
        continue;
      }
      Vec3 mean{0, 0, 0};
      for (int i = b; i < e; ++i) mean += mesh.vertices[neighbours[i]];
      mean = mean / double(e - b);
      next[v] = mesh.vertices[v] + factor * (mean - mesh.vertices[v]);
    }
    mesh.vertices.swap(next);
  };
  for (int it = 0; it < iterations; ++it) {
    step(lambda);
    step(mu);
  }
}

}  // namespace soupuv::proxy
