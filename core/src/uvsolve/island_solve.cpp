#include "uvsolve/island_solve.h"

#include <omp.h>

#include <algorithm>

#include "transfer/slim.h"
#include "uvsolve/overlap_split.h"
#include "uvsolve/local_island.h"

namespace soupuv::uvsolve::detail {

SolveFigures solve_islands(const Soup& soup, double uv_per_length, int max_iterations, int threads,
                           UvLayout& L, const std::vector<uint8_t>* selected, double lap_cell) {
  SolveFigures f;
  const auto islands = island_triangles(L);
  std::vector<uint32_t> order;
  for (uint32_t i = 0; i < islands.size(); ++i)
    if (!selected || (i < selected->size() && (*selected)[i])) order.push_back(i);
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t a, uint32_t b) { return islands[a].size() > islands[b].size(); });
  double before = 0, after = 0, rest_area = 0;
  size_t solved = 0, unstarted = 0, kept = 0;
  int max_used = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(std::max(1, threads)) \
    reduction(+ : before, after, rest_area, solved, unstarted, kept) reduction(max : max_used)
  for (size_t o = 0; o < order.size(); ++o) {
    const auto& tris = islands[order[o]];
    LocalIsland m = local_island(soup, uv_per_length, tris, L);
    for (const auto& r : m.rest) rest_area += r.area;
    std::vector<Vec2>& uv = m.uv;
    const auto& rest = m.rest;
    const auto& local = m.triangles;
    if (tris.size() == 1) {
      // One triangle: its rest shape, placed at its current centroid.
      if (rest[0].valid) {
        const Vec2 c = (1.0 / 3) * (uv[0] + uv[1] + uv[2]);
        const Vec2 rc = (1.0 / 3) * (rest[0].x[0] + rest[0].x[1] + rest[0].x[2]);
        for (int k = 0; k < 3; ++k) uv[local[0][k]] = c + (rest[0].x[k] - rc);
      }
    } else {
      auto laps = [&] {
        std::vector<std::array<Vec2, 3>> corners(local.size());
        for (size_t j = 0; j < local.size(); ++j)
          for (int k = 0; k < 3; ++k) corners[j][k] = uv[local[j][k]];
        return overlap_samples(corners, lap_cell);
      };
      const size_t laps_before = lap_cell > 0 ? laps() : 0;
      const std::vector<uint8_t> fixed(uv.size(), 0);
      transfer::detail::SlimOptions so;
      so.max_iterations = max_iterations;
      const auto r = transfer::detail::slim_relax(local, rest, fixed, uv, so);
      if (!r.started) {
        ++unstarted;
        continue;
      }
      if (lap_cell > 0 && laps() > laps_before) {
        ++kept;
        continue;
      }
      before += r.energy_before;
      after += r.energy_after;
      ++solved;
      max_used = std::max(max_used, r.iterations);
    }
    write_back(m, L);
  }
  f.solved_islands = solved;
  f.unstarted_islands = unstarted;
  f.kept_for_laps = kept;
  // Per unit rest area: 4 is an isometry.
  f.energy_before = rest_area > 0 ? before / rest_area : 0;
  f.energy_after = rest_area > 0 ? after / rest_area : 0;
  f.max_iterations_used = max_used;
  return f;
}

}  // namespace soupuv::uvsolve::detail
