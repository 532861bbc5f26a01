#include "uvsolve/union_merge.h"

#include <algorithm>
#include <numeric>

#include "uvsolve/pairs_by_triangle.h"
#include "uvsolve/piece_flatten.h"

namespace soupuv::uvsolve::detail {
namespace {
// Attempts may flatten this many times the soup's triangles in all.
constexpr size_t kFlattenBudget = 8;
}  // namespace

UnionMergeFigures merge_by_reflattening(const Soup& soup, double uv_per_length,
                                        const std::vector<geometry::AdjacentPair>& pairs, double cell,
                                        double max_stretch, int solve_iterations, size_t attempts_per_island,
                                        UvLayout& L) {
  UnionMergeFigures f;
  std::vector<std::vector<uint32_t>> members = island_triangles(L);
  const size_t n = L.corner_vertex.size();
  const PairsByTriangle by_triangle(pairs, n);
  // Seams between islands, longest (most shared pairs) first.
  std::vector<std::pair<uint64_t, uint32_t>> seams;
  {
    std::vector<uint64_t> keys;
    for (const auto& p : pairs) {
      const uint32_t i = L.island[p.a], j = L.island[p.b];
      if (i != j) keys.push_back((uint64_t(std::min(i, j)) << 32) | std::max(i, j));
    }
    std::sort(keys.begin(), keys.end());
    for (size_t k = 0; k < keys.size();) {
      size_t e = k;
      while (e < keys.size() && keys[e] == keys[k]) ++e;
      seams.push_back({keys[k], uint32_t(e - k)});
      k = e;
    }
    std::stable_sort(seams.begin(), seams.end(), [](const auto& x, const auto& y) { return x.second > y.second; });
  }
  std::vector<uint32_t> root(L.island_count);
  std::iota(root.begin(), root.end(), 0u);
  auto find = [&](uint32_t x) {
    while (root[x] != x) x = root[x] = root[root[x]];
    return x;
  };
  std::vector<size_t> attempts(L.island_count, 0);
  std::vector<uint32_t> vertex_of(L.uv.size());
  std::iota(vertex_of.begin(), vertex_of.end(), 0u);
  std::vector<uint32_t> touched;
  // The work bound: triangles flattened in all attempts together.
  const size_t budget = kFlattenBudget * n;
  size_t flattened = 0;
  for (const auto& [key, count] : seams) {
    uint32_t i = find(uint32_t(key >> 32)), j = find(uint32_t(key));
    if (i == j || attempts[i] >= attempts_per_island || attempts[j] >= attempts_per_island) continue;
    const size_t size = members[i].size() + members[j].size();
    if (flattened + size > budget) continue;
    flattened += size;
    ++f.attempts;
    if (members[i].size() < members[j].size()) std::swap(i, j);  // j: the smaller
    // Close the seam: the smaller island's shared corners take the larger's vertices.
    touched.clear();
    for (uint32_t t : members[j])
      for (uint32_t e = by_triangle.first[t]; e < by_triangle.first[t + 1]; ++e) {
        const auto& p = pairs[by_triangle.index[e]];
        const bool t_is_a = p.a == t;
        const uint32_t o = t_is_a ? p.b : p.a;
        if (find(L.island[o]) != i) continue;
        for (int s = 0; s < 2; ++s) {
          const uint32_t mine = L.corner_vertex[t][t_is_a ? p.a_corner[s] : p.b_corner[s]];
          const uint32_t theirs = L.corner_vertex[o][t_is_a ? p.b_corner[s] : p.a_corner[s]];
          if (vertex_of[mine] != mine) continue;  // joined already
          vertex_of[mine] = theirs;
          touched.push_back(mine);
        }
      }
    std::vector<uint32_t> tris = members[i];
    tris.insert(tris.end(), members[j].begin(), members[j].end());
    const PieceMesh m = piece_mesh(soup, uv_per_length, tris, L, &vertex_of);
    Piece piece;
    const bool kept = m.components == 1 &&
                      flatten(m, tris, cell, max_stretch, solve_iterations, piece) == Outcome::kept;
    for (uint32_t v : touched) vertex_of[v] = v;
    if (!kept) {
      ++attempts[i], ++attempts[j];  // only refusals count: a join may be followed by more
      continue;
    }
    ++f.joined;
    const uint32_t base = uint32_t(L.uv.size());
    L.uv.insert(L.uv.end(), piece.uv.begin(), piece.uv.end());
    vertex_of.resize(L.uv.size());
    std::iota(vertex_of.begin() + base, vertex_of.end(), base);
    for (size_t k = 0; k < tris.size(); ++k) {
      for (int c = 0; c < 3; ++c) L.corner_vertex[tris[k]][c] = base + piece.corner[k][c];
      L.island[tris[k]] = i;
    }
    root[j] = i;
    members[i] = std::move(tris);
    members[j].clear();
    attempts[i] = std::max(attempts[i], attempts[j]);
  }
  if (f.joined == 0) return f;
  // Island ids stay dense: renumber the survivors.
  std::vector<uint32_t> id(L.island_count, UINT32_MAX);
  uint32_t count = 0;
  for (size_t t = 0; t < n; ++t) {
    uint32_t& k = id[L.island[t]];
    if (k == UINT32_MAX) k = count++;
    L.island[t] = k;
  }
  L.island_count = count;
  split_vertices_by_island(L);
  return f;
}

}  // namespace soupuv::uvsolve::detail
