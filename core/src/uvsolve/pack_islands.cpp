#include "uvsolve/pack_islands.h"

#include <algorithm>
#include <cmath>

#include "atlas/pack.h"
#include "atlas/raster_pack.h"
#include "soupuv/errors.h"

namespace soupuv::uvsolve::detail {

PackFigures pack_islands(const UvLayout& L, int texture_size, double padding_px, int threads,
                         std::vector<std::array<Vec2, 3>>& corner_uvs) {
  const auto islands = island_triangles(L);
  const size_t k = islands.size();
  std::vector<std::vector<Vec2>> uv(k);
  std::vector<std::vector<std::array<int, 3>>> tris(k);
  std::vector<std::vector<std::array<int, 2>>> boundary(k);
  std::vector<uint32_t> local(L.uv.size(), UINT32_MAX);
  for (size_t i = 0; i < k; ++i) {
    for (uint32_t t : islands[i]) {
      std::array<int, 3> tri;
      for (int c = 0; c < 3; ++c) {
        const uint32_t v = L.corner_vertex[t][c];
        if (local[v] == UINT32_MAX) {
          local[v] = uint32_t(uv[i].size());
          uv[i].push_back(L.uv[v]);
        }
        tri[c] = int(local[v]);
      }
      tris[i].push_back(tri);
    }
    // Boundary edges: used once (as directed edges, an edge used by two
    // triangles of one orientation appears once each way).
    std::vector<std::pair<uint64_t, std::array<int, 2>>> edges;
    for (const auto& tri : tris[i])
      for (int c = 0; c < 3; ++c) {
        int a = tri[c], b = tri[(c + 1) % 3];
        edges.push_back({(uint64_t(std::min(a, b)) << 32) | uint32_t(std::max(a, b)), {a, b}});
      }
    std::sort(edges.begin(), edges.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    for (size_t e = 0; e < edges.size();) {
      size_t f = e;
      while (f < edges.size() && edges[f].first == edges[e].first) ++f;
      // An odd count leaves the edge on the boundary (even-odd rule).
      if ((f - e) % 2 == 1) boundary[i].push_back(edges[e].second);
      e = f;
    }
    for (uint32_t t : islands[i])
      for (int c = 0; c < 3; ++c) local[L.corner_vertex[t][c]] = UINT32_MAX;
  }
  std::vector<atlas::PackChart> charts(k);
  for (size_t i = 0; i < k; ++i) charts[i] = {&uv[i], &tris[i], nullptr, &boundary[i]};
  atlas::RasterPackOptions ro;
  ro.threads = threads;
  // Many small islands: fewer turns (each costs a rasterisation per packing).
  if (k > 2000) ro.angles = 4;
  else if (k > 200) ro.angles = 8;
  const atlas::RasterPackResult r = atlas::raster_pack(charts, texture_size, padding_px, 0, ro);
  if (!(r.scale > 0))
    throw Error(ErrorCode::limit_exceeded,
                std::to_string(k) + " UV islands do not fit a " + std::to_string(texture_size) +
                    " texture with " + std::to_string(padding_px) + " texels of padding");
  PackFigures f;
  f.texels_per_uv = r.scale;
  f.attempts = r.attempts;
  corner_uvs.assign(L.corner_vertex.size(), {});
  for (size_t i = 0; i < k; ++i) {
    size_t j = 0;
    for (uint32_t t : islands[i]) {
      for (int c = 0; c < 3; ++c) corner_uvs[t][c] = uv[i][tris[i][j][c]];
      ++j;
    }
  }
  for (size_t t = 0; t < corner_uvs.size(); ++t) {
    const auto& p = corner_uvs[t];
    f.utilisation += 0.5 * std::abs(cross(p[1] - p[0], p[2] - p[0]));
  }
  return f;
}

}  // namespace soupuv::uvsolve::detail
