#include "transfer/island_mesh.h"

#include <algorithm>
#include <numeric>

#include "soupuv/union_find.h"

namespace soupuv::transfer::detail {

IslandMeshes island_meshes(const Soup& soup, const quality::Weld& weld, const quality::Weld* also,
                           const std::vector<std::array<Vec2, 3>>& corner_uvs, double texel,
                           double uv_per_length) {
  const size_t n = corner_uvs.size(), corners = 3 * n;
  IslandMeshes m;
  // Continuous copies join, unless that would put two corners of one
  // triangle in one vertex (one weld never does; two welds' groups chained
  // could). Each class keeps its triangles to check that.
  UnionFind copies(corners);
  std::vector<std::vector<uint32_t>> triangles_of(corners);
  for (uint32_t c = 0; c < corners; ++c) triangles_of[c] = {c / 3};
  auto uv_of = [&](uint32_t c) { return corner_uvs[c / 3][c % 3]; };
  auto xyz_of = [&](uint32_t c) { return soup.corner(c / 3, int(c % 3)); };
  auto join = [&](uint32_t a, uint32_t b) {
    uint32_t ra = copies.find(a), rb = copies.find(b);
    if (ra == rb) return;
    auto& ta = triangles_of[ra];
    auto& tb = triangles_of[rb];
    for (uint32_t t : ta)
      if (std::find(tb.begin(), tb.end(), t) != tb.end()) return;
    copies.unite(ra, rb);
    const uint32_t root = copies.find(ra), other = root == ra ? rb : ra;
    auto& keep = triangles_of[root];
    auto& gone = triangles_of[other];
    keep.insert(keep.end(), gone.begin(), gone.end());
    gone = {};
  };
  for (const quality::Weld* w : {&weld, also}) {
    if (!w || w->corner_vertex.size() != corners) continue;
    // Corners of each welded vertex (CSR).
    std::vector<uint32_t> start(w->vertex_count + 1, 0), members(corners);
    for (size_t c = 0; c < corners; ++c) ++start[w->corner_vertex[c] + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (size_t c = 0; c < corners; ++c) members[fill[w->corner_vertex[c]]++] = uint32_t(c);
    for (uint32_t v = 0; v < w->vertex_count; ++v)
      for (uint32_t i = start[v]; i < start[v + 1]; ++i)
        for (uint32_t j = i + 1; j < start[v + 1]; ++j) {
          const uint32_t a = members[i], b = members[j];
          if (norm(uv_of(a) - uv_of(b)) <= texel + 2 * norm(xyz_of(a) - xyz_of(b)) * uv_per_length)
            join(a, b);
        }
  }

  // Island vertices in order of first corner; their UV the corners' mean.
  m.vertex_of_corner.assign(corners, UINT32_MAX);
  std::vector<uint32_t> id_of_root(corners, UINT32_MAX);
  std::vector<uint32_t> uses;
  for (uint32_t c = 0; c < corners; ++c) {
    uint32_t& id = id_of_root[copies.find(c)];
    if (id == UINT32_MAX) {
      id = uint32_t(m.vertex_uv.size());
      m.vertex_uv.push_back({0, 0});
      uses.push_back(0);
    }
    m.vertex_of_corner[c] = id;
    m.vertex_uv[id] = m.vertex_uv[id] + uv_of(c);
    ++uses[id];
  }
  for (size_t v = 0; v < m.vertex_uv.size(); ++v) m.vertex_uv[v] = m.vertex_uv[v] * (1.0 / uses[v]);
  for (uint32_t c = 0; c < corners; ++c) {
    const Vec2 d = uv_of(c) - m.vertex_uv[m.vertex_of_corner[c]];
    m.snapped_corners += d.x != 0 || d.y != 0;
  }

  // Islands: triangles joined through shared island vertices.
  UnionFind tris(n);
  std::vector<uint32_t> first_triangle(m.vertex_uv.size(), UINT32_MAX);
  for (uint32_t c = 0; c < corners; ++c) {
    uint32_t& f = first_triangle[m.vertex_of_corner[c]];
    if (f == UINT32_MAX) f = c / 3;
    else tris.unite(f, c / 3);
  }
  std::vector<uint32_t> island_of_root(n, UINT32_MAX);
  for (uint32_t t = 0; t < n; ++t) {
    uint32_t& id = island_of_root[tris.find(t)];
    if (id == UINT32_MAX) {
      id = uint32_t(m.islands.size());
      m.islands.emplace_back();
    }
    m.islands[id].push_back(t);
  }
  std::stable_sort(m.islands.begin(), m.islands.end(),
                   [](const auto& a, const auto& b) { return a.size() > b.size(); });
  return m;
}

}  // namespace soupuv::transfer::detail
