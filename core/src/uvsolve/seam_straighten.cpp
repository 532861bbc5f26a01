#include "uvsolve/seam_straighten.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <numeric>

#include "atlas/max_flow.h"
#include "uvsolve/local_join.h"
#include "uvsolve/pairs_by_triangle.h"
#include "uvsolve/piece_flatten.h"

namespace soupuv::uvsolve::detail {
namespace {
// Seams shorter than this are left as they are: a few pairs cannot be cut
// shorter by kMinGain.
constexpr size_t kMinSeam = 4;
// How far from the seam its course may move, in rings of welded triangles,
// widest first: a seam that zigzags across a row of triangles strays one or
// two rings from its shortest course; where the widest band's cut is
// refused (it found a shorter course through a neck, and an island of that
// shape does not flatten), the narrowest one's only straightens the teeth.
constexpr int kBandRings[] = {3, 1};
// The least gain, in seam pairs, worth two flattenings.
constexpr size_t kMinGain = 2;
// The joins may cost this many times the soup's triangles in all: each the
// flattening of the triangles that move (flatten_cost) and the test of the
// two islands, counted as a kJudgeShare-th of their triangles.
constexpr size_t kStraightenBudget = 2;
constexpr size_t kJudgeShare = 4;
// Seams flattened at once (a constant, so the result does not depend on the
// thread count).
constexpr size_t kBatch = 64;

// A new division of two islands.
struct Division {
  std::vector<uint32_t> tris_i, tris_j;  // soup order (rejoin_side reorders them)
  size_t gain = 0;                        // seam pairs it closes
  size_t moved = 0;                       // triangles that change island
};

struct Attempt {
  uint32_t i = 0, j = 0;
  std::vector<Division> tries;  // by band, widest first
  int kept = -1;                // the try kept
  bool moved_i = false, moved_j = false;  // the island took triangles (has a new piece)
  bool whole_allowed = false;             // a refused local join may be followed by a flattening
  size_t flattened = 0;                   // flatten_cost of the flattenings made
  Piece piece_i, piece_j;
};

// What joining a division's moved triangles costs from the budget.
size_t join_cost(const Division& d) {
  return flatten_cost(d.moved) + (d.tris_i.size() + d.tris_j.size()) / kJudgeShare;
}

// The two islands divided again by a minimum cut in the band around their
// seam (see the header); false when the cut is not kMinGain pairs shorter.
// `node` is all -1 on entry and on return.
bool divide(const std::vector<geometry::AdjacentPair>& pairs, const PairsByTriangle& by, const UvLayout& L,
            const std::vector<std::vector<uint32_t>>& members, uint32_t i, uint32_t j, int rings,
            std::vector<int>& node, Division& a) {
  auto other_end = [&](uint32_t t, uint32_t e) {
    const auto& p = pairs[by.index[e]];
    return p.a == t ? p.b : p.a;
  };
  auto in_pair = [&](uint32_t t) { return L.island[t] == i || L.island[t] == j; };
  std::vector<uint32_t> band;
  std::vector<int> ring;
  auto visit = [&](uint32_t t, int r) {
    if (node[t] >= 0) return;
    node[t] = int(band.size());
    band.push_back(t);
    ring.push_back(r);
  };
  // The seam: pairs from the smaller island into the other (each once).
  const uint32_t small = members[i].size() <= members[j].size() ? i : j, large = small == i ? j : i;
  size_t seam = 0;
  for (uint32_t t : members[small])
    for (uint32_t e = by.first[t]; e < by.first[t + 1]; ++e) {
      const uint32_t o = other_end(t, e);
      if (L.island[o] != large) continue;
      ++seam;
      visit(t, 0), visit(o, 0);
    }
  for (size_t h = 0; h < band.size(); ++h) {
    if (ring[h] >= rings) continue;
    const uint32_t t = band[h];
    for (uint32_t e = by.first[t]; e < by.first[t + 1]; ++e) {
      const uint32_t o = other_end(t, e);
      if (in_pair(o)) visit(o, ring[h] + 1);
    }
  }
  // Nodes: the band, then the source (island i) and the sink (island j).
  // A pair is one unit of cut; a triangle leaving its island costs a
  // little, so among the shortest cuts the one moving fewest is taken.
  const int n = int(band.size()), source = n, sink = n + 1;
  atlas::FlowGraph g(n + 2);
  const double held = 4.0 * double(seam + 1), stay = 1.0 / double(n + 2);
  bool anchored[2] = {false, false};
  int deepest[2] = {-1, -1};
  for (int h = 0; h < n; ++h) {
    const uint32_t t = band[h];
    const int side = L.island[t] == i ? 0 : 1;
    deepest[side] = std::max(deepest[side], ring[h]);
    for (uint32_t e = by.first[t]; e < by.first[t + 1]; ++e) {
      const uint32_t o = other_end(t, e);
      if (!in_pair(o)) continue;
      if (node[o] >= 0) {
        if (pairs[by.index[e]].a == t) g.add_edge(h, node[o], 1.0);
      } else {
        // Beyond the band: the same island as t (a pair between the two
        // islands puts both its triangles in the first ring).
        g.add_edge(h, side == 0 ? source : sink, held);
        anchored[side] = true;
      }
    }
    g.add_edge(h, side == 0 ? source : sink, stay);
  }
  // An island wholly inside the band holds its farthest ring.
  for (int h = 0; h < n; ++h) {
    const int side = L.island[band[h]] == i ? 0 : 1;
    if (!anchored[side] && ring[h] == deepest[side]) g.add_edge(h, side == 0 ? source : sink, held);
  }
  const atlas::MinCut cut = g.min_cut(source, sink);
  size_t cut_pairs = 0;
  for (int h = 0; h < n; ++h) {
    const uint32_t t = band[h];
    for (uint32_t e = by.first[t]; e < by.first[t + 1]; ++e) {
      const auto& p = pairs[by.index[e]];
      if (p.a != t || node[p.b] < 0) continue;
      cut_pairs += cut.source_side[h] != cut.source_side[node[p.b]];
    }
  }
  const bool shorter = cut_pairs + kMinGain <= seam;
  if (shorter) {
    a.gain = seam - cut_pairs;
    for (int h = 0; h < n; ++h) a.moved += bool(cut.source_side[h]) != (L.island[band[h]] == i);
    for (uint32_t x : {i, j})
      for (uint32_t t : members[x]) {
        const bool to_i = node[t] >= 0 ? bool(cut.source_side[node[t]]) : x == i;
        (to_i ? a.tris_i : a.tris_j).push_back(t);
      }
    std::sort(a.tris_i.begin(), a.tris_i.end());
    std::sort(a.tris_j.begin(), a.tris_j.end());
  }
  for (uint32_t t : band) node[t] = -1;
  return shorter && !a.tris_i.empty() && !a.tris_j.empty();
}

// One island of the new division, its triangles that stayed first: those
// that came from the other island take the vertices of their welded
// neighbours that stayed, and are joined onto the island's map as it
// stands (local_join.h); where that is refused and `whole_allowed`, the
// island is flattened anew from its own shape (piece_flatten.h; its cost
// added to `flattened`). `moved` receives whether any came; an island that
// only gave triangles away keeps its map (it needs no piece) if it stays
// one piece.
bool rejoin_side(const Soup& soup, double uv_per_length, const std::vector<geometry::AdjacentPair>& pairs,
                 const PairsByTriangle& by, const UvLayout& L, std::vector<uint32_t>& tris, uint32_t stayed,
                 std::vector<uint8_t>& in_side, std::vector<uint32_t>& join, double cell,
                 double max_stretch, int solve_iterations, bool whole_allowed, Piece& piece, bool& moved,
                 size_t& flattened) {
  const size_t staying = size_t(
      std::stable_partition(tris.begin(), tris.end(), [&](uint32_t t) { return L.island[t] == stayed; }) -
      tris.begin());
  moved = staying < tris.size();
  for (uint32_t t : tris) in_side[t] = 1;
  std::vector<uint32_t> touched;
  for (size_t k = staying; k < tris.size(); ++k) {
    const uint32_t t = tris[k];
    for (uint32_t e = by.first[t]; e < by.first[t + 1]; ++e) {
      const auto& p = pairs[by.index[e]];
      const uint32_t o = p.a == t ? p.b : p.a;
      if (in_side[o] && L.island[o] == stayed) join_across(p, t, L, join, touched);
    }
  }
  const PieceMesh m = piece_mesh(soup, uv_per_length, tris, L, &join);
  for (uint32_t v : touched) join[v] = v;
  for (uint32_t t : tris) in_side[t] = 0;
  if (m.components != 1) return false;
  if (!moved) return true;
  if (join_locally(m, tris, staying, L, cell, max_stretch, solve_iterations, piece) == Outcome::kept) return true;
  if (!whole_allowed) return false;
  flattened += flatten_cost(tris.size());
  return flatten(m, tris, cell, max_stretch, solve_iterations, piece) == Outcome::kept;
}
}  // namespace

SeamStraightenFigures straighten_seams(const Soup& soup, double uv_per_length,
                                       const std::vector<geometry::AdjacentPair>& pairs, double cell,
                                       double max_stretch, int solve_iterations, int threads, UvLayout& L) {
  SeamStraightenFigures f;
  const size_t n = L.corner_vertex.size();
  std::vector<std::vector<uint32_t>> members = island_triangles(L);
  const PairsByTriangle by(pairs, n);
  // Seams between islands of at least kMinSeam pairs, longest first.
  std::vector<std::pair<uint64_t, uint32_t>> seams = seams_longest_first(pairs, L);
  seams.erase(std::remove_if(seams.begin(), seams.end(), [](const auto& x) { return x.second < kMinSeam; }),
              seams.end());
  f.seams = seams.size();
  const size_t budget = kStraightenBudget * n;
  size_t spent = 0;
  const int team = std::max(1, threads);
  std::vector<int> node(n, -1);
  std::vector<std::vector<uint8_t>> in_side(size_t(team), std::vector<uint8_t>(n, 0));
  std::vector<std::vector<uint32_t>> join(static_cast<size_t>(team));
  std::vector<uint8_t> busy(L.island_count, 0);
  std::vector<std::pair<uint64_t, uint32_t>> pending = std::move(seams), later;
  std::vector<Attempt> batch;
  bool changed = false;
  // Rounds: seams whose islands no earlier seam of the round touches are
  // divided (serially: a max-flow on a band is cheap), the shorter ones
  // flattened at once, then applied in seam order; a seam whose island is
  // taken waits for the next round and sees the division made there.
  while (!pending.empty()) {
    batch.clear();
    later.clear();
    std::vector<uint32_t> busy_list;
    size_t k = 0;
    for (; k < pending.size() && batch.size() < kBatch; ++k) {
      const uint32_t i = uint32_t(pending[k].first >> 32), j = uint32_t(pending[k].first);
      if (busy[i] || busy[j]) {
        later.push_back(pending[k]);
        for (uint32_t x : {i, j})
          if (!busy[x]) busy[x] = 1, busy_list.push_back(x);
        continue;
      }
      Attempt a;
      a.i = i, a.j = j;
      for (const int rings : kBandRings) {
        Division d;
        if (!divide(pairs, by, L, members, i, j, rings, node, d)) continue;
        if (!a.tries.empty() && d.tris_i == a.tries.back().tris_i) continue;  // the same cut
        a.tries.push_back(std::move(d));
      }
      if (a.tries.empty()) continue;
      ++f.shorter;
      const Division& first = a.tries.front();
      const size_t cost = join_cost(first);
      if (spent + cost > budget) {
        ++f.over_budget;
        continue;
      }
      spent += cost;
      a.whole_allowed = spent + flatten_cost(first.tris_i.size()) + flatten_cost(first.tris_j.size()) <= budget;
      for (uint32_t x : {i, j}) busy[x] = 1, busy_list.push_back(x);
      batch.push_back(std::move(a));
    }
    later.insert(later.end(), pending.begin() + long(k), pending.end());
    for (auto& v : join) {
      const size_t old = v.size();
      v.resize(L.uv.size());
      std::iota(v.begin() + long(old), v.end(), uint32_t(old));
    }
#pragma omp parallel for schedule(dynamic, 1) num_threads(team)
    for (size_t b = 0; b < batch.size(); ++b) {
      Attempt& a = batch[b];
      const size_t me = size_t(omp_get_thread_num());
      for (size_t k = 0; k < a.tries.size() && a.kept < 0; ++k) {
        Division& d = a.tries[k];
        if (k > 0) a.flattened += join_cost(d);  // the first was paid for when formed
        if (rejoin_side(soup, uv_per_length, pairs, by, L, d.tris_i, a.i, in_side[me], join[me], cell, max_stretch,
                        solve_iterations, a.whole_allowed, a.piece_i, a.moved_i, a.flattened) &&
            rejoin_side(soup, uv_per_length, pairs, by, L, d.tris_j, a.j, in_side[me], join[me], cell, max_stretch,
                        solve_iterations, a.whole_allowed, a.piece_j, a.moved_j, a.flattened))
          a.kept = int(k);
      }
    }
    for (Attempt& a : batch) {
      spent += a.flattened;
      if (a.kept < 0) {
        ++f.refused;
        continue;
      }
      Division& d = a.tries[size_t(a.kept)];
      ++f.straightened;
      f.pairs_gained += d.gain;
      changed = true;
      for (int side = 0; side < 2; ++side) {
        const std::vector<uint32_t>& tris = side == 0 ? d.tris_i : d.tris_j;
        const Piece& piece = side == 0 ? a.piece_i : a.piece_j;
        const uint32_t id = side == 0 ? a.i : a.j;
        if (!(side == 0 ? a.moved_i : a.moved_j)) continue;  // it only gave triangles away
        const uint32_t base = uint32_t(L.uv.size());
        L.uv.insert(L.uv.end(), piece.uv.begin(), piece.uv.end());
        for (size_t t = 0; t < tris.size(); ++t) {
          for (int c = 0; c < 3; ++c) L.corner_vertex[tris[t]][c] = base + piece.corner[t][c];
          L.island[tris[t]] = id;
        }
      }
      members[a.i] = std::move(d.tris_i);
      members[a.j] = std::move(d.tris_j);
    }
    for (uint32_t x : busy_list) busy[x] = 0;
    pending.swap(later);
  }
  if (changed) split_vertices_by_island(L);
  return f;
}

}  // namespace soupuv::uvsolve::detail
