#include "uvsolve/fold_cut.h"
#include "uvsolve/untangle.h"

#include <algorithm>
#include <cmath>
#include <deque>

namespace soupuv::uvsolve::detail {
namespace {

// Triangles sharing an edge of the layout as it was before the cut (the
// corners' vertices at that point), as CSR lists.
struct Neighbours {
  std::vector<uint32_t> first, list;
};

Neighbours edge_neighbours(const std::vector<std::array<uint32_t, 3>>& cv) {
  struct Use {
    uint64_t key;
    uint32_t t;
  };
  std::vector<Use> uses;
  uses.reserve(3 * cv.size());
  for (size_t t = 0; t < cv.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      uint32_t a = cv[t][k], b = cv[t][(k + 1) % 3];
      if (a > b) std::swap(a, b);
      uses.push_back({(uint64_t(a) << 32) | b, uint32_t(t)});
    }
  std::sort(uses.begin(), uses.end(), [](const Use& x, const Use& y) { return x.key < y.key || (x.key == y.key && x.t < y.t); });
  std::vector<std::pair<uint32_t, uint32_t>> pairs;
  for (size_t i = 0; i < uses.size();) {
    size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key) ++j;
    for (size_t a = i; a < j; ++a)
      for (size_t b = a + 1; b < j && b < a + 8; ++b) {
        pairs.push_back({uses[a].t, uses[b].t});
        pairs.push_back({uses[b].t, uses[a].t});
      }
    i = j;
  }
  Neighbours nb;
  nb.first.assign(cv.size() + 1, 0);
  for (const auto& p : pairs) ++nb.first[p.first + 1];
  for (size_t t = 0; t < cv.size(); ++t) nb.first[t + 1] += nb.first[t];
  nb.list.resize(pairs.size());
  std::vector<uint32_t> at(nb.first.begin(), nb.first.end() - 1);
  for (const auto& p : pairs) nb.list[at[p.first]++] = p.second;
  return nb;
}

// Third corner m of a triangle unfolded across its edge (i, j), placed at
// uv_i, uv_j: similar to the 3D triangle, on the side that makes the
// triangle positive in corner order. False when the edge is degenerate.
bool unfold_corner(Vec3 pi, Vec3 pj, Vec3 pm, Vec2 ui, Vec2 uj, bool positive_left, Vec2& um) {
  const Vec3 e = pj - pi, f = pm - pi;
  const double e2 = norm2(e);
  const Vec2 E = uj - ui;
  if (!(e2 > 0) || !(norm(E) > 0)) return false;
  const double along = dot(f, e) / e2;
  const double height = norm(cross(e, f)) / e2;  // |h| / |e|, relative to the edge
  const Vec2 left{-E.y, E.x};
  um = ui + along * E + (positive_left ? height : -height) * left;
  return true;
}

}  // namespace

FoldCutFigures cut_folds(const Soup& soup, double uv_per_length, double collapse_ratio,
                         UvLayout& L) {
  FoldCutFigures f;
  const size_t n = L.corner_vertex.size();
  // 1. Flipped or collapsed triangles are cut out.
  std::vector<uint8_t> good(n, 1);
  for (size_t t = 0; t < n; ++t)
    if (is_folded(soup, uv_per_length, collapse_ratio, L, t)) {
      good[t] = 0;
      ++f.cut_triangles;
    }
  const Neighbours nb = edge_neighbours(L.corner_vertex);
  const std::vector<std::array<uint32_t, 3>> before = L.corner_vertex;
  L.island_count = edge_components(L.corner_vertex, &good, L.island);
  // Cut triangles get their own vertices (placed below); the good ones keep
  // theirs, split where their island split.
  for (size_t t = 0; t < n; ++t)
    if (!good[t]) L.island[t] = 0;  // placeholder until placed
  split_vertices_by_island(L);
  if (f.cut_triangles == 0) return f;

  // 2. Unfold the cut triangles, breadth first from the placed ones.
  L.unfolded.assign(n, 0);
  std::vector<uint8_t> placed = good;
  std::deque<uint32_t> queue;
  auto push_neighbours = [&](uint32_t t) {
    for (uint32_t i = nb.first[t]; i < nb.first[t + 1]; ++i)
      if (!placed[nb.list[i]]) queue.push_back(nb.list[i]);
  };
  for (size_t t = 0; t < n; ++t)
    if (good[t]) push_neighbours(uint32_t(t));
  auto place_from = [&](uint32_t t) {
    for (uint32_t i = nb.first[t]; i < nb.first[t + 1]; ++i) {
      const uint32_t s = nb.list[i];
      if (!placed[s]) continue;
      // The shared edge: corners k (of t) and their matches in s, by the
      // layout vertices before the cut.
      int ks[3], count = 0, m = -1;
      for (int k = 0; k < 3; ++k) {
        ks[k] = -1;
        for (int q = 0; q < 3; ++q)
          if (before[s][q] == before[t][k]) ks[k] = q;
        if (ks[k] >= 0) ++count;
        else m = k;
      }
      if (count != 2 || m < 0) continue;
      const int i0 = (m + 1) % 3, j0 = (m + 2) % 3;  // corner order i0 -> j0 -> m
      const Vec2 ui = L.uv[L.corner_vertex[s][ks[i0]]], uj = L.uv[L.corner_vertex[s][ks[j0]]];
      Vec2 um;
      // Corner order (i0, j0, m) is counter-clockwise when m lies left of i0 -> j0.
      if (!unfold_corner(soup.corner(t, i0), soup.corner(t, j0), soup.corner(t, m), ui, uj, true, um)) continue;
      L.corner_vertex[t][i0] = L.corner_vertex[s][ks[i0]];
      L.corner_vertex[t][j0] = L.corner_vertex[s][ks[j0]];
      L.corner_vertex[t][m] = uint32_t(L.uv.size());
      L.uv.push_back(um);
      L.island[t] = L.island[s];
      return true;
    }
    return false;
  };
  size_t seed = 0;
  while (true) {
    while (!queue.empty()) {
      const uint32_t t = queue.front();
      queue.pop_front();
      if (placed[t] || !place_from(t)) continue;
      placed[t] = 1;
      L.unfolded[t] = 1;
      ++f.unfolded_triangles;
      push_neighbours(t);
    }
    while (seed < n && placed[seed]) ++seed;
    if (seed == n) break;
    // A new island at the triangle's rest shape (flattened, counter-clockwise).
    const uint32_t t = uint32_t(seed);
    const Vec3 p0 = soup.corner(t, 0), p1 = soup.corner(t, 1), p2 = soup.corner(t, 2);
    const double l = norm(p1 - p0);
    Vec2 u0{0, 0}, u1{uv_per_length * l, 0}, u2{0, 0};
    if (l > 0) {
      const double along = dot(p2 - p0, p1 - p0) / l, height = norm(cross(p1 - p0, p2 - p0)) / l;
      u2 = {uv_per_length * along, uv_per_length * height};
    }
    const uint32_t base = uint32_t(L.uv.size());
    L.uv.push_back(u0);
    L.uv.push_back(u1);
    L.uv.push_back(u2);
    L.corner_vertex[t] = {base, base + 1, base + 2};
    L.island[t] = L.island_count++;
    placed[t] = 1;
    L.unfolded[t] = 1;
    ++f.seeded_islands;
    push_neighbours(t);
  }
  return f;
}

}  // namespace soupuv::uvsolve::detail
