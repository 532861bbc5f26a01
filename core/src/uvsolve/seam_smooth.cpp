#include "uvsolve/seam_smooth.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "transfer/sym_dirichlet.h"
#include "uvsolve/island_grid.h"
#include "uvsolve/pairs_by_triangle.h"
#include "uvsolve/patch_relax.h"
#include "uvsolve/piece_flatten.h"
#include "uvsolve/untangle.h"

namespace soupuv::uvsolve::detail {

namespace {
constexpr size_t kMaxPasses = 8;
// A triangle that does not fit its new island as it is gets the island's
// vertices within this many rings of it relaxed, by this many SLIM
// iterations (docs/tuning.md, session 33).
constexpr int kPatchRings = 2;
constexpr int kPatchIterations = 10;

enum class Refusal { none, fold, stretch, overlap };
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

  VertexTriangles incidence(L);
  // Moves in or out of each island so far, and per triangle the island a
  // relaxed join was last refused into with that island's count then: the
  // same attempt on an unchanged island is refused again (its patch, the
  // only thing the relaxation and its tests read, is the same).
  std::vector<uint32_t> changes(L.island_count, 0);
  struct Refused {
    uint32_t island = UINT32_MAX, changes = 0;
  };
  std::vector<Refused> relax_refused(n);
  auto rest_of = [&](uint32_t t) {
    return transfer::detail::rest_triangle(soup.corner(t, 0), soup.corner(t, 1), soup.corner(t, 2), uv_per_length,
                                           1.0);
  };
  auto folded = [&](uint32_t t, const Corners& c) {
    return is_folded(0.5 * cross(c[1] - c[0], c[2] - c[0]), triangle_area(soup, t) * uv_per_length * uv_per_length,
                     collapse_ratio);
  };
  // The island's triangles that the triangle at `c` laps, by area (each
  // once, `self` left out), stopping once above the budget.
  std::vector<uint32_t> lapped_by;
  auto laps_beyond = [&](uint32_t island, uint32_t self, const Corners& c, double& lapped) {
    lapped_by.clear();
    return grid.any_near(island, c, [&](uint32_t u) {
      if (u == self || L.island[u] != island || !interiors_overlap(c, corners_of(L, u))) return false;
      if (std::find(lapped_by.begin(), lapped_by.end(), u) != lapped_by.end()) return false;
      lapped_by.push_back(u);
      lapped += overlap_area(c, corners_of(L, u));
      return !(lapped <= max_lap_area);
    });
  };
  // Why triangle t may not join `island` with its image c there as it is.
  auto refusal = [&](const Corners& c, uint32_t t, uint32_t island) {
    if (folded(t, c)) return Refusal::fold;
    if (rest_stretch_l2({rest_of(t)}, {c}) > max_stretch) return Refusal::stretch;
    double lapped = 0;
    return laps_beyond(island, t, c, lapped) ? Refusal::overlap : Refusal::none;
  };
  // Triangle t joins `island` on `vertices` with the island's vertices
  // around them relaxed (patch_relax.h), kept when no patch triangle folds,
  // the patch's L2 stretch (t's with it) is within the budget or its own
  // before, and the patch laps the island by at most the lap budget.
  auto relax_into = [&](uint32_t t, uint32_t island, const std::array<uint32_t, 3>& vertices) {
    const std::array<uint32_t, 3> was = L.corner_vertex[t];
    const uint32_t was_island = L.island[t];
    incidence.remove(t, was), incidence.add(t, vertices);
    L.corner_vertex[t] = vertices;
    L.island[t] = island;
    const RelaxedPatch patch = relax_patch(soup, uv_per_length, L, incidence, {vertices[0], vertices[1], vertices[2]},
                                           kPatchRings, kPatchIterations);
    bool kept = false;
    if (patch.relaxed) {
      std::vector<transfer::detail::RestTriangle> rest;
      std::vector<Corners> before, after;
      for (uint32_t u : patch.triangles)
        if (u != t) rest.push_back(rest_of(u)), before.push_back(corners_of(L, u));
      const double l2_before = rest_stretch_l2(rest, before);
      std::vector<Vec2> saved(patch.vertices.size());
      for (size_t i = 0; i < patch.vertices.size(); ++i)
        saved[i] = L.uv[patch.vertices[i]], L.uv[patch.vertices[i]] = patch.uv[i];
      rest.clear();
      kept = true;
      for (uint32_t u : patch.triangles) {
        const Corners c = corners_of(L, u);
        if (folded(u, c)) kept = false;
        rest.push_back(rest_of(u)), after.push_back(c);
      }
      kept = kept && rest_stretch_l2(rest, after) <= std::max(max_stretch, l2_before);
      double lapped = 0;
      for (size_t k = 0; kept && k < patch.triangles.size(); ++k)
        kept = !laps_beyond(island, patch.triangles[k], after[k], lapped);
      if (!kept)
        for (size_t i = 0; i < patch.vertices.size(); ++i) L.uv[patch.vertices[i]] = saved[i];
    }
    if (!kept) {
      incidence.remove(t, vertices), incidence.add(t, was);
      L.corner_vertex[t] = was;
      L.island[t] = was_island;
      return false;
    }
    for (uint32_t u : patch.triangles) grid.insert(island, u, corners_of(L, u));
    return true;
  };
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
        const Refusal why = refusal(c, t, side.island);
        const uint32_t from = own;
        if (why == Refusal::none) {
          incidence.remove(t, L.corner_vertex[t]), incidence.add(t, side.vertex);
          L.corner_vertex[t] = side.vertex;
          L.island[t] = side.island;
          grid.insert(side.island, t, c);
          ++changes[from], ++changes[side.island];
          ++f.moved;
          again = true;
          break;
        }
        const bool tried = relax_refused[t].island == side.island && relax_refused[t].changes == changes[side.island];
        if (!tried && relax_into(t, side.island, side.vertex)) {
          ++changes[from], ++changes[side.island];
          ++f.moved;
          ++f.relaxed;
          again = true;
          break;
        }
        if (!tried) relax_refused[t] = {side.island, changes[side.island]};
        why == Refusal::fold ? ++f.refused_fold : why == Refusal::stretch ? ++f.refused_stretch : ++f.refused_overlap;
      }
    }
  }
  if (f.moved == 0) return f;
  compact_island_ids(L);  // drops the islands left empty
  return f;
}

}  // namespace soupuv::uvsolve::detail
