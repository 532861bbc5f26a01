#include "edge_vertex_weld.h"

#include <algorithm>

namespace soupuv::proxy {

TriMesh weld_edge_vertices(std::vector<std::vector<EdgeVertex>>& vertices,
                           const std::vector<std::vector<std::array<uint64_t, 3>>>& triangles) {
  std::vector<EdgeVertex> all;
  for (auto& v : vertices) all.insert(all.end(), v.begin(), v.end());
  vertices.clear();
  std::sort(all.begin(), all.end(), [](const EdgeVertex& a, const EdgeVertex& b) { return a.key < b.key; });
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
  for (const auto& list : triangles)
    for (const auto& t : list) mesh.faces.push_back({index_of(t[0]), index_of(t[1]), index_of(t[2])});
  return mesh;
}

}  // namespace soupuv::proxy
