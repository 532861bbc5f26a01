#include "soupuv/quality/continuity_bound.h"

#include <cmath>
#include <numbers>

#include "soupuv/union_find.h"

namespace soupuv::quality {

ContinuityBound continuity_bound(const Soup& soup, const geometry::Weld& weld,
                                 const std::vector<geometry::AdjacentPair>& adjacency, double cone_defect) {
  ContinuityBound b;
  const size_t n = soup.triangles.size();
  b.pairs = adjacency.size();
  if (n == 0 || weld.corner_vertex.size() != 3 * n || b.pairs == 0) return b;

  std::vector<double> angle_sum(weld.vertex_count, 0);
  for (size_t t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k) {
      const Vec3 a = soup.corner(t, (k + 1) % 3) - soup.corner(t, k);
      const Vec3 c = soup.corner(t, (k + 2) % 3) - soup.corner(t, k);
      const double la = norm(a), lc = norm(c);
      if (la > 0 && lc > 0)
        angle_sum[weld.corner_vertex[3 * t + k]] += std::acos(std::clamp(dot(a, c) / (la * lc), -1.0, 1.0));
    }

  // Border vertices: on a directed edge no adjacent pair covers. Count how
  // many triangles use each (welded) edge; a pair covers two uses.
  UnionFind parts(n);
  std::vector<uint32_t> paired(3 * n, 0);  // per corner edge (k -> k+1): in some pair
  for (const geometry::AdjacentPair& p : adjacency) {
    parts.unite(p.a, p.b);
    auto mark = [&](uint32_t t, std::array<uint8_t, 2> c) {
      const int k0 = c[0], k1 = c[1];
      paired[3 * t + ((k1 == (k0 + 1) % 3) ? k0 : k1)] = 1;
    };
    mark(p.a, p.a_corner);
    mark(p.b, p.b_corner);
  }
  std::vector<uint8_t> border(weld.vertex_count, 0);
  for (size_t t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k)
      if (!paired[3 * t + k]) {
        border[weld.corner_vertex[3 * t + k]] = 1;
        border[weld.corner_vertex[3 * t + (k + 1) % 3]] = 1;
      }

  // Per component: its cones, and whether it has a border.
  std::vector<size_t> cones(n, 0);
  std::vector<uint8_t> open(n, 0), counted(weld.vertex_count, 0);
  for (size_t t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = weld.corner_vertex[3 * t + k], root = parts.find(uint32_t(t));
      if (border[v]) open[root] = 1;
      if (counted[v]) continue;
      counted[v] = 1;
      if (!border[v] && std::abs(2 * std::numbers::pi - angle_sum[v]) > cone_defect) ++cones[root];
    }
  for (size_t r = 0; r < n; ++r) {
    b.cone_vertices += cones[r];
    if (cones[r] > 0) b.min_cut_edges += open[r] ? cones[r] : cones[r] - 1;
  }
  b.bound = 1 - double(std::min(b.min_cut_edges, b.pairs)) / double(b.pairs);
  return b;
}

}  // namespace soupuv::quality
