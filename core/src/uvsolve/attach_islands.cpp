#include "uvsolve/attach_islands.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include "transfer/sym_dirichlet.h"
#include "uvsolve/island_grid.h"
#include "uvsolve/pairs_by_triangle.h"
#include "uvsolve/piece_flatten.h"
#include "uvsolve/rigid_fit.h"
#include "uvsolve/untangle.h"

namespace soupuv::uvsolve::detail {
namespace {

// The largest island tried (the self-overlap test is quadratic in it).
constexpr size_t kMaxTriangles = 64;
// Hosts tried per small island, most shared edges first, and shared
// edges tried alone per host when snapping all of them fails.
constexpr size_t kHostsTried = 3;
constexpr size_t kEdgesTriedAlone = 3;

}  // namespace

AttachFigures attach_small_islands(const Soup& soup, const std::vector<geometry::AdjacentPair>& pairs,
                                   double uv_per_length, double collapse_ratio, double max_stretch,
                                   double max_area, double max_lap_area, UvLayout& L) {
  AttachFigures f;
  const size_t n = L.corner_vertex.size();
  if (!(max_area > 0) || n == 0 || L.island_count < 2) return f;
  std::vector<double> area(L.island_count, 0);
  for (uint32_t t = 0; t < n; ++t) area[L.island[t]] += 0.5 * std::abs(signed_area2(L, t));
  const double uv_area = std::accumulate(area.begin(), area.end(), 0.0);
  if (!(uv_area > 0)) return f;
  // Cells of about two mean triangles a side: a query touches a few cells.
  IslandGrid grid(2 * std::sqrt(uv_area / double(n)));
  for (uint32_t t = 0; t < n; ++t) grid.insert(L.island[t], t, corners_of(L, t));

  std::vector<std::vector<uint32_t>> members = island_triangles(L);
  std::vector<uint32_t> host(L.island_count);
  std::iota(host.begin(), host.end(), 0u);
  auto find = [&](uint32_t x) {
    while (host[x] != x) x = host[x] = host[host[x]];
    return x;
  };
  const PairsByTriangle by_triangle(pairs, n);

  std::vector<uint32_t> order;
  for (uint32_t i = 0; i < L.island_count; ++i)
    if (!members[i].empty() && members[i].size() <= kMaxTriangles && area[i] <= max_area) order.push_back(i);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return area[a] < area[b]; });

  std::unordered_map<uint32_t, uint32_t> snap;  // small island's vertex -> host's vertex
  std::vector<Corners> moved;
  std::vector<transfer::detail::RestTriangle> rest;
  std::vector<uint32_t> lapped_by_k;  // host triangles a small triangle laps
  for (const uint32_t j : order) {
    if (find(j) != j) continue;  // attached to another already
    const std::vector<uint32_t>& mine = members[j];
    // Neighbouring islands and the welded pairs shared with each.
    std::unordered_map<uint32_t, std::vector<uint32_t>> shared;
    for (uint32_t t : mine)
      for (uint32_t e = by_triangle.first[t]; e < by_triangle.first[t + 1]; ++e) {
        const auto& p = pairs[by_triangle.index[e]];
        const uint32_t h = find(L.island[p.a == t ? p.b : p.a]);
        if (h != j) shared[h].push_back(by_triangle.index[e]);
      }
    if (shared.empty()) continue;
    ++f.candidates;
    std::vector<std::pair<uint32_t, std::vector<uint32_t>>> hosts(shared.begin(), shared.end());
    std::sort(hosts.begin(), hosts.end(), [&](const auto& a, const auto& b) {
      if (a.second.size() != b.second.size()) return a.second.size() > b.second.size();
      if (members[a.first].size() != members[b.first].size()) return members[a.first].size() > members[b.first].size();
      return a.first < b.first;
    });
    if (hosts.size() > kHostsTried) hosts.resize(kHostsTried);
    // One attempt: snapped along the given welded pairs with host h.
    auto try_attach = [&](uint32_t h, const uint32_t* pair_ids, size_t pair_count) {
      ++f.attempts;
      // The shared corners: this island's vertex -> the host's (first match wins).
      snap.clear();
      for (size_t q = 0; q < pair_count; ++q) {
        const auto& p = pairs[pair_ids[q]];
        const bool a_is_mine = find(L.island[p.a]) == j;
        const uint32_t t = a_is_mine ? p.a : p.b, o = a_is_mine ? p.b : p.a;
        for (int s = 0; s < 2; ++s) {
          const uint32_t v = L.corner_vertex[t][a_is_mine ? p.a_corner[s] : p.b_corner[s]];
          const uint32_t w = L.corner_vertex[o][a_is_mine ? p.b_corner[s] : p.a_corner[s]];
          snap.emplace(v, w);
        }
      }
      // Rigid motion onto the host, fitted on the shared corners.
      std::vector<std::pair<Vec2, Vec2>> shared_corners;
      for (const auto& [v, w] : snap) shared_corners.push_back({L.uv[v], L.uv[w]});
      const RigidMotion motion = fit_rigid_motion(shared_corners);
      auto place = [&](uint32_t v) {
        if (auto it = snap.find(v); it != snap.end()) return L.uv[it->second];
        return motion(L.uv[v]);
      };
      moved.resize(mine.size());
      bool folds = false;
      for (size_t k = 0; k < mine.size(); ++k) {
        for (int c = 0; c < 3; ++c) moved[k][c] = place(L.corner_vertex[mine[k]][c]);
        folds = folds || is_folded(0.5 * cross(moved[k][1] - moved[k][0], moved[k][2] - moved[k][0]),
                                   triangle_area(soup, mine[k]) * uv_per_length * uv_per_length, collapse_ratio);
      }
      if (folds) {
        ++f.refused_fold;
        return false;
      }
      rest.clear();
      for (uint32_t t : mine)
        rest.push_back(transfer::detail::rest_triangle(soup.corner(t, 0), soup.corner(t, 1), soup.corner(t, 2),
                                                       uv_per_length, 1.0));
      if (rest_stretch_l2(rest, moved) > max_stretch) {
        ++f.refused_stretch;
        return false;
      }
      bool overlaps = false;
      double lapped = 0;  // area over the host's triangles so far
      for (size_t k = 0; k < mine.size() && !overlaps; ++k) {
        for (size_t l = k + 1; l < mine.size() && !overlaps; ++l) overlaps = interiors_overlap(moved[k], moved[l]);
        lapped_by_k.clear();  // the grid may offer a host triangle once per cell: count it once
        overlaps = overlaps || grid.any_near(h, moved[k], [&](uint32_t u) {
                     if (find(L.island[u]) != h || !interiors_overlap(moved[k], corners_of(L, u))) return false;
                     if (std::find(lapped_by_k.begin(), lapped_by_k.end(), u) != lapped_by_k.end()) return false;
                     lapped_by_k.push_back(u);
                     lapped += overlap_area(moved[k], corners_of(L, u));
                     return !(lapped <= max_lap_area);
                   });
      }
      if (overlaps) {
        ++f.refused_overlap;
        return false;
      }
      // Kept: the island's corners take the host's shared vertices, its
      // other vertices move with it, and its triangles join the host.
      for (size_t k = 0; k < mine.size(); ++k)
        for (int c = 0; c < 3; ++c) {
          uint32_t& v = L.corner_vertex[mine[k]][c];
          if (auto it = snap.find(v); it != snap.end()) v = it->second;
        }
      for (size_t k = 0; k < mine.size(); ++k)
        for (int c = 0; c < 3; ++c) L.uv[L.corner_vertex[mine[k]][c]] = moved[k][c];
      host[j] = h;
      if (lapped > 0) {
        ++f.attached_with_lap;
        f.lapped_area += lapped;
      }
      for (uint32_t t : mine) grid.insert(h, t, corners_of(L, t));
      members[h].insert(members[h].end(), mine.begin(), mine.end());
      members[j].clear();
      ++f.attached;
      return true;
    };
    // All the pairs shared with a host first; where snapping them all folds
    // or laps, each shared edge alone (the island keeps its own shape).
    for (const auto& [h, pair_ids] : hosts) {
      if (try_attach(h, pair_ids.data(), pair_ids.size())) break;
      bool attached = false;
      for (size_t q = 0; q < pair_ids.size() && q < kEdgesTriedAlone && pair_ids.size() > 1 && !attached; ++q)
        attached = try_attach(h, &pair_ids[q], 1);
      if (attached) break;
    }
  }
  if (f.attached == 0) return f;
  // Every triangle to its host's id, then the hosts renumbered.
  for (size_t t = 0; t < n; ++t) L.island[t] = find(L.island[t]);
  compact_island_ids(L);
  return f;
}

}  // namespace soupuv::uvsolve::detail
