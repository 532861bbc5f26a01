#include "uvsolve/uv_mesh.h"

#include <algorithm>

#include "soupuv/union_find.h"

namespace soupuv::uvsolve::detail {
namespace {

// Vertices again as the corners glued through edges that exactly two
// triangles use in opposite directions, at the mean UV of their corners.
// Why: where the noise reaches the shortest edges, the weld puts a corner
// on a neighbouring vertex; the triangles around it then use an edge in
// the same direction as a neighbour, or an edge three times, and no flat
// map of that topology exists (every such triangle folds). Gluing only
// through consistently oriented manifold edges detaches the wrong corner
// and keeps every right join (around a manifold vertex the corners are
// joined through its fan's edges anyway).
void glue_through_oriented_edges(const std::vector<std::array<Vec2, 3>>& corner_uvs, UvLayout& L) {
  const size_t n = L.corner_vertex.size();
  struct EdgeUse {
    uint64_t key;
    uint32_t corner;  // triangle * 3 + k: the edge from corner k to k + 1
    bool forward;     // from the smaller vertex id to the larger
  };
  std::vector<EdgeUse> uses;
  uses.reserve(3 * n);
  for (size_t t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = L.corner_vertex[t][k], b = L.corner_vertex[t][(k + 1) % 3];
      if (a == b) continue;
      uses.push_back({(uint64_t(std::min(a, b)) << 32) | std::max(a, b), uint32_t(3 * t + k), a < b});
    }
  std::sort(uses.begin(), uses.end(), [](const EdgeUse& x, const EdgeUse& y) {
    return x.key != y.key ? x.key < y.key : x.corner < y.corner;
  });
  UnionFind corners(3 * n);
  auto next = [](uint32_t c) { return c - c % 3 + (c % 3 + 1) % 3; };
  for (size_t i = 0; i < uses.size();) {
    size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key) ++j;
    if (j - i == 2 && uses[i].forward != uses[i + 1].forward) {
      const uint32_t c = uses[i].corner, d = uses[i + 1].corner;
      corners.unite(c, next(d));
      corners.unite(next(c), d);
    }
    i = j;
  }
  std::vector<uint32_t> id(3 * n, UINT32_MAX);
  std::vector<Vec2> sum;
  std::vector<uint32_t> count;
  for (uint32_t c = 0; c < 3 * n; ++c) {
    const uint32_t root = corners.find(c);
    if (id[root] == UINT32_MAX) {
      id[root] = uint32_t(sum.size());
      sum.push_back({0, 0});
      count.push_back(0);
    }
    const uint32_t v = id[root];
    sum[v] = sum[v] + corner_uvs[c / 3][c % 3];
    ++count[v];
    L.corner_vertex[c / 3][c % 3] = v;
  }
  L.uv.resize(sum.size());
  for (size_t v = 0; v < sum.size(); ++v) L.uv[v] = (1.0 / count[v]) * sum[v];
}

}  // namespace

UvLayout build_uv_mesh(const Soup& soup, const geometry::Weld& weld,
                       const std::vector<std::array<Vec2, 3>>& corner_uvs,
                       const std::vector<int>& corner_chart, double texel, double uv_per_length) {
  const size_t n = soup.triangles.size();
  const size_t corners = 3 * n;
  // Corners grouped by welded vertex (counting sort).
  std::vector<uint32_t> first(weld.vertex_count + 1, 0), order(corners);
  for (size_t c = 0; c < corners; ++c) ++first[weld.corner_vertex[c] + 1];
  for (uint32_t v = 0; v < weld.vertex_count; ++v) first[v + 1] += first[v];
  {
    std::vector<uint32_t> at(first.begin(), first.end() - 1);
    for (size_t c = 0; c < corners; ++c) order[at[weld.corner_vertex[c]]++] = uint32_t(c);
  }
  auto uv_of = [&](uint32_t c) { return corner_uvs[c / 3][c % 3]; };
  auto pos_of = [&](uint32_t c) { return soup.corner(c / 3, int(c % 3)); };

  UvLayout L;
  L.corner_vertex.resize(n);
  std::vector<uint32_t> group_rep;  // per new vertex: its first corner
  std::vector<Vec2> sum;
  std::vector<uint32_t> count;
  for (uint32_t w = 0; w < weld.vertex_count; ++w) {
    const size_t begin = group_rep.size();
    for (uint32_t i = first[w]; i < first[w + 1]; ++i) {
      const uint32_t c = order[i];
      const Vec2 p = uv_of(c);
      // The first group of this welded vertex whose representative passes
      // the continuity test (greedy, in corner order: deterministic).
      size_t g = begin;
      for (; g < group_rep.size(); ++g) {
        const uint32_t r = group_rep[g];
        if (corner_chart[r] != corner_chart[c]) continue;
        const double tol = texel + 2 * uv_per_length * norm(pos_of(r) - pos_of(c));
        if (norm(uv_of(r) - p) <= tol) break;
      }
      if (g == group_rep.size()) {
        group_rep.push_back(c);
        sum.push_back({0, 0});
        count.push_back(0);
      }
      sum[g] = sum[g] + p;
      ++count[g];
      L.corner_vertex[c / 3][c % 3] = uint32_t(g);
    }
  }
  L.uv.resize(group_rep.size());
  for (size_t g = 0; g < group_rep.size(); ++g) L.uv[g] = (1.0 / count[g]) * sum[g];
  glue_through_oriented_edges(corner_uvs, L);
  L.island_count = edge_components(L.corner_vertex, nullptr, L.island);
  split_vertices_by_island(L);
  return L;
}

}  // namespace soupuv::uvsolve::detail
