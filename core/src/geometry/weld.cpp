#include "soupuv/geometry/weld.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include <omp.h>

#include "geometry/corner_grid.h"
#include "geometry/shared_triangle.h"
#include "soupuv/union_find.h"

namespace soupuv::geometry {

namespace {

// weld_corners, starting from the groups of `start` (nullptr: every corner alone).
Weld weld_corners_from(const Soup& soup, double tolerance, double edge_fraction,
                       const Weld* start) {
  const size_t corners = soup.triangles.size() * 3;
  Weld w;
  if (corners == 0) return w;
  UnionFind uf(corners);
  auto pos = [&](size_t c) { return soup.positions[soup.triangles[c / 3][c % 3]]; };

  Box3 box = bounding_box(soup);
  // A tolerance far below the coordinates' resolution means "exact": bucket by
  // bits then, so a 0 tolerance does not make an infinitely fine grid.
  double cell = tolerance / 2;  // corner_grid.h: half the reach
  double floor_cell = box.diagonal() * 1e-9;
  bool exact = !(cell > floor_cell);
  if (exact) cell = std::max(floor_cell, 1e-300);
  // Limit the grid to 2^21 cells per axis; a coarser cell only costs more
  // distance tests, never a wrong answer.
  double span = std::max({box.extent().x, box.extent().y, box.extent().z, 0.0});
  cell = std::max(cell, span / double(1 << 20));

  // Per-triangle squared cap for edge_fraction: (fraction * shortest edge)^2.
  std::vector<double> cap2;
  if (edge_fraction > 0) {
    cap2.resize(soup.triangles.size());
    for (size_t t = 0; t < soup.triangles.size(); ++t) {
      Vec3 a = soup.corner(t, 0), b = soup.corner(t, 1), c = soup.corner(t, 2);
      double e = std::min({norm2(b - a), norm2(c - b), norm2(a - c)});
      cap2[t] = edge_fraction * edge_fraction * e;
    }
  }
  const CornerGrid grid(soup, box, cell, exact ? 0.0 : tolerance);
  const double tol2 = tolerance * tolerance;
  struct Candidate {
    double d2;
    uint32_t a, b;
  };
  // The pairs within the tolerance, found by the threads over contiguous
  // ranges of corners (the order below is total, so the split cannot show).
  const int threads = std::max(1, omp_get_max_threads());
  std::vector<std::vector<Candidate>> found(threads);
#pragma omp parallel num_threads(threads)
  {
    const int me = omp_get_thread_num(), of = omp_get_num_threads();
    const size_t c0 = corners * me / of, c1 = corners * (me + 1) / of;
    for (size_t c = c0; c < c1; ++c) {
      const Vec3 p = pos(c);
      // A partner lies within both triangles' caps, so within this one's:
      // on a scan, where the tolerance spans several edges, the cap is the
      // smaller reach (docs/tuning.md, "The corner weld queried within each
      // triangle's cap").
      const double reach = exact ? 0.0 : cap2.empty() ? tolerance : std::min(tolerance, std::sqrt(cap2[c / 3]));
      grid.for_each_near(p, reach, [&](uint32_t o, const Vec3& q) {
        if (o <= c) return;
        const double d2 = norm2(p - q);
        bool same = exact ? (p.x == q.x && p.y == q.y && p.z == q.z) : d2 <= tol2;
        if (same && !cap2.empty() && !exact) same = d2 <= std::min(cap2[c / 3], cap2[o / 3]);
        if (same) found[me].push_back({d2, uint32_t(c), o});
      });
    }
  }
  std::vector<Candidate> candidates;
  for (auto& f : found) {
    candidates.insert(candidates.end(), f.begin(), f.end());
    f = {};
  }
  // Nearest pairs first, and never two corners of one triangle (even through
  // a chain of welds): a noisy copy is closer to its twins than to the next
  // vertex, so the greedy order welds twins and the constraint keeps
  // triangles from collapsing where the tolerance exceeds an edge.
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& x, const Candidate& y) {
              return x.d2 != y.d2 ? x.d2 < y.d2 : (x.a != y.a ? x.a < y.a : x.b < y.b);
            });
  std::vector<std::vector<uint32_t>> members(corners);  // triangles per root
  for (size_t c = 0; c < corners; ++c) members[c] = {uint32_t(c / 3)};
  auto join = [&](uint32_t ra, uint32_t rb) {
    uf.unite(ra, rb);
    uint32_t root = uf.find(ra), other = root == ra ? rb : ra;
    members[root].insert(members[root].end(), members[other].begin(), members[other].end());
    members[other].clear();
    members[other].shrink_to_fit();
  };
  if (start && start->corner_vertex.size() == corners) {
    std::vector<uint32_t> first(start->vertex_count, UINT32_MAX);
    for (uint32_t c = 0; c < corners; ++c) {
      uint32_t& f = first[start->corner_vertex[c]];
      if (f == UINT32_MAX) f = c;
      else if (uf.find(f) != uf.find(c)) join(uf.find(f), uf.find(c));
    }
  }
  SharedTriangleTest share_a_triangle(soup.triangles.size());
  for (const Candidate& k : candidates) {
    uint32_t ra = uf.find(k.a), rb = uf.find(k.b);
    if (ra == rb) continue;
    if (share_a_triangle(members[ra], members[rb])) continue;
    join(ra, rb);
  }

  w.corner_vertex.resize(corners);
  std::vector<uint32_t> id(corners, UINT32_MAX);
  for (size_t c = 0; c < corners; ++c) {
    uint32_t r = uf.find(uint32_t(c));
    if (id[r] == UINT32_MAX) id[r] = w.vertex_count++;
    w.corner_vertex[c] = id[r];
  }
  return w;
}

}  // namespace

Weld weld_corners(const Soup& soup, double tolerance, double edge_fraction) {
  return weld_corners_from(soup, tolerance, edge_fraction, nullptr);
}

Weld extend_weld(const Soup& soup, const Weld& start, double tolerance, double edge_fraction) {
  return weld_corners_from(soup, tolerance, edge_fraction, &start);
}

std::vector<AdjacentPair> edge_adjacency(const Weld& weld, size_t triangle_count) {
  struct EdgeUse {
    uint64_t key;
    uint32_t tri;
    uint8_t c0, c1;  // corners holding the smaller and the larger vertex id
  };
  std::vector<EdgeUse> uses;
  uses.reserve(triangle_count * 3);
  for (size_t t = 0; t < triangle_count; ++t) {
    for (int k = 0; k < 3; ++k) {
      int k1 = (k + 1) % 3;
      uint32_t va = weld.corner_vertex[t * 3 + k], vb = weld.corner_vertex[t * 3 + k1];
      if (va == vb) continue;
      uint8_t ca = uint8_t(k), cb = uint8_t(k1);
      if (va > vb) { std::swap(va, vb); std::swap(ca, cb); }
      uses.push_back({(uint64_t(va) << 32) | vb, uint32_t(t), ca, cb});
    }
  }
  std::sort(uses.begin(), uses.end(), [](const EdgeUse& x, const EdgeUse& y) {
    return x.key != y.key ? x.key < y.key : x.tri < y.tri;
  });
  std::vector<AdjacentPair> pairs;
  for (size_t i = 0; i < uses.size();) {
    size_t j = i;
    while (j < uses.size() && uses[j].key == uses[i].key) ++j;
    for (size_t a = i; a < j; ++a)
      for (size_t b = a + 1; b < j; ++b) {
        if (uses[a].tri == uses[b].tri) continue;
        pairs.push_back({uses[a].tri, uses[b].tri, {uses[a].c0, uses[a].c1}, {uses[b].c0, uses[b].c1}});
      }
    i = j;
  }
  return pairs;
}

}  // namespace soupuv::geometry
