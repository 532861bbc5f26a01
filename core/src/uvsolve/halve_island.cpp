#include "uvsolve/halve_island.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "atlas/flat_split.h"

namespace soupuv::uvsolve::detail {

bool halve_island(UvLayout& L, uint32_t island) {
  std::vector<uint32_t> tris;
  for (size_t t = 0; t < L.island.size(); ++t)
    if (L.island[t] == island) tris.push_back(uint32_t(t));
  const size_t n = tris.size();
  if (n < 2) return false;
  std::vector<Vec2> points, centroid(n);
  std::vector<double> area(n);
  points.reserve(3 * n);
  for (size_t i = 0; i < n; ++i) {
    const auto& v = L.corner_vertex[tris[i]];
    for (uint32_t c : v) points.push_back(L.uv[c]);
    centroid[i] = (L.uv[v[0]] + L.uv[v[1]] + L.uv[v[2]]) * (1.0 / 3);
    area[i] = 0.5 * std::abs(signed_area2(L, tris[i]));
  }
  const std::vector<int> cut = atlas::area_median_sides(points, centroid, area);
  if (cut.empty()) return false;
  std::vector<uint8_t> side(cut.begin(), cut.end());

  // The line's cut through triangles by centroid zigzags across thin ones
  // (noisy soups' slivers): a triangle with two or three edge neighbours on
  // the other side goes there, which shortens the seam; a few passes.
  std::vector<std::array<uint32_t, 3>> local(n);
  for (size_t i = 0; i < n; ++i) local[i] = L.corner_vertex[tris[i]];
  std::vector<std::array<uint32_t, 3>> neighbour(n, {UINT32_MAX, UINT32_MAX, UINT32_MAX});
  {
    std::vector<std::pair<uint64_t, uint32_t>> edges;
    edges.reserve(3 * n);
    for (size_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) {
        const auto [a, b] = std::minmax(local[i][k], local[i][(k + 1) % 3]);
        edges.push_back({(uint64_t(a) << 32) | b, uint32_t(3 * i + k)});
      }
    std::sort(edges.begin(), edges.end());
    for (size_t e = 0; e + 1 < edges.size(); ++e)
      if (edges[e].first == edges[e + 1].first && (e + 2 == edges.size() || edges[e + 2].first != edges[e].first)) {
        const uint32_t x = edges[e].second, y = edges[e + 1].second;
        neighbour[x / 3][x % 3] = y / 3;
        neighbour[y / 3][y % 3] = x / 3;
      }
  }
  for (int pass = 0; pass < 4; ++pass) {
    bool moved = false;
    for (size_t i = 0; i < n; ++i) {
      int across = 0;
      for (uint32_t j : neighbour[i]) across += j != UINT32_MAX && side[j] != side[i];
      if (across >= 2) {
        side[i] = 1 - side[i];
        moved = true;
      }
    }
    if (!moved) break;
  }

  // Each side as one piece: a side's smaller pieces join the other side
  // (they touch the island only through it), twice, since a moved piece can
  // join two of the other side's pieces.
  std::vector<uint32_t> component;
  for (int pass = 0; pass < 2; ++pass)
    for (uint8_t s = 0; s < 2; ++s) {
      std::vector<uint8_t> active(n);
      for (size_t i = 0; i < n; ++i) active[i] = side[i] == s;
      const uint32_t pieces = edge_components(local, &active, component);
      if (pieces <= 1) continue;
      std::vector<double> piece_area(pieces, 0);
      for (size_t i = 0; i < n; ++i)
        if (active[i]) piece_area[component[i]] += area[i];
      const uint32_t keep = uint32_t(std::max_element(piece_area.begin(), piece_area.end()) - piece_area.begin());
      for (size_t i = 0; i < n; ++i)
        if (active[i] && component[i] != keep) side[i] = 1 - s;
    }
  for (uint8_t s = 0; s < 2; ++s) {
    std::vector<uint8_t> active(n);
    for (size_t i = 0; i < n; ++i) active[i] = side[i] == s;
    if (edge_components(local, &active, component) != 1) return false;
  }

  // Side 1 becomes a new island; its vertices shared with side 0 are copied.
  std::vector<uint8_t> on_side0(L.uv.size(), 0);
  for (size_t i = 0; i < n; ++i)
    if (side[i] == 0)
      for (uint32_t v : local[i]) on_side0[v] = 1;
  std::vector<uint32_t> copy(L.uv.size(), UINT32_MAX);
  const uint32_t fresh = L.island_count++;
  for (size_t i = 0; i < n; ++i) {
    if (side[i] == 0) continue;
    const uint32_t t = tris[i];
    L.island[t] = fresh;
    for (uint32_t& v : L.corner_vertex[t]) {
      if (!on_side0[v]) continue;
      if (copy[v] == UINT32_MAX) {
        copy[v] = uint32_t(L.uv.size());
        L.uv.push_back(L.uv[v]);
      }
      v = copy[v];
    }
  }
  return true;
}

std::vector<HalvingRound> halve_to_pack(const std::vector<geometry::AdjacentPair>& pairs,
                                        const HalvingOptions& options, int texture_size, double padding_px,
                                        int threads, UvLayout& layout,
                                        std::vector<std::array<Vec2, 3>>& corner_uvs, PackFigures& packed) {
  std::vector<HalvingRound> rounds;
  if (layout.island_count > options.max_islands) return rounds;
  UvLayout trial = layout;
  for (int round = 0; round < options.rounds && packed.utilisation < options.below; ++round) {
    const auto islands = island_triangles(trial);
    std::vector<double> area(islands.size(), 0);
    for (size_t i = 0; i < islands.size(); ++i)
      for (uint32_t t : islands[i]) area[i] += 0.5 * std::abs(signed_area2(trial, t));
    const double largest = *std::max_element(area.begin(), area.end());
    HalvingRound h;
    for (size_t i = 0; i < islands.size(); ++i)
      if (area[i] >= 0.5 * largest) h.halved += halve_island(trial, uint32_t(i));
    h.kept_pairs = kept_pair_share(pairs, trial);
    if (h.halved == 0 || h.kept_pairs < options.min_kept_pairs) {
      rounds.push_back(h);
      break;
    }
    std::vector<std::array<Vec2, 3>> uvs;
    const PackFigures tried = pack_islands(trial, texture_size, padding_px, threads, uvs);
    h.packed = true;
    h.utilisation = tried.utilisation;
    h.kept = tried.utilisation > packed.utilisation;
    rounds.push_back(h);
    if (!h.kept) break;
    packed = tried;
    corner_uvs = std::move(uvs);
    layout = trial;
  }
  return rounds;
}

}  // namespace soupuv::uvsolve::detail
