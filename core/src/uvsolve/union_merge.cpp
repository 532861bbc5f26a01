#include "uvsolve/union_merge.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <array>
#include <numeric>
#include <set>
#include <unordered_map>

#include <omp.h>

#include "uvsolve/local_join.h"
#include "uvsolve/pairs_by_triangle.h"
#include "uvsolve/piece_flatten.h"

namespace soupuv::uvsolve::detail {
namespace {
// Attempts may flatten this many times the soup's triangles in all,
// counted by flatten_cost.
constexpr size_t kFlattenBudget = 8;
// One flattening may cost at most this many times the soup's triangles
// (flatten_cost): a soup of up to 18,750 triangles may still be flattened
// whole, the largest union of a 69k soup is ~45k triangles and of a 124k
// soup ~65k. A union that would cost more is not tried, and a failed local
// join is not followed by its flattening. On stanford-bunny (69k, 14
// islands) unions of 47k and 60k triangles took 5 and 10 s against a
// 7-9 s trace. A cap of the soup's size (1) also held back the fallbacks
// of failed local joins there (union merge 16 -> 2 s), but fandisk and
// the duck, spot and fandisk soups at new seeds lost 1-1.4 points of
// continuity: their whole unions cost 1.2-2.1 soups (docs/tuning.md,
// session 43).
constexpr double kMaxOneFlatten = 2.5;
// An island at most this share of the other's size is first joined onto
// the larger one's map as it stands (local_join.h); only when that fails
// is the union flattened anew.
constexpr size_t kLocalJoinRatio = 8;
// Attempts flattened at once (a constant, so the result does not depend on
// the thread count).
constexpr size_t kBatch = 64;
// A disk union whose outline is shorter than a hemisphere's of the same
// area (isoperimetric quotient L^2 / (4 pi A) below 0.5; a flat disc has 1)
// is nearly closed: refused for stretch or a fold, it is slit along half its
// seam like a closed one, whatever the seam's shape. A sphere missing a few
// triangles has a seam that is a path, not a loop: SpheresScaledInstances'
// soups at seeds 42, 46 and 54 kept 0.944 / 0.950 / 0.948 of their resolved
// edges without it, 0.951 / 0.955 / 0.953 with it (docs/tuning.md, session 45).
constexpr double kNearlyClosedQuotient = 0.5;

// The vertices to leave unjoined so that half of a seam opens: the seam's
// edges (by the smaller island's vertices) must meet at most two at a
// vertex; its longest chain is walked from one end (from its first edge's
// vertex when it is a loop), and the vertices of the walk's first half are
// returned, the loop's first vertex left joined (a loop opened along a run
// of its edges; a path from its end, where it meets the union's outline).
// Empty for a seam with a branch, or too short to open.
std::vector<uint32_t> half_seam_opening(const std::vector<std::array<uint32_t, 2>>& edges, bool loop_only) {
  constexpr uint32_t kNone = UINT32_MAX;
  if (edges.size() < 4) return {};
  std::unordered_map<uint32_t, std::array<uint32_t, 2>> next;
  next.reserve(2 * edges.size());
  for (const auto& e : edges) {
    if (e[0] == e[1]) return {};
    for (int s = 0; s < 2; ++s) {
      auto [it, fresh] = next.try_emplace(e[s], std::array<uint32_t, 2>{kNone, kNone});
      auto& slot = it->second;
      if (slot[0] == kNone) slot[0] = e[1 - s];
      else if (slot[1] == kNone && slot[0] != e[1 - s]) slot[1] = e[1 - s];
      else return {};  // a third edge, or the same edge twice
    }
  }
  // Chains in a fixed order (the edges' order), each walked from an end if
  // it has one; the longest kept.
  std::unordered_map<uint32_t, uint8_t> seen;
  std::vector<uint32_t> best;
  bool best_loop = false;
  for (const auto& e : edges) {
    if (seen.count(e[0])) continue;
    // To an end of its chain; a loop starts at e[0].
    uint32_t previous = kNone, at = e[0];
    for (size_t steps = 0; steps <= next.size(); ++steps) {
      const auto& n = next.at(at);
      if (n[1] == kNone) break;  // an end
      const uint32_t to = n[0] != previous ? n[0] : n[1];
      if (to == e[0]) {
        at = e[0];
        break;
      }
      previous = at, at = to;
    }
    std::vector<uint32_t> chain{at};
    seen[at] = 1;
    previous = kNone;
    bool loop = false;
    while (true) {
      const auto& n = next.at(chain.back());
      const uint32_t to = n[0] != previous ? n[0] : n[1];
      if (to == kNone) break;
      if (to == chain.front()) {
        loop = true;
        break;
      }
      previous = chain.back();
      chain.push_back(to);
      seen[to] = 1;
    }
    if (chain.size() > best.size()) best = std::move(chain), best_loop = loop;
  }
  if (loop_only && !best_loop) return {};
  const size_t edges_in = best_loop ? best.size() : best.size() - 1;
  if (edges_in < 4) return {};
  const size_t from = best_loop ? 1 : 0;
  return std::vector<uint32_t>(best.begin() + long(from), best.begin() + long(edges_in / 2));
}

// A disk piece whose outline is short for its area: isoperimetric quotient
// L^2 / (4 pi A) below kNearlyClosedQuotient, lengths and area in 3D.
bool nearly_closed_disk(const Soup& soup, const PieceMesh& m, const std::vector<uint32_t>& tris) {
  if (m.chart.boundary_loops != 1 || m.chart.boundary.size() < 3) return false;
  double area = 0, length = 0;
  for (uint32_t t : tris) area += triangle_area(soup, t);
  const auto& b = m.chart.boundary;
  for (size_t k = 0; k < b.size(); ++k) length += norm(m.chart.position[b[k]] - m.chart.position[b[(k + 1) % b.size()]]);
  return area > 0 && length * length < kNearlyClosedQuotient * 4 * std::acos(-1.0) * area;
}

// The island x has been joined into (read-only: the parallel attempts
// must not compress the shared paths).
uint32_t root_of(const std::vector<uint32_t>& root, uint32_t x) {
  while (root[x] != x) x = root[x];
  return x;
}
}  // namespace

UnionMergeFigures merge_by_reflattening(const Soup& soup, double uv_per_length,
                                        const std::vector<geometry::AdjacentPair>& pairs, double cell,
                                        double max_stretch, int solve_iterations, size_t attempts_per_island,
                                        bool slit, int threads, UvLayout& L,
                                        const std::function<void(double share)>& on_round) {
  UnionMergeFigures f;
  std::vector<std::vector<uint32_t>> members = island_triangles(L);
  const size_t n = L.corner_vertex.size();
  const PairsByTriangle by_triangle(pairs, n);
  // Seams between islands, longest (most shared pairs) first.
  std::vector<std::pair<uint64_t, uint32_t>> seams = seams_longest_first(pairs, L);
  std::vector<uint32_t> root(L.island_count);
  std::iota(root.begin(), root.end(), 0u);
  auto find = [&](uint32_t x) {
    while (root[x] != x) x = root[x] = root[root[x]];
    return x;
  };
  std::vector<size_t> attempts(L.island_count, 0);
  // The work bound: triangles flattened in all attempts together.
  const size_t budget = kFlattenBudget * n;
  size_t flattened = 0;
  const int team = std::max(1, threads);
  // Per thread: layout vertex -> the vertex it is joined to (identity but
  // for the join being flattened).
  std::vector<std::vector<uint32_t>> vertex_of(static_cast<size_t>(team));

  // Rounds: up to kBatch attempts on islands no earlier attempt of the
  // round touches are flattened at once, then applied in seam order. A
  // seam whose island an earlier seam of the round touches waits for the
  // next round, and blocks its islands for the seams after it, so every
  // attempt sees its islands as the one-by-one order would.
  struct Attempt {
    uint32_t i, j;  // j: the smaller, joined into i
    std::vector<uint32_t> tris;
    bool kept = false;
    bool refused_before = false;  // the same two islands, unchanged, were refused
    Piece piece;
    Outcome outcome = Outcome::parts;
    double stretch_floor = 1;  // on a stretch refusal (piece_flatten.h)
    bool local_first = false;     // joined onto i's map first (local_join.h)
    bool whole_allowed = true;    // the union may be flattened anew (kMaxOneFlatten)
    bool joined_locally = false;  // kept so
    bool flattened_whole = false;  // the union flattened anew
    bool slit = false;             // and again with half its seam open (a closed union)
  };
  // Refusals by the two islands and their versions (joins so far): a seam
  // between islands already refused as they are now gets the same answer
  // (several seams of one island often lead to the same neighbour), so it
  // is counted as tried but not flattened again.
  std::vector<uint32_t> version(L.island_count, 0);
  std::set<std::array<uint32_t, 4>> refused;
  auto refusal_key = [&](uint32_t i, uint32_t j) {
    if (i > j) std::swap(i, j);
    return std::array<uint32_t, 4>{i, j, version[i], version[j]};
  };
  // Stretch refusals (the two islands as they were, their union's area and
  // the stretch its flattening was heading for), listed by each island's
  // current root. A union that holds a refused one is forecast to stay
  // above the budget when the refused part at its floor and the added
  // area at stretch 1 (no map of a triangle does better) average above it
  // (area-weighted, as the L2 stretch): then it is answered from the
  // refusal, like an unchanged pair. The retries of a large union after
  // its larger island took in a few small ones were the costliest attempts
  // on the CAD soups (docs/tuning.md, session 38).
  struct StretchRefusal {
    uint32_t i, j;
    double area, floor;
  };
  std::vector<StretchRefusal> stretch_refusals;
  std::vector<std::vector<uint32_t>> refusals_of(L.island_count);
  std::vector<double> area(L.island_count, 0);
  for (uint32_t x = 0; x < L.island_count; ++x)
    for (uint32_t t : members[x]) area[x] += triangle_area(soup, t);
  auto heading_over = [&](uint32_t i, uint32_t j) {
    const double now = area[i] + area[j];
    for (const uint32_t x : {i, j})
      for (uint32_t k : refusals_of[x]) {
        const StretchRefusal& r = stretch_refusals[k];
        const uint32_t ri = find(r.i), rj = find(r.j);
        if (!((ri == i && rj == j) || (ri == j && rj == i)) || !(now > 0)) continue;
        if ((r.area * r.floor * r.floor + (now - r.area)) / now > max_stretch * max_stretch) return true;
      }
    return false;
  };
  std::vector<uint8_t> busy(L.island_count, 0);
  std::vector<uint32_t> busy_list;
  auto block = [&](uint32_t x) {
    if (!busy[x]) busy[x] = 1, busy_list.push_back(x);
  };
  const double seam_count = double(seams.size());
  std::vector<std::pair<uint64_t, uint32_t>> pending = std::move(seams), later;
  std::vector<Attempt> batch;
  while (!pending.empty()) {
    if (on_round) on_round(1.0 - double(pending.size()) / seam_count);
    batch.clear();
    later.clear();
    size_t k = 0;
    for (; k < pending.size() && batch.size() < kBatch; ++k) {
      uint32_t i = find(uint32_t(pending[k].first >> 32)), j = find(uint32_t(pending[k].first));
      if (busy[i] || busy[j]) {
        later.push_back(pending[k]);
        block(i), block(j);
        continue;
      }
      if (i == j || attempts[i] >= attempts_per_island || attempts[j] >= attempts_per_island) continue;
      if (members[i].size() < members[j].size()) std::swap(i, j);
      // A join tried locally first costs about the smaller island's
      // flattening; a whole flattening after it is charged when it is made.
      const bool local_first = kLocalJoinRatio * members[j].size() <= members[i].size();
      const size_t cost = flatten_cost(local_first ? members[j].size() : members[i].size() + members[j].size());
      const bool whole_allowed = double(flatten_cost(members[i].size() + members[j].size())) <= kMaxOneFlatten * double(n);
      if (flattened + cost > budget || (!local_first && !whole_allowed)) continue;
      flattened += cost;
      ++f.attempts;
      const bool unchanged = refused.count(refusal_key(i, j)) > 0;
      const bool forecast = !unchanged && heading_over(i, j);
      batch.push_back({i, j, {}, false, unchanged || forecast, {}});
      batch.back().local_first = local_first;
      batch.back().whole_allowed = whole_allowed;
      f.repeated += unchanged;
      f.forecast_refused += forecast;
      block(i), block(j);
    }
    later.insert(later.end(), pending.begin() + k, pending.end());
    for (auto& v : vertex_of) {
      const size_t old = v.size();
      v.resize(L.uv.size());
      std::iota(v.begin() + old, v.end(), uint32_t(old));
    }
#pragma omp parallel for schedule(dynamic, 1) num_threads(team)
    for (size_t b = 0; b < batch.size(); ++b) {
      Attempt& a = batch[b];
      if (a.refused_before) continue;
      std::vector<uint32_t>& join = vertex_of[size_t(omp_get_thread_num())];
      // Close the seam: the smaller island's shared corners take the larger's vertices.
      std::vector<uint32_t> touched;
      std::vector<std::array<uint32_t, 2>> seam;  // the seam's edges, by the smaller island's vertices
      for (uint32_t t : members[a.j])
        for (uint32_t e = by_triangle.first[t]; e < by_triangle.first[t + 1]; ++e) {
          const auto& p = pairs[by_triangle.index[e]];
          const bool t_is_a = p.a == t;
          const uint32_t o = t_is_a ? p.b : p.a;
          if (root_of(root, L.island[o]) != a.i) continue;
          seam.push_back({L.corner_vertex[t][t_is_a ? p.a_corner[0] : p.b_corner[0]],
                          L.corner_vertex[t][t_is_a ? p.a_corner[1] : p.b_corner[1]]});
          join_across(p, t, L, join, touched);
        }
      a.tris = members[a.i];
      a.tris.insert(a.tris.end(), members[a.j].begin(), members[a.j].end());
      const PieceMesh m = piece_mesh(soup, uv_per_length, a.tris, L, &join);
      if (m.components == 1) {
        if (a.local_first)
          a.outcome = join_locally(m, a.tris, members[a.i].size(), L, cell, max_stretch, solve_iterations, a.piece);
        if (a.outcome == Outcome::kept) a.joined_locally = a.local_first;
        else if (a.whole_allowed) {
          a.outcome = flatten(m, a.tris, cell, max_stretch, solve_iterations, a.piece, &a.stretch_floor);
          a.flattened_whole = true;
          // Two halves of a closed part, their seam one loop, make a union
          // that is closed (no flat map) or nearly so (one that stretches
          // beyond the budget or folds): half their seam is left open, a
          // slit the union unfolds along. A union whose outline is short for
          // its area (kNearlyClosedQuotient) is slit whatever its seam's shape.
          const bool closed = a.outcome == Outcome::topology && m.chart.boundary_loops == 0;
          const bool refused_shape = a.outcome == Outcome::stretch || a.outcome == Outcome::flip;
          const std::vector<uint32_t> opened =
              !slit ? std::vector<uint32_t>{}
              : closed || (refused_shape && nearly_closed_disk(soup, m, a.tris)) ? half_seam_opening(seam, false)
              : refused_shape ? half_seam_opening(seam, true)
                              : std::vector<uint32_t>{};
          if (!opened.empty()) {
            for (uint32_t v : opened) join[v] = v;
            const PieceMesh slit = piece_mesh(soup, uv_per_length, a.tris, L, &join);
            a.slit = true;
            if (slit.components == 1)
              a.outcome = flatten(slit, a.tris, cell, max_stretch, solve_iterations, a.piece, &a.stretch_floor);
          }
        }
      }
      a.kept = a.outcome == Outcome::kept;
      for (uint32_t v : touched) join[v] = v;
    }
    for (Attempt& a : batch) {
      // A local try that failed was followed by the whole flattening.
      if (a.local_first && a.flattened_whole) flattened += flatten_cost(a.tris.size());
      if (a.slit) flattened += flatten_cost(a.tris.size());
      if (!a.kept) {
        ++attempts[a.i], ++attempts[a.j];  // only refusals count: a join may be followed by more
        refused.insert(refusal_key(a.i, a.j));
        if (!a.refused_before && a.outcome == Outcome::stretch) {
          const uint32_t k = uint32_t(stretch_refusals.size());
          stretch_refusals.push_back({a.i, a.j, area[a.i] + area[a.j], a.stretch_floor});
          refusals_of[a.i].push_back(k), refusals_of[a.j].push_back(k);
        }
        continue;
      }
      ++version[a.i];
      ++f.joined;
      f.joined_locally += a.joined_locally;
      f.slit += a.slit;
      const uint32_t base = uint32_t(L.uv.size());
      L.uv.insert(L.uv.end(), a.piece.uv.begin(), a.piece.uv.end());
      for (size_t k2 = 0; k2 < a.tris.size(); ++k2) {
        for (int c = 0; c < 3; ++c) L.corner_vertex[a.tris[k2]][c] = base + a.piece.corner[k2][c];
        L.island[a.tris[k2]] = a.i;
      }
      root[a.j] = a.i;
      area[a.i] += area[a.j];
      refusals_of[a.i].insert(refusals_of[a.i].end(), refusals_of[a.j].begin(), refusals_of[a.j].end());
      refusals_of[a.j] = {};
      members[a.i] = std::move(a.tris);
      members[a.j].clear();
      attempts[a.i] = std::max(attempts[a.i], attempts[a.j]);
    }
    for (uint32_t x : busy_list) busy[x] = 0;
    busy_list.clear();
    pending.swap(later);
  }
  if (f.joined == 0) return f;
  compact_island_ids(L);  // the survivors renumbered
  split_vertices_by_island(L);
  return f;
}

}  // namespace soupuv::uvsolve::detail
