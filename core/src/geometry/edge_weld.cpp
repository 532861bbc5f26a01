// Welding a noisy soup by matching its edges (see weld.h, weld_by_edges).
//
// Input : a soup and a tolerance (absolute length): the farthest two copies
//         of one original vertex may lie apart.
// Output: a Weld (corner -> vertex id) whose vertices are the corners joined
//         through matched edges.
// Method: every directed triangle edge (p -> q) looks for edges of other
//         triangles running back (q' -> p', or p' -> q' for a flipped
//         neighbour) with both endpoints within the tolerance; all such
//         candidate pairs are matched greedily, the closest (sum of squared
//         endpoint distances) first, each edge at most once, and a match is
//         refused when it would join two corners of one triangle (even through
//         a chain of matches). The matched edges' endpoints are welded.
// Why edges and not positions: where the soup's noise is as large as its
//         shortest edges (a teapot's lid knob, 0.9e-3 of the diagonal against
//         copies up to 3e-3 apart), welding corners nearest-first joins
//         distinct vertices (teapot: 409 corners on a wrong vertex, 430 false
//         neighbour pairs) and the repair then untangles a patch that was
//         never a surface. An edge needs both ends to agree, so a wrong
//         partner must be close at both ends, which is much rarer.
// Cost  : O(n) expected (uniform hash grid, corner_grid.h), plus sorting the
//         candidate pairs; the pass over the candidates runs on the OpenMP
//         threads.
#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include <omp.h>

#include "geometry/corner_grid.h"
#include "geometry/shared_triangle.h"
#include "soupuv/geometry/weld.h"
#include "soupuv/union_find.h"

namespace soupuv::geometry {

namespace {

struct EdgeMatch {
  double cost;
  uint32_t edge, other;  // edge ids: triangle * 3 + k, from corner k to k+1
  bool reversed;         // other runs the same way as edge (a flipped neighbour)
};

}  // namespace

Weld weld_by_edges(const Soup& soup, double tolerance, double ambiguity_ratio, bool flipped_neighbours) {
  constexpr double kNone = std::numeric_limits<double>::infinity();
  const size_t corners = soup.triangles.size() * 3;
  Weld w;
  if (corners == 0) return w;
  auto pos = [&](size_t c) { return soup.positions[soup.triangles[c / 3][c % 3]]; };
  auto next = [](uint32_t c) { return c - c % 3 + (c % 3 + 1) % 3; };
  auto prev = [](uint32_t c) { return c - c % 3 + (c % 3 + 2) % 3; };

  const Box3 box = bounding_box(soup);
  const double span = std::max({box.extent().x, box.extent().y, box.extent().z, 0.0});
  // A zero tolerance still buckets exact copies together; the grid stays at
  // most 2^20 cells per axis (a coarser cell only costs more distance tests).
  const double cell = std::max({tolerance / 2, span / double(1 << 20), box.diagonal() * 1e-9, 1e-300});
  const CornerGrid grid(soup, box, cell, tolerance);

  // Each triangle's normal (unnormalised) and its length, computed once:
  // on a noisy 124k scan the test below ran ~50 million times.
  std::vector<Vec3> normal(soup.triangles.size());
  std::vector<double> normal_length(soup.triangles.size());
  for (size_t t = 0; t < soup.triangles.size(); ++t) {
    normal[t] = cross(soup.corner(t, 1) - soup.corner(t, 0), soup.corner(t, 2) - soup.corner(t, 0));
    normal_length[t] = norm(normal[t]);
  }
  // A neighbour across an edge lies on its far side; a triangle on the same
  // side and nearly parallel overlaps ours: it is the next row of a strip
  // finer than the noise (a teapot's rim), not a neighbour. (A true fold
  // sharper than ~37 degrees would be refused too; meshes rarely have one.)
  auto overlaps = [&](uint32_t e, uint32_t f) {
    const uint32_t t = e / 3, u = f / 3;
    const Vec3 p = pos(e), q = pos(next(e));
    const Vec3& n1 = normal[t];
    const double l1 = normal_length[t], l2 = normal_length[u];
    if (!(l1 > 0) || !(l2 > 0) || std::abs(dot(n1, normal[u])) < 0.8 * l1 * l2) return false;
    const Vec3 side = cross(n1, q - p);
    const double mine = dot(pos(prev(e)) - p, side), theirs = dot(pos(prev(f)) - p, side);
    return mine * theirs > 0;
  };
  const double tol2 = tolerance * tolerance;
  // Every candidate pair (edge, other edge running back within the
  // tolerance at both ends) whose edge lies in [e0, e1), each listed once.
  auto for_each_candidate = [&](uint32_t e0, uint32_t e1, auto&& f) {
    for (uint32_t e = e0; e < e1; ++e) {
      const Vec3 p = pos(e), q = pos(next(e));
      grid.for_each_near(q, [&](uint32_t c, const Vec3& at) {  // c lies near q
        // Each pair is listed by its lower edge id (the tests are symmetric).
        if (c <= e && (!flipped_neighbours || prev(c) <= e)) return;
        if (c / 3 == e / 3) return;
        const double dq = norm2(at - q);
        if (dq > tol2) return;
        // Back along c -> next(c) (consistent winding), or forward along
        // prev(c) -> c (a flipped neighbour).
        if (e < c) {
          const double back = norm2(pos(next(c)) - p);
          if (back <= tol2 && !overlaps(e, c)) f(EdgeMatch{dq + back, e, c, false});
        }
        if (flipped_neighbours && e < prev(c)) {
          const double forward = norm2(pos(prev(c)) - p);
          if (forward <= tol2 && !overlaps(e, prev(c)))
            f(EdgeMatch{dq + forward, e, prev(c), true});
        }
      });
    }
  };
  // The pass over the candidates splits the edges over the threads, in
  // contiguous ranges (thread order is edge order).
  const int threads = std::max(1, omp_get_max_threads());
  auto range = [&](int i, int of) { return uint32_t(uint64_t(corners) * uint64_t(i) / uint64_t(of)); };

  // An edge whose two closest partners are about as close is ambiguous
  // (rows of a strip finer than the noise): leave it unmatched rather than
  // guess, since a wrong weld costs more than a missing one. Each thread
  // keeps its own two least costs per edge; the merge is exact (the two
  // least of the union). Only a clear winner can ever be matched, and a
  // pair that is not one among the pairs seen so far never becomes one
  // (the least costs only fall): each thread keeps just the pairs that are
  // clear winners when found, and the merged costs sift those (on a noisy
  // 124k scan the full list held tens of millions of pairs; finding them
  // all a second time was half the weld).
  auto clear_winner = [&](double cost, uint32_t edge, uint32_t other, const std::vector<double>& second) {
    return ambiguity_ratio * cost <= second[edge] && ambiguity_ratio * cost <= second[other];
  };
  std::vector<std::vector<double>> best_of(threads), second_of(threads);
  std::vector<std::vector<EdgeMatch>> kept(threads);
#pragma omp parallel num_threads(threads)
  {
    const int me = omp_get_thread_num(), of = omp_get_num_threads();
    std::vector<double>& best = best_of[me];
    std::vector<double>& second = second_of[me];
    best.assign(corners, kNone);
    second.assign(corners, kNone);
    auto note = [&](uint32_t e, double cost) {
      if (cost < best[e]) { second[e] = best[e]; best[e] = cost; }
      else if (cost < second[e]) second[e] = cost;
    };
    for_each_candidate(range(me, of), range(me + 1, of), [&](const EdgeMatch& m) {
      note(m.edge, m.cost);
      note(m.other, m.cost);
      if (clear_winner(m.cost, m.edge, m.other, second)) kept[me].push_back(m);
    });
  }
  std::vector<double>& best = best_of[0];
  std::vector<double>& second = second_of[0];
  for (int t = 1; t < threads; ++t) {
    if (best_of[t].empty()) continue;
    for (size_t e = 0; e < corners; ++e) {
      const double b = best_of[t][e], s2 = second_of[t][e];
      if (b < best[e]) { second[e] = std::min(best[e], s2); best[e] = b; }
      else second[e] = std::min(second[e], b);
    }
    best_of[t] = {};
    second_of[t] = {};
  }
  std::vector<EdgeMatch> candidates;
  for (auto& k : kept)
    for (const EdgeMatch& m : k)
      if (clear_winner(m.cost, m.edge, m.other, second)) candidates.push_back(m);
  kept = {};
  std::sort(candidates.begin(), candidates.end(), [](const EdgeMatch& a, const EdgeMatch& b) {
    return a.cost != b.cost ? a.cost < b.cost : (a.edge != b.edge ? a.edge < b.edge : a.other < b.other);
  });

  UnionFind uf(corners);
  std::vector<std::vector<uint32_t>> members(corners);  // triangles per root
  for (size_t c = 0; c < corners; ++c) members[c] = {uint32_t(c / 3)};
  // The triangles of the set rooted at r, or of the union of roots r0 and r1
  // when r is one of them (a match's first corner pair, not yet joined).
  auto triangles_of = [&](uint32_t r, uint32_t r0, uint32_t r1, std::vector<uint32_t>& out) {
    out = members[r];
    if (r == r0 || r == r1) {
      out = members[r0];
      if (r1 != r0) out.insert(out.end(), members[r1].begin(), members[r1].end());
    }
  };
  SharedTriangleTest share_a_triangle(soup.triangles.size());
  auto unite = [&](uint32_t a, uint32_t b) {
    const uint32_t ra = uf.find(a), rb = uf.find(b);
    if (ra == rb) return;
    uf.unite(ra, rb);
    const uint32_t root = uf.find(ra), other = root == ra ? rb : ra;
    members[root].insert(members[root].end(), members[other].begin(), members[other].end());
    members[other].clear();
    members[other].shrink_to_fit();
  };
  std::vector<uint8_t> matched(corners, 0);
  std::vector<uint32_t> side_a, side_b;
  for (const EdgeMatch& m : candidates) {
    if (matched[m.edge] || matched[m.other]) continue;
    // Corner pairs: (start of edge, the other's corner near it), (end, ...).
    const uint32_t a0 = m.edge, a1 = next(m.edge);
    const uint32_t b0 = m.reversed ? m.other : next(m.other);
    const uint32_t b1 = m.reversed ? next(m.other) : m.other;
    const uint32_t r0a = uf.find(a0), r0b = uf.find(b0), r1a = uf.find(a1), r1b = uf.find(b1);
    if (r0a != r0b && share_a_triangle(members[r0a], members[r0b])) continue;
    // The second pair as it will be once the first is joined.
    const bool second_joined = (r1a == r0a || r1a == r0b) && (r1b == r0a || r1b == r0b);
    if (r1a != r1b && !second_joined) {
      triangles_of(r1a, r0a, r0b, side_a);
      triangles_of(r1b, r0a, r0b, side_b);
      if (share_a_triangle(side_a, side_b)) continue;
    }
    unite(a0, b0);
    unite(a1, b1);
    matched[m.edge] = matched[m.other] = 1;
  }

  w.corner_vertex.resize(corners);
  std::vector<uint32_t> id(corners, UINT32_MAX);
  for (size_t c = 0; c < corners; ++c) {
    const uint32_t r = uf.find(uint32_t(c));
    if (id[r] == UINT32_MAX) id[r] = w.vertex_count++;
    w.corner_vertex[c] = id[r];
  }
  return w;
}

}  // namespace soupuv::geometry
