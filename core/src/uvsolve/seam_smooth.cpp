#include "uvsolve/seam_smooth.h"

#include <cmath>
#include <numeric>

#include "transfer/sym_dirichlet.h"
#include "uvsolve/island_grid.h"
#include "uvsolve/pairs_by_triangle.h"
#include "uvsolve/piece_flatten.h"
#include "uvsolve/untangle.h"

namespace soupuv::uvsolve::detail {

namespace {
constexpr size_t kMaxPasses = 8;
}  // namespace

SeamSmoothFigures smooth_seams(const Soup& soup, const std::vector<geometry::AdjacentPair>& pairs,
                               double uv_per_length, double collapse_ratio, double max_stretch,
                               double max_lap_area, UvLayout& L) {
  SeamSmoothFigures f;
  const size_t n = L.corner_vertex.size();
  if (n == 0 || L.island_count < 2) return f;
  double uv_area = 0;
  for (uint32_t t = 0; t < n; ++t) uv_area += 0.5 * std::abs(signed_area2(L, t));
  if (!(uv_area > 0)) return f;
  IslandGrid grid(2 * std::sqrt(uv_area / double(n)));
  for (uint32_t t = 0; t < n; ++t) grid.insert(L.island[t], t, corners_of(L, t));
  const PairsByTriangle by_triangle(pairs, n);

  std::vector<uint32_t> lapped_by;  // the island's triangles a moved one laps, once each
  std::vector<transfer::detail::RestTriangle> rest(1);
  std::vector<Corners> moved(1);
  for (bool again = true; again && f.passes < kMaxPasses;) {
    again = false;
    ++f.passes;
    for (uint32_t t = 0; t < n; ++t) {
      // Per other island: the edges shared with it and, per corner of t,
      // the vertex it is welded to there (UINT32_MAX: none yet; a corner
      // welded to two different vertices of one island is no candidate).
      struct Side {
        uint32_t island;
        int edges;
        std::array<uint32_t, 3> vertex;
        bool consistent;
      };
      std::array<Side, 3> sides;
      int side_count = 0;
      const uint32_t own = L.island[t];
      for (uint32_t e = by_triangle.first[t]; e < by_triangle.first[t + 1]; ++e) {
        const auto& p = pairs[by_triangle.index[e]];
        const bool t_is_a = p.a == t;
        const uint32_t o = t_is_a ? p.b : p.a;
        const uint32_t island = L.island[o];
        if (island == own) continue;
        int s = 0;
        while (s < side_count && sides[s].island != island) ++s;
        if (s == side_count) {
          if (side_count == 3) continue;
          sides[side_count++] = {island, 0, {UINT32_MAX, UINT32_MAX, UINT32_MAX}, true};
        }
        Side& side = sides[s];
        ++side.edges;
        for (int k = 0; k < 2; ++k) {
          const int mine = t_is_a ? p.a_corner[k] : p.b_corner[k];
          const uint32_t theirs = L.corner_vertex[o][t_is_a ? p.b_corner[k] : p.a_corner[k]];
          if (side.vertex[mine] == UINT32_MAX) side.vertex[mine] = theirs;
          else if (side.vertex[mine] != theirs) side.consistent = false;
        }
      }
      for (int s = 0; s < side_count; ++s) {
        const Side& side = sides[s];
        if (side.edges < 2 || !side.consistent) continue;
        if (side.vertex[0] == UINT32_MAX || side.vertex[1] == UINT32_MAX || side.vertex[2] == UINT32_MAX) continue;
        ++f.candidates;
        const Corners c{L.uv[side.vertex[0]], L.uv[side.vertex[1]], L.uv[side.vertex[2]]};
        if (is_folded(0.5 * cross(c[1] - c[0], c[2] - c[0]), triangle_area(soup, t) * uv_per_length * uv_per_length,
                      collapse_ratio)) {
          ++f.refused_fold;
          continue;
        }
        rest[0] = transfer::detail::rest_triangle(soup.corner(t, 0), soup.corner(t, 1), soup.corner(t, 2),
                                                  uv_per_length, 1.0);
        moved[0] = c;
        if (rest_stretch_l2(rest, moved) > max_stretch) {
          ++f.refused_stretch;
          continue;
        }
        double lapped = 0;
        lapped_by.clear();
        const bool laps = grid.any_near(side.island, c, [&](uint32_t u) {
          if (L.island[u] != side.island || !interiors_overlap(c, corners_of(L, u))) return false;
          if (std::find(lapped_by.begin(), lapped_by.end(), u) != lapped_by.end()) return false;
          lapped_by.push_back(u);
          lapped += overlap_area(c, corners_of(L, u));
          return !(lapped <= max_lap_area);
        });
        if (laps) {
          ++f.refused_overlap;
          continue;
        }
        L.corner_vertex[t] = side.vertex;
        L.island[t] = side.island;
        grid.insert(side.island, t, c);
        ++f.moved;
        again = true;
        break;
      }
    }
  }
  if (f.moved == 0) return f;
  compact_island_ids(L);  // drops the islands left empty
  return f;
}

}  // namespace soupuv::uvsolve::detail
