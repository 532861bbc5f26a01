#include "uvsolve/reembed.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <queue>

#include "transfer/slim.h"
#include "uvsolve/piece_flatten.h"

namespace soupuv::uvsolve::detail {
namespace {

constexpr double kCreaseWeight = 4;

// The piece's edge-connected parts, or, when it is one, its two halves:
// each triangle goes to the nearer of two far-apart seeds, by shortest
// paths between the centroids of joined triangles.
std::vector<std::vector<uint32_t>> split(const Soup& soup, const std::vector<uint32_t>& tris, const PieceMesh& m) {
  const size_t n = tris.size();
  std::vector<std::vector<uint32_t>> parts;
  if (m.components > 1) {
    parts.resize(m.components);
    for (uint32_t i = 0; i < n; ++i) parts[m.component[i]].push_back(tris[i]);
    return parts;
  }
  std::vector<Vec3> centroid(n), normal(n);
  for (size_t i = 0; i < n; ++i) {
    const Vec3 a = soup.corner(tris[i], 0), b = soup.corner(tris[i], 1), c = soup.corner(tris[i], 2);
    centroid[i] = (1.0 / 3) * (a + b + c);
    const Vec3 m = cross(b - a, c - a);
    const double l = norm(m);
    normal[i] = l > 0 ? (1.0 / l) * m : Vec3{0, 0, 0};
  }
  // A step across a crease counts longer (kCreaseWeight x (1 - cos of the
  // dihedral angle) more), so the two halves meet along creases where
  // there are some: halves of a part are flatter than halves of a sphere.
  const double crease = kCreaseWeight;
  std::vector<double> dist;
  std::vector<int> label;
  // Multi-source Dijkstra: distance and nearest source per triangle.
  auto sweep = [&](const std::vector<uint32_t>& sources) {
    dist.assign(n, INFINITY);
    label.assign(n, -1);
    using Item = std::pair<double, uint32_t>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> q;
    for (size_t s = 0; s < sources.size(); ++s) {
      dist[sources[s]] = 0;
      label[sources[s]] = int(s);
      q.push({0, sources[s]});
    }
    while (!q.empty()) {
      const auto [d, i] = q.top();
      q.pop();
      if (d > dist[i]) continue;
      for (uint32_t j : m.neighbours[i]) {
        const double dj = d + norm(centroid[j] - centroid[i]) * (1 + crease * (1 - dot(normal[i], normal[j])));
        if (dj < dist[j]) {
          dist[j] = dj;
          label[j] = label[i];
          q.push({dj, j});
        }
      }
    }
  };
  auto farthest = [&]() { return uint32_t(std::max_element(dist.begin(), dist.end()) - dist.begin()); };
  sweep({0});
  const uint32_t a = farthest();
  sweep({a});
  const uint32_t b = farthest();
  sweep({a, b});
  parts.resize(2);
  for (uint32_t i = 0; i < n; ++i) parts[label[i] == 1].push_back(tris[i]);
  if (parts[1].empty() || parts[0].empty()) {  // every centroid equal: split by index
    std::vector<uint32_t> all = tris;
    parts[0].assign(all.begin(), all.begin() + all.size() / 2);
    parts[1].assign(all.begin() + all.size() / 2, all.end());
  }
  return parts;
}

}  // namespace

ReembedFigures reembed_islands(const Soup& soup, double uv_per_length, const std::vector<uint8_t>& selected,
                               double cell, double max_stretch, int solve_iterations, int threads,
                               UvLayout& L) {
  ReembedFigures f;
  const auto islands = island_triangles(L);
  std::vector<uint32_t> chosen;
  for (uint32_t i = 0; i < islands.size(); ++i)
    if (i < selected.size() && selected[i] && islands[i].size() > 1) chosen.push_back(i);
  // Largest first: the parallel loop ends on small ones.
  std::stable_sort(chosen.begin(), chosen.end(),
                   [&](uint32_t a, uint32_t b) { return islands[a].size() > islands[b].size(); });
  if (chosen.empty()) return f;
  std::vector<std::vector<Piece>> pieces_of(chosen.size());
  size_t split_topology = 0, split_flip = 0, split_stretch = 0, lapping = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(std::max(1, threads)) \
    reduction(+ : split_topology, split_flip, split_stretch, lapping)
  for (size_t c = 0; c < chosen.size(); ++c) {
    std::vector<std::vector<uint32_t>> work{islands[chosen[c]]};
    while (!work.empty()) {
      std::vector<uint32_t> tris = std::move(work.back());
      work.pop_back();
      Piece piece;
      if (tris.size() == 1) {
        // One triangle: its own shape.
        const auto r = transfer::detail::rest_triangle(soup.corner(tris[0], 0), soup.corner(tris[0], 1),
                                                       soup.corner(tris[0], 2), uv_per_length, 1.0);
        const auto& cv = L.corner_vertex[tris[0]];
        piece.tris = tris;
        piece.corner = {{0, 1, 2}};
        if (r.valid) piece.uv.assign(r.x.begin(), r.x.end());
        else piece.uv = {L.uv[cv[0]], L.uv[cv[1]], L.uv[cv[2]]};
        pieces_of[c].push_back(std::move(piece));
        continue;
      }
      const PieceMesh m = piece_mesh(soup, uv_per_length, tris, L);
      const Outcome outcome = m.components > 1 ? Outcome::parts
                                               : flatten(m, tris, cell, max_stretch, solve_iterations, piece);
      switch (outcome) {
        case Outcome::kept: pieces_of[c].push_back(std::move(piece)); continue;
        // A piece that laps over itself although it neither folds nor
        // stretches winds around a point of its boundary (a noisy fan of
        // more than a full turn): halving it would cut far more than the
        // overlap split cuts around the lap, so it is kept for that split.
        case Outcome::overlap: ++lapping; pieces_of[c].push_back(std::move(piece)); continue;
        case Outcome::parts: break;
        case Outcome::topology: ++split_topology; break;
        case Outcome::flip: ++split_flip; break;
        case Outcome::stretch: ++split_stretch; break;
      }
      for (auto& part : split(soup, tris, m)) work.push_back(std::move(part));
    }
  }
  f.split_topology = split_topology;
  f.split_flip = split_flip;
  f.split_stretch = split_stretch;
  f.lapping_pieces = lapping;
  // Pieces become islands: the first keeps the island's id.
  f.islands = chosen.size();
  for (size_t c = 0; c < chosen.size(); ++c)
    for (size_t p = 0; p < pieces_of[c].size(); ++p) {
      const Piece& piece = pieces_of[c][p];
      ++f.pieces;
      f.singleton_pieces += piece.tris.size() == 1;
      const uint32_t id = p == 0 ? chosen[c] : L.island_count++;
      for (uint32_t t : piece.tris) L.island[t] = id;
    }
  // Every piece gets fresh vertices (its own joins), the old ones are
  // dropped by the compaction.
  for (const auto& list : pieces_of)
    for (const Piece& piece : list) {
      const uint32_t base = uint32_t(L.uv.size());
      L.uv.insert(L.uv.end(), piece.uv.begin(), piece.uv.end());
      for (size_t j = 0; j < piece.tris.size(); ++j)
        for (int k = 0; k < 3; ++k) L.corner_vertex[piece.tris[j]][k] = base + piece.corner[j][k];
    }
  split_vertices_by_island(L);
  return f;
}

}  // namespace soupuv::uvsolve::detail
