#include "uvsolve/uv_mesh.h"

namespace soupuv::uvsolve::detail {

UvLayout build_uv_mesh(const Soup& soup, const quality::Weld& weld,
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
  L.island_count = edge_components(L.corner_vertex, nullptr, L.island);
  split_vertices_by_island(L);
  return L;
}

}  // namespace soupuv::uvsolve::detail
