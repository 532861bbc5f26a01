#include "uvsolve/uv_layout.h"

#include <algorithm>
#include <unordered_map>

#include "soupuv/union_find.h"

namespace soupuv::uvsolve::detail {

double signed_area2(const UvLayout& layout, size_t t) {
  const auto& v = layout.corner_vertex[t];
  return cross(layout.uv[v[1]] - layout.uv[v[0]], layout.uv[v[2]] - layout.uv[v[0]]);
}

void split_vertices_by_island(UvLayout& layout) {
  std::unordered_map<uint64_t, uint32_t> id;
  id.reserve(layout.uv.size() * 2);
  std::vector<Vec2> uv;
  uv.reserve(layout.uv.size());
  const uint64_t islands = std::max<uint64_t>(layout.island_count, 1);
  for (size_t t = 0; t < layout.corner_vertex.size(); ++t)
    for (uint32_t& v : layout.corner_vertex[t]) {
      const uint64_t key = uint64_t(v) * islands + layout.island[t];
      auto [it, fresh] = id.try_emplace(key, uint32_t(uv.size()));
      if (fresh) uv.push_back(layout.uv[v]);
      v = it->second;
    }
  layout.uv = std::move(uv);
}

uint32_t edge_components(const std::vector<std::array<uint32_t, 3>>& corner_vertex,
                         const std::vector<uint8_t>* active, std::vector<uint32_t>& component) {
  const size_t n = corner_vertex.size();
  struct EdgeUse {
    uint64_t key;
    uint32_t triangle;
  };
  std::vector<EdgeUse> edges;
  edges.reserve(3 * n);
  for (size_t t = 0; t < n; ++t) {
    if (active && !(*active)[t]) continue;
    for (int k = 0; k < 3; ++k) {
      uint32_t a = corner_vertex[t][k], b = corner_vertex[t][(k + 1) % 3];
      if (a > b) std::swap(a, b);
      edges.push_back({(uint64_t(a) << 32) | b, uint32_t(t)});
    }
  }
  std::sort(edges.begin(), edges.end(), [](const EdgeUse& x, const EdgeUse& y) { return x.key < y.key; });
  UnionFind sets(n);
  for (size_t i = 1; i < edges.size(); ++i)
    if (edges[i].key == edges[i - 1].key) sets.unite(edges[i].triangle, edges[i - 1].triangle);
  component.assign(n, UINT32_MAX);
  std::vector<uint32_t> number(n, UINT32_MAX);
  uint32_t count = 0;
  for (size_t t = 0; t < n; ++t) {
    if (active && !(*active)[t]) continue;
    const uint32_t root = sets.find(uint32_t(t));
    if (number[root] == UINT32_MAX) number[root] = count++;
    component[t] = number[root];
  }
  return count;
}

void compact_island_ids(UvLayout& layout) {
  std::vector<uint32_t> id(layout.island_count, UINT32_MAX);
  uint32_t count = 0;
  for (uint32_t& island : layout.island) {
    uint32_t& k = id[island];
    if (k == UINT32_MAX) k = count++;
    island = k;
  }
  layout.island_count = count;
}

double kept_pair_share(const std::vector<geometry::AdjacentPair>& pairs, const UvLayout& L) {
  if (pairs.empty()) return 1;
  size_t kept = 0;
  for (const auto& p : pairs)
    kept += L.corner_vertex[p.a][p.a_corner[0]] == L.corner_vertex[p.b][p.b_corner[0]] &&
            L.corner_vertex[p.a][p.a_corner[1]] == L.corner_vertex[p.b][p.b_corner[1]];
  return double(kept) / double(pairs.size());
}

std::vector<std::vector<uint32_t>> island_triangles(const UvLayout& layout) {
  std::vector<std::vector<uint32_t>> out(layout.island_count);
  for (size_t t = 0; t < layout.island.size(); ++t) out[layout.island[t]].push_back(uint32_t(t));
  return out;
}

std::vector<std::pair<uint64_t, uint32_t>> seams_longest_first(const std::vector<geometry::AdjacentPair>& pairs,
                                                               const UvLayout& layout) {
  std::vector<uint64_t> keys;
  for (const auto& p : pairs) {
    const uint32_t i = layout.island[p.a], j = layout.island[p.b];
    if (i != j) keys.push_back((uint64_t(std::min(i, j)) << 32) | std::max(i, j));
  }
  std::sort(keys.begin(), keys.end());
  std::vector<std::pair<uint64_t, uint32_t>> seams;
  for (size_t k = 0; k < keys.size();) {
    size_t e = k;
    while (e < keys.size() && keys[e] == keys[k]) ++e;
    seams.push_back({keys[k], uint32_t(e - k)});
    k = e;
  }
  std::stable_sort(seams.begin(), seams.end(), [](const auto& x, const auto& y) { return x.second > y.second; });
  return seams;
}

}  // namespace soupuv::uvsolve::detail
