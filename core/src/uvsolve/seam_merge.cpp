#include "uvsolve/seam_merge.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "soupuv/union_find.h"
#include "uvsolve/overlap_split.h"
#include "uvsolve/island_grid.h"
#include "uvsolve/piece_flatten.h"
#include "uvsolve/pairs_by_triangle.h"
#include "uvsolve/rigid_fit.h"
#include "uvsolve/untangle.h"

namespace soupuv::uvsolve::detail {

namespace {
// The L2 stretch of the triangles `tris` as the layout maps them, against
// their soup shapes (piece_flatten.h's measure, the flattenings' budget).
double island_stretch(const Soup& soup, double uv_per_length, const std::vector<uint32_t>& tris, const UvLayout& L) {
  std::vector<transfer::detail::RestTriangle> rest;
  std::vector<std::array<Vec2, 3>> corners;
  rest.reserve(tris.size());
  corners.reserve(tris.size());
  for (uint32_t t : tris) {
    rest.push_back(
        transfer::detail::rest_triangle(soup.corner(t, 0), soup.corner(t, 1), soup.corner(t, 2), uv_per_length, 1.0));
    corners.push_back(corners_of(L, t));
  }
  return rest_stretch_l2(rest, corners);
}
}  // namespace

SeamMergeFigures merge_seams(const Soup& soup, const std::vector<geometry::AdjacentPair>& pairs,
                             double cell, double uv_per_length, double collapse_ratio, double max_stretch,
                             size_t max_attempts, size_t max_relax_triangles, UvLayout& L) {
  SeamMergeFigures f;
  auto islands = island_triangles(L);
  // Seams: welded pairs whose triangles lie in different islands, counted
  // per island pair.
  std::map<std::pair<uint32_t, uint32_t>, size_t> seam;
  for (const auto& p : pairs) {
    uint32_t a = L.island[p.a], b = L.island[p.b];
    if (a == b) continue;
    if (a > b) std::swap(a, b);
    ++seam[{a, b}];
  }
  std::vector<std::pair<size_t, std::pair<uint32_t, uint32_t>>> order;
  for (const auto& [k, n] : seam)
    if (n >= 2) order.push_back({n, k});
  std::stable_sort(order.begin(), order.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
  // A seam's pairs come from the smaller island's triangles: scanning every
  // welded pair per attempt cost O(attempts x pairs).
  const PairsByTriangle by_triangle(pairs, L.corner_vertex.size());

  UnionFind merged(L.island_count);
  std::vector<uint8_t> grew(L.island_count, 0);  // the island a join kept
  for (const auto& entry : order) {
    if (f.attempts >= max_attempts) break;
    uint32_t A = merged.find(entry.second.first), B = merged.find(entry.second.second);
    if (A == B) continue;
    // B, the smaller, moves onto A.
    if (islands[B].size() > islands[A].size()) std::swap(A, B);
    // The shared corners: (vertex in A, vertex in B) for each seam pair.
    // Each pair between A and B has exactly one triangle in B.
    std::vector<std::pair<uint32_t, uint32_t>> match;
    for (const uint32_t t : islands[B])
      for (uint32_t e = by_triangle.first[t]; e < by_triangle.first[t + 1]; ++e) {
        const auto& p = pairs[by_triangle.index[e]];
        const uint32_t ia = merged.find(L.island[p.a]), ib = merged.find(L.island[p.b]);
        if (!((ia == A && ib == B) || (ia == B && ib == A))) continue;
        for (int i = 0; i < 2; ++i) {
          uint32_t va = L.corner_vertex[p.a][p.a_corner[i]], vb = L.corner_vertex[p.b][p.b_corner[i]];
          if (ia == B) std::swap(va, vb);
          match.push_back({va, vb});
        }
      }
    std::sort(match.begin(), match.end());
    match.erase(std::unique(match.begin(), match.end()), match.end());
    // A vertex of B matched to two different vertices of A (or the reverse)
    // would close a loop the flat map cannot: refuse.
    {
      std::map<uint32_t, uint32_t> a_of_b, b_of_a;
      bool ambiguous = false;
      for (const auto& [va, vb] : match) {
        auto [i1, n1] = a_of_b.emplace(vb, va);
        auto [i2, n2] = b_of_a.emplace(va, vb);
        if ((!n1 && i1->second != va) || (!n2 && i2->second != vb)) ambiguous = true;
      }
      if (ambiguous || match.size() < 3) continue;
    }
    ++f.attempts;
    std::vector<uint32_t> joined = islands[A];
    joined.insert(joined.end(), islands[B].begin(), islands[B].end());
    const double stretch_before = island_stretch(soup, uv_per_length, joined, L);
    // The rotation and shift of B's matched corners onto A's.
    std::vector<std::pair<Vec2, Vec2>> b_to_a;
    for (const auto& [va, vb] : match) b_to_a.push_back({L.uv[vb], L.uv[va]});
    const RigidMotion motion = fit_rigid_motion(b_to_a);
    // Try it on copies: B's vertices moved, the matched ones joined.
    std::vector<uint32_t> b_vertices;
    for (uint32_t t : islands[B]) b_vertices.insert(b_vertices.end(), L.corner_vertex[t].begin(), L.corner_vertex[t].end());
    std::sort(b_vertices.begin(), b_vertices.end());
    b_vertices.erase(std::unique(b_vertices.begin(), b_vertices.end()), b_vertices.end());
    std::vector<Vec2> saved_uv(b_vertices.size());
    for (size_t i = 0; i < b_vertices.size(); ++i) saved_uv[i] = L.uv[b_vertices[i]];
    std::vector<std::pair<uint32_t, Vec2>> saved_a;
    for (const uint32_t v : b_vertices) L.uv[v] = motion(L.uv[v]);
    std::map<uint32_t, uint32_t> to_a;
    for (const auto& [va, vb] : match) {
      saved_a.push_back({va, L.uv[va]});
      to_a[vb] = va;
    }
    for (const auto& [vb, va] : to_a) L.uv[va] = 0.5 * (L.uv[va] + L.uv[vb]);
    std::vector<std::array<uint32_t, 3>> saved_b_tris;
    for (uint32_t t : islands[B]) {
      saved_b_tris.push_back(L.corner_vertex[t]);
      for (uint32_t& v : L.corner_vertex[t]) {
        auto it = to_a.find(v);
        if (it != to_a.end()) v = it->second;
      }
    }
    auto folded = [&] {
      for (uint32_t t : joined)
        if (is_folded(soup, uv_per_length, collapse_ratio, L, t)) return true;
      return false;
    };
    bool folds = folded();
    bool relaxed = false;
    std::vector<std::pair<uint32_t, Vec2>> saved_all;
    if (folds && joined.size() <= max_relax_triangles) {
      // The two sides of a seam are distorted differently: the mean corners
      // can fold a thin triangle beside the seam. Relax the joined island
      // as rigidly as possible (untangle.h) and look again.
      for (uint32_t t : joined)
        for (uint32_t v : L.corner_vertex[t]) saved_all.push_back({v, L.uv[v]});
      relaxed = arap_island(soup, uv_per_length, joined, 8, L);
      folds = folded();
    }
    // A and B were each overlap-free: unless the whole island moved, only
    // where B now lies can they overlap, so the test takes the triangles
    // reaching into B's box.
    bool overlaps = false;
    if (!folds && relaxed) {
      overlaps = overlap_samples(L, joined, cell) > 0;
    } else if (!folds) {
      Vec2 lo{INFINITY, INFINITY}, hi{-INFINITY, -INFINITY};
      for (uint32_t t : islands[B])
        for (uint32_t v : L.corner_vertex[t]) {
          lo = {std::min(lo.x, L.uv[v].x), std::min(lo.y, L.uv[v].y)};
          hi = {std::max(hi.x, L.uv[v].x), std::max(hi.y, L.uv[v].y)};
        }
      std::vector<uint32_t> near = islands[B];
      for (uint32_t t : islands[A]) {
        const auto& cv = L.corner_vertex[t];
        const double x0 = std::min({L.uv[cv[0]].x, L.uv[cv[1]].x, L.uv[cv[2]].x});
        const double x1 = std::max({L.uv[cv[0]].x, L.uv[cv[1]].x, L.uv[cv[2]].x});
        const double y0 = std::min({L.uv[cv[0]].y, L.uv[cv[1]].y, L.uv[cv[2]].y});
        const double y1 = std::max({L.uv[cv[0]].y, L.uv[cv[1]].y, L.uv[cv[2]].y});
        if (x1 >= lo.x && x0 <= hi.x && y1 >= lo.y && y0 <= hi.y) near.push_back(t);
      }
      overlaps = overlap_samples(L, near, cell) > 0;
    }
    // The joined island's stretch within the flattenings' budget, or no
    // worse than the two islands' own: the mean corners can pull a seam
    // that closes a box's faces far out of shape, and the solve after the
    // merge only evens it out (BoxesMeta's soup at seed 41: a cube of 9 + 3
    // triangles joined at L2 2.6, solved to 1.37; docs/tuning.md, session 45).
    const bool stretches =
        !folds && !overlaps && island_stretch(soup, uv_per_length, joined, L) > std::max(max_stretch, stretch_before);
    if (folds || overlaps || stretches) {
      for (auto it = saved_all.rbegin(); it != saved_all.rend(); ++it) L.uv[it->first] = it->second;
      for (size_t i = 0; i < b_vertices.size(); ++i) L.uv[b_vertices[i]] = saved_uv[i];
      for (const auto& [va, p] : saved_a) L.uv[va] = p;
      for (size_t i = 0; i < islands[B].size(); ++i) L.corner_vertex[islands[B][i]] = saved_b_tris[i];
      folds ? ++f.refused_fold : overlaps ? ++f.refused_overlap : ++f.refused_stretch;
      continue;
    }
    ++f.joined;
    grew[A] = 1;
    for (uint32_t t : islands[B]) L.island[t] = A;
    islands[A] = std::move(joined);
    islands[B].clear();
    merged.unite(A, B);
    // unite() keeps the smaller id as the root: keep the triangle lists there.
    const uint32_t root = merged.find(A);
    if (root != A) {
      grew[root] = 1;
      islands[root] = std::move(islands[A]);
      islands[A].clear();
      for (uint32_t t : islands[root]) L.island[t] = root;
    }
  }
  // Renumber islands densely.
  std::vector<uint32_t> number(L.island_count, UINT32_MAX);
  uint32_t count = 0;
  for (uint32_t& i : L.island) {
    if (number[i] == UINT32_MAX) number[i] = count++;
    i = number[i];
  }
  f.joined_island.assign(count, 0);
  for (uint32_t i = 0; i < grew.size(); ++i)
    if (grew[i] && number[i] != UINT32_MAX) f.joined_island[number[i]] = 1;
  L.island_count = count;
  return f;
}

}  // namespace soupuv::uvsolve::detail
