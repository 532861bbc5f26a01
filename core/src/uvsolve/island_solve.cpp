#include "uvsolve/island_solve.h"

#include <omp.h>

#include <algorithm>
#include <numeric>

#include "transfer/slim.h"
#include "transfer/sym_dirichlet.h"

namespace soupuv::uvsolve::detail {

SolveFigures solve_islands(const Soup& soup, double uv_per_length, int max_iterations, int threads,
                           UvLayout& L) {
  using transfer::detail::RestTriangle;
  SolveFigures f;
  const auto islands = island_triangles(L);
  std::vector<uint32_t> order(islands.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t a, uint32_t b) { return islands[a].size() > islands[b].size(); });
  double before = 0, after = 0, rest_area = 0;
  size_t solved = 0, unstarted = 0;
  int max_used = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(std::max(1, threads)) \
    reduction(+ : before, after, rest_area, solved, unstarted) reduction(max : max_used)
  for (size_t o = 0; o < order.size(); ++o) {
    const auto& tris = islands[order[o]];
    // Local numbering of the island's vertices.
    std::vector<uint32_t> global;
    std::vector<std::array<uint32_t, 3>> local(tris.size());
    std::vector<RestTriangle> rest(tris.size());
    for (size_t i = 0; i < tris.size(); ++i) {
      const uint32_t t = tris[i];
      local[i] = L.corner_vertex[t];  // renumbered below
      rest[i] = transfer::detail::rest_triangle(soup.corner(t, 0), soup.corner(t, 1), soup.corner(t, 2),
                                                uv_per_length, 1.0);
      rest_area += rest[i].area;
    }
    for (const auto& tri : local) global.insert(global.end(), tri.begin(), tri.end());
    std::sort(global.begin(), global.end());
    global.erase(std::unique(global.begin(), global.end()), global.end());
    for (auto& tri : local)
      for (uint32_t& v : tri) v = uint32_t(std::lower_bound(global.begin(), global.end(), v) - global.begin());
    std::vector<Vec2> uv(global.size());
    for (size_t i = 0; i < global.size(); ++i) uv[i] = L.uv[global[i]];
    if (tris.size() == 1) {
      // One triangle: its rest shape, placed at its current centroid.
      if (rest[0].valid) {
        const Vec2 c = (1.0 / 3) * (uv[0] + uv[1] + uv[2]);
        const Vec2 rc = (1.0 / 3) * (rest[0].x[0] + rest[0].x[1] + rest[0].x[2]);
        for (int k = 0; k < 3; ++k) uv[local[0][k]] = c + (rest[0].x[k] - rc);
      }
    } else {
      const std::vector<uint8_t> fixed(uv.size(), 0);
      transfer::detail::SlimOptions so;
      so.max_iterations = max_iterations;
      const auto r = transfer::detail::slim_relax(local, rest, fixed, uv, so);
      if (!r.started) {
        ++unstarted;
        continue;
      }
      before += r.energy_before;
      after += r.energy_after;
      ++solved;
      max_used = std::max(max_used, r.iterations);
    }
    for (size_t i = 0; i < global.size(); ++i) L.uv[global[i]] = uv[i];
  }
  f.solved_islands = solved;
  f.unstarted_islands = unstarted;
  // Per unit rest area: 4 is an isometry.
  f.energy_before = rest_area > 0 ? before / rest_area : 0;
  f.energy_after = rest_area > 0 ? after / rest_area : 0;
  f.max_iterations_used = max_used;
  return f;
}

}  // namespace soupuv::uvsolve::detail
