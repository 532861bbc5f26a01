// Welding the extractors' per-thread output. See edge_vertex_weld.h.
#include "edge_vertex_weld.h"

#include <algorithm>

namespace soupuv::proxy {

TriMesh weld_edge_vertices(std::vector<std::vector<EdgeVertex>>& vertices,
                           const std::vector<std::vector<std::array<uint64_t, 3>>>& triangles) {
  auto by_key = [](const EdgeVertex& a, const EdgeVertex& b) { return a.key < b.key; };
  // Each thread's list sorted in parallel, then merged: copies of one key
  // are bit-identical, so the order among equal keys does not matter.
#pragma omp parallel for schedule(dynamic, 1)
  for (long l = 0; l < long(vertices.size()); ++l) std::sort(vertices[size_t(l)].begin(), vertices[size_t(l)].end(), by_key);
  std::vector<EdgeVertex> all;
  for (auto& v : vertices) {
    size_t middle = all.size();
    all.insert(all.end(), v.begin(), v.end());
    std::vector<EdgeVertex>().swap(v);
    std::inplace_merge(all.begin(), all.begin() + long(middle), all.end(), by_key);
  }
  vertices.clear();
  all.erase(std::unique(all.begin(), all.end(),
                        [](const EdgeVertex& a, const EdgeVertex& b) { return a.key == b.key; }),
            all.end());
  TriMesh mesh;
  mesh.vertices.reserve(all.size());
  for (const auto& v : all) mesh.vertices.push_back(v.position);
  auto index_of = [&](uint64_t key) {
    return int(std::lower_bound(all.begin(), all.end(), key,
                                [](const EdgeVertex& v, uint64_t k) { return v.key < k; }) -
               all.begin());
  };
  // The corner lookups (binary searches) are independent: in parallel, each
  // list written to its own range of faces, so the order stays fixed.
  std::vector<size_t> start(triangles.size() + 1, 0);
  for (size_t l = 0; l < triangles.size(); ++l) start[l + 1] = start[l] + triangles[l].size();
  mesh.faces.resize(start.back());
  for (size_t l = 0; l < triangles.size(); ++l) {
    const auto& list = triangles[l];
#pragma omp parallel for schedule(static)
    for (long n = 0; n < long(list.size()); ++n) {
      const auto& t = list[size_t(n)];
      mesh.faces[start[l] + size_t(n)] = {index_of(t[0]), index_of(t[1]), index_of(t[2])};
    }
  }
  return mesh;
}

}  // namespace soupuv::proxy
