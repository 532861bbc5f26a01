// Welding a noisy soup by matching its edges (see weld.h, weld_by_edges).
//
// Input : a soup and a tolerance (absolute length): the farthest two copies
//         of one original vertex may lie apart.
// Output: a Weld (corner -> vertex id) whose vertices are the corners joined
//         through matched edges.
// Method: every directed triangle edge (p -> q) looks for edges of other
//         triangles running back (q' -> p', or p' -> q' for a flipped
//         neighbour) with both endpoints within the tolerance, costing the
//         sum of the squared endpoint distances; a pair among the four
//         cheapest of both its edges is offered. The offered pairs are
//         matched for the least total cost, each edge at most once
//         (pair_matching.h), then joined cheapest first, a join refused when
//         it would put two corners of one triangle together (even through a
//         chain of joins); edges a refusal left alone take their cheapest
//         remaining offer. The matched edges' endpoints are welded.
// Why the least total and not the cheapest pair first: where rows of thin
//         triangles are narrower than the noise (a bolt's shank), the row
//         beside is often the closer, and a greedy that takes it leaves the
//         right partner to a wrong one in turn; on the corpus's bracket soup
//         it joined 1,497 wrong pairs and found 89.9 % of the right ones,
//         the least total 645 and 96.9 % (docs/tuning.md, "The edge weld as
//         an assignment").
// Why edges and not positions: where the soup's noise is as large as its
//         shortest edges (a teapot's lid knob, 0.9e-3 of the diagonal against
//         copies up to 3e-3 apart), welding corners nearest-first joins
//         distinct vertices (teapot: 409 corners on a wrong vertex, 430 false
//         neighbour pairs) and the repair then untangles a patch that was
//         never a surface. An edge needs both ends to agree, so a wrong
//         partner must be close at both ends, which is much rarer.
// Cost  : O(n) expected (uniform hash grid, corner_grid.h; the queries of
//         one cell tested together against the corners around it, eight at
//         a time: edge_block.h), plus sorting the candidate pairs and the
//         matching (local searches, in parallel over the candidates'
//         connected parts); the pass over the candidates runs on the OpenMP
//         threads.
#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include <omp.h>

#include "geometry/corner_grid.h"
#include "geometry/edge_block.h"
#include "geometry/pair_matching.h"
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
  // Cells a hair over the tolerance: every corner within the tolerance of
  // a cell's point lies in the 27 cells around it, whatever the rounding
  // (cells of exactly the tolerance reached two cells out), and a cell's
  // queries share that block (cells of half the tolerance gave a block of
  // 125 cells to ~4 queries). A zero tolerance still buckets exact copies
  // together; the grid stays at most 2^20 cells per axis (a coarser cell
  // only costs more distance tests).
  const double cell = std::max({tolerance * (1 + 1e-6), span / double(1 << 20), box.diagonal() * 1e-9, 1e-300});
  const CornerGrid grid(soup, box, cell, tolerance, /*with_next=*/true);

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
  // tolerance at both ends), each listed once, by the queries of the grid
  // cells [k0, k1): a cell's query edges are those ending at its corners;
  // the corners near any of them are gathered once (edge_block.h) and each
  // query tests them all, the survivors exactly in double.
  struct Cell {
    uint32_t first, end;
    Vec3 centre;
  };
  std::vector<Cell> cells;
  grid.for_each_cell([&](uint32_t first, uint32_t end, const Vec3& centre) { cells.push_back({first, end, centre}); });
  // The float prefilter's reach: a hair over the tolerance (float rounding
  // of coordinates within ~2 tolerances of the cell's centre is ~1e-7 of
  // them); 0 stays 0, which passes exact copies only.
  const float reach2 = float(tol2 * (1 + 1e-3));
  // The float costs' error: ~1e-7 of the coordinates (within ~2 tolerances
  // of the cell's centre) in each squared distance.
  const float bound_margin = float(1e-5 * tol2);
  auto for_each_candidate = [&](size_t k0, size_t k1, const std::vector<float>& bound_of, auto&& wanted, auto&& f) {
    detail::EdgeBlock block;
    std::vector<const Vec3*> at_of, next_of;
    std::vector<uint32_t> hits;
    for (size_t k = k0; k < k1; ++k) {
      const Cell& cell = cells[k];
      const Vec3 o = cell.centre;
      block.clear(flipped_neighbours);
      at_of.clear();
      next_of.clear();
      grid.for_each_near_cell(
          o,
          [&](const Vec3& lo, const Vec3& hi) {
            block.begin_run(lo - o, hi - o);
            at_of.resize(block.size(), nullptr);  // the padding of the run before
            next_of.resize(block.size(), nullptr);
          },
          [&](uint32_t c, const Vec3& at, const Vec3& at_next) {
            block.add(c, at - o, at_next - o, flipped_neighbours ? pos(prev(c)) - o : Vec3{0, 0, 0});
            at_of.push_back(&at);
            next_of.push_back(&at_next);
          });
      block.seal();
      for (uint32_t i = cell.first; i < cell.end; ++i) {
        const uint32_t e = prev(grid.entry_corner(i));  // the edge e -> next(e) ends in this cell
        const Vec3 p = pos(e), q = grid.entry_position(i);
        const Vec3 qo = q - o, po = p - o;
        const float qf[3] = {float(qo.x), float(qo.y), float(qo.z)}, pf[3] = {float(po.x), float(po.y), float(po.z)};
        // Without flipped neighbours a pair is listed by its lower edge:
        // only corners above e can pair with it here.
        const detail::CostBound bound{bound_of.data(), bound_of[e], bound_margin};
        block.near_both(qf, pf, reach2, flipped_neighbours, flipped_neighbours ? 0 : e + 1,
                        flipped_neighbours ? nullptr : &bound, hits);
        for (const uint32_t h : hits) {
          const uint32_t c = block.corner(h);  // c lies near q
          // Each pair is listed by its lower edge id (the tests are symmetric).
          if (c <= e && (!flipped_neighbours || prev(c) <= e)) continue;
          if (c / 3 == e / 3) continue;
          const double dq = norm2(*at_of[h] - q);
          if (dq > tol2) continue;
          // Back along c -> next(c) (consistent winding), or forward along
          // prev(c) -> c (a flipped neighbour).
          if (e < c) {
            const double back = norm2(*next_of[h] - p);
            if (back <= tol2 && wanted(dq + back, e, c) && !overlaps(e, c)) f(EdgeMatch{dq + back, e, c, false});
          }
          if (flipped_neighbours && e < prev(c)) {
            const double forward = norm2(pos(prev(c)) - p);
            if (forward <= tol2 && wanted(dq + forward, e, prev(c)) && !overlaps(e, prev(c)))
              f(EdgeMatch{dq + forward, e, prev(c), true});
          }
        }
      }
    }
  };
  // The pass over the candidates splits the cells over the threads (each
  // keeps its own least costs, merged after: the result does not depend
  // on which thread found a pair).
  const int threads = std::max(1, omp_get_max_threads());

  // Each edge's kKept least candidate costs (per thread, then merged:
  // the least of the union). Only a pair among the kKept cheapest of both
  // its edges is offered to the matching: the right partner is almost
  // always among them (table of the corpus: the closest for 67 % of its
  // edges, among the four closest for 93 %), and on a noisy 124k scan,
  // where the tolerance spans several edges, the full list held tens of
  // millions of pairs. A pair that is not among them when found never
  // becomes one (the least costs only fall), so each thread keeps just the
  // pairs that are when found, and the merged costs sift those.
  // With ambiguity_ratio > 1 an edge whose two closest partners are about
  // as close (rows of a strip finer than the noise) is left unmatched
  // rather than guessed: a pair is offered only when ambiguity_ratio times
  // its cost is within the second least of both edges.
  constexpr int kKept = 4;
  auto offered = [&](double cost, uint32_t edge, uint32_t other, const std::vector<double>& least) {
    const double* e = &least[size_t(edge) * kKept];
    const double* o = &least[size_t(other) * kKept];
    if (!(cost <= e[kKept - 1] && cost <= o[kKept - 1])) return false;
    return !(ambiguity_ratio > 1) || (ambiguity_ratio * cost <= e[1] && ambiguity_ratio * cost <= o[1]);
  };
  auto note = [](double* list, double cost) {
    if (!(cost < list[kKept - 1])) return;
    int k = kKept - 1;
    while (k > 0 && list[k - 1] > cost) list[k] = list[k - 1], --k;
    list[k] = cost;
  };
  std::vector<std::vector<double>> least_of(threads);
  std::vector<std::vector<EdgeMatch>> kept(threads);
#pragma omp parallel num_threads(threads)
  {
    const int me = omp_get_thread_num();
    std::vector<double>& least = least_of[me];
    least.assign(size_t(corners) * kKept, kNone);
    // A pair at or above both edges' kKept-th least cost so far (and above
    // one of them) changes neither list nor is offered, and never will be
    // (the least costs only fall): it skips the overlap test. On a noisy
    // 124k scan ~48 million pairs lie within the tolerance at both ends,
    // and testing each was most of the weld.
    auto wanted = [&](double cost, uint32_t edge, uint32_t other) {
      const double e = least[size_t(edge) * kKept + kKept - 1], o = least[size_t(other) * kKept + kKept - 1];
      return !(cost >= e && cost >= o && (cost > e || cost > o));
    };
    // Each edge's kKept-th least cost so far, rounded up to float: the SIMD
    // prefilter's cost bound (edge_block.h).
    std::vector<float> bound_of(corners, INFINITY);
    auto bound = [&](uint32_t edge) {
      const double x = least[size_t(edge) * kKept + kKept - 1];
      float f = float(x);
      if (double(f) < x) f = std::nextafter(f, INFINITY);
      bound_of[edge] = f;
    };
    auto keep = [&](const EdgeMatch& m) {
      note(&least[size_t(m.edge) * kKept], m.cost);
      note(&least[size_t(m.other) * kKept], m.cost);
      bound(m.edge), bound(m.other);
      if (offered(m.cost, m.edge, m.other, least)) kept[me].push_back(m);
    };
    // Chunks of cells, taken in turn: a cell's work varies with its corners.
    constexpr size_t kChunk = 64;
#pragma omp for schedule(dynamic, 1)
    for (size_t k = 0; k < cells.size(); k += kChunk) for_each_candidate(k, std::min(cells.size(), k + kChunk), bound_of, wanted, keep);
  }
  std::vector<double>& least = least_of[0];
  for (int t = 1; t < threads; ++t) {
    if (least_of[t].empty()) continue;
    for (size_t e = 0; e < corners; ++e)
      for (int k = 0; k < kKept; ++k) note(&least[e * kKept], least_of[t][e * kKept + k]);
    least_of[t] = {};
  }
  std::vector<EdgeMatch> candidates;
  for (auto& k : kept)
    for (const EdgeMatch& m : k)
      if (offered(m.cost, m.edge, m.other, least)) candidates.push_back(m);
  kept = {};
  least_of = {};
  std::sort(candidates.begin(), candidates.end(), [](const EdgeMatch& a, const EdgeMatch& b) {
    if (a.cost != b.cost) return a.cost < b.cost;
    if (a.edge != b.edge) return a.edge < b.edge;
    return a.other != b.other ? a.other < b.other : a.reversed < b.reversed;
  });
  // The least-cost matching (pair_matching.h) chooses the pairs; an edge
  // left alone costs as much as the dearest pair, so every pair is worth
  // taking. Its pairs are joined first, cheapest first, under the
  // one-triangle rule below; what that rule refuses leaves edges for the
  // other offered pairs, cheapest first.
  {
    std::vector<CandidatePair> offer(candidates.size());
    for (size_t i = 0; i < candidates.size(); ++i) offer[i] = {candidates[i].edge, candidates[i].other, candidates[i].cost};
    const std::vector<uint8_t> chosen = least_cost_matching(uint32_t(corners), offer, 2 * tol2, threads);
    std::vector<EdgeMatch> ordered;
    ordered.reserve(candidates.size());
    for (size_t i = 0; i < candidates.size(); ++i)
      if (chosen[i]) ordered.push_back(candidates[i]);
    for (size_t i = 0; i < candidates.size(); ++i)
      if (!chosen[i]) ordered.push_back(candidates[i]);
    candidates.swap(ordered);
  }

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
