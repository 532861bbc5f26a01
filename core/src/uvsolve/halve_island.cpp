#include "uvsolve/halve_island.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "atlas/pack.h"

namespace soupuv::uvsolve::detail {

namespace {
// Each side of the cut keeps at least this share of the island's area.
constexpr double kMinSideShare = 1.0 / 3;
// Offsets tried along the rectangle's long side.
constexpr int kCutOffsets = 64;

// The line across the long side of the minimal-area rectangle of `points`
// (a square splits into two rectangles, a long island into two shorter
// ones), at the offset that crosses the fewest triangle edges (`neighbour`:
// the triangle across each edge, UINT32_MAX for none) among kCutOffsets
// offsets leaving each side at least kMinSideShare of the area; ties go
// to the offset nearest the area median. Every edge the line crosses is a
// welded pair the map loses: where the island narrows (a neck, a limb)
// the cut costs a fraction of a cut through its middle. -> side per
// triangle (by centroid); empty when the area is 0.
std::vector<uint8_t> cheapest_cut_sides(const std::vector<Vec2>& points, const std::vector<Vec2>& centroid,
                                        const std::vector<double>& area,
                                        const std::vector<std::array<uint32_t, 3>>& neighbour) {
  const size_t n = centroid.size();
  double total = 0;
  for (double a : area) total += a;
  if (!(total > 0)) return {};
  const atlas::MinRectangle rect = atlas::min_area_rectangle(points);
  const Vec2 axis = rect.size.x >= rect.size.y ? rect.axis : Vec2{-rect.axis.y, rect.axis.x};
  std::vector<double> at(n);
  for (size_t i = 0; i < n; ++i) at[i] = dot(centroid[i], axis);
  std::vector<uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return at[a] < at[b]; });
  // The projections where the area below reaches kMinSideShare, the median
  // and 1 - kMinSideShare.
  double lo = at[order.front()], median = lo, hi = at[order.back()], acc = 0;
  bool lo_set = false, median_set = false;
  for (uint32_t i : order) {
    acc += area[i];
    if (!lo_set && acc >= kMinSideShare * total) lo = at[i], lo_set = true;
    if (!median_set && acc >= 0.5 * total) median = at[i], median_set = true;
    if (acc <= (1 - kMinSideShare) * total) hi = at[i];
  }
  if (!(hi > lo)) hi = lo = median;
  // Edges crossed at each offset: an edge between projections p < q is
  // crossed by the offsets in [p, q).
  std::vector<double> offset(kCutOffsets);
  for (int k = 0; k < kCutOffsets; ++k) offset[k] = lo + (hi - lo) * (k + 0.5) / kCutOffsets;
  std::vector<int> crossed(kCutOffsets + 1, 0);
  for (size_t i = 0; i < n; ++i)
    for (uint32_t j : neighbour[i]) {
      if (j == UINT32_MAX || j < i) continue;
      const auto [p, q] = std::minmax(at[i], at[j]);
      const int first = int(std::lower_bound(offset.begin(), offset.end(), p) - offset.begin());
      const int last = int(std::lower_bound(offset.begin(), offset.end(), q) - offset.begin());
      ++crossed[first], --crossed[last];
    }
  double best = median;
  int best_count = INT32_MAX;
  for (int k = 0, running = 0; k < kCutOffsets; ++k) {
    running += crossed[k];
    if (running < best_count ||
        (running == best_count && std::abs(offset[k] - median) < std::abs(best - median)))
      best_count = running, best = offset[k];
  }
  std::vector<uint8_t> side(n);
  for (size_t i = 0; i < n; ++i) side[i] = at[i] >= best;
  return side;
}
}  // namespace

bool halve_island(UvLayout& L, uint32_t island) {
  std::vector<uint32_t> tris;
  for (size_t t = 0; t < L.island.size(); ++t)
    if (L.island[t] == island) tris.push_back(uint32_t(t));
  const size_t n = tris.size();
  if (n < 2) return false;
  std::vector<Vec2> points, centroid(n);
  std::vector<double> area(n);
  points.reserve(3 * n);
  for (size_t i = 0; i < n; ++i) {
    const auto& v = L.corner_vertex[tris[i]];
    for (uint32_t c : v) points.push_back(L.uv[c]);
    centroid[i] = (L.uv[v[0]] + L.uv[v[1]] + L.uv[v[2]]) * (1.0 / 3);
    area[i] = 0.5 * std::abs(signed_area2(L, tris[i]));
  }
  std::vector<std::array<uint32_t, 3>> local(n);
  for (size_t i = 0; i < n; ++i) local[i] = L.corner_vertex[tris[i]];
  std::vector<std::array<uint32_t, 3>> neighbour(n, {UINT32_MAX, UINT32_MAX, UINT32_MAX});
  {
    std::vector<std::pair<uint64_t, uint32_t>> edges;
    edges.reserve(3 * n);
    for (size_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k) {
        const auto [a, b] = std::minmax(local[i][k], local[i][(k + 1) % 3]);
        edges.push_back({(uint64_t(a) << 32) | b, uint32_t(3 * i + k)});
      }
    std::sort(edges.begin(), edges.end());
    for (size_t e = 0; e + 1 < edges.size(); ++e)
      if (edges[e].first == edges[e + 1].first && (e + 2 == edges.size() || edges[e + 2].first != edges[e].first)) {
        const uint32_t x = edges[e].second, y = edges[e + 1].second;
        neighbour[x / 3][x % 3] = y / 3;
        neighbour[y / 3][y % 3] = x / 3;
      }
  }
  std::vector<uint8_t> side = cheapest_cut_sides(points, centroid, area, neighbour);
  if (side.empty()) return false;

  // The line's cut through triangles by centroid zigzags across thin ones
  // (noisy soups' slivers): a triangle with two or three edge neighbours on
  // the other side goes there, which shortens the seam; a few passes.
  for (int pass = 0; pass < 4; ++pass) {
    bool moved = false;
    for (size_t i = 0; i < n; ++i) {
      int across = 0;
      for (uint32_t j : neighbour[i]) across += j != UINT32_MAX && side[j] != side[i];
      if (across >= 2) {
        side[i] = 1 - side[i];
        moved = true;
      }
    }
    if (!moved) break;
  }

  // Each side as one piece: a side's smaller pieces join the other side
  // (they touch the island only through it), twice, since a moved piece can
  // join two of the other side's pieces.
  std::vector<uint32_t> component;
  for (int pass = 0; pass < 2; ++pass)
    for (uint8_t s = 0; s < 2; ++s) {
      std::vector<uint8_t> active(n);
      for (size_t i = 0; i < n; ++i) active[i] = side[i] == s;
      const uint32_t pieces = edge_components(local, &active, component);
      if (pieces <= 1) continue;
      std::vector<double> piece_area(pieces, 0);
      for (size_t i = 0; i < n; ++i)
        if (active[i]) piece_area[component[i]] += area[i];
      const uint32_t keep = uint32_t(std::max_element(piece_area.begin(), piece_area.end()) - piece_area.begin());
      for (size_t i = 0; i < n; ++i)
        if (active[i] && component[i] != keep) side[i] = 1 - s;
    }
  for (uint8_t s = 0; s < 2; ++s) {
    std::vector<uint8_t> active(n);
    for (size_t i = 0; i < n; ++i) active[i] = side[i] == s;
    if (edge_components(local, &active, component) != 1) return false;
  }

  // Side 1 becomes a new island; its vertices shared with side 0 are copied.
  std::vector<uint8_t> on_side0(L.uv.size(), 0);
  for (size_t i = 0; i < n; ++i)
    if (side[i] == 0)
      for (uint32_t v : local[i]) on_side0[v] = 1;
  std::vector<uint32_t> copy(L.uv.size(), UINT32_MAX);
  const uint32_t fresh = L.island_count++;
  for (size_t i = 0; i < n; ++i) {
    if (side[i] == 0) continue;
    const uint32_t t = tris[i];
    L.island[t] = fresh;
    for (uint32_t& v : L.corner_vertex[t]) {
      if (!on_side0[v]) continue;
      if (copy[v] == UINT32_MAX) {
        copy[v] = uint32_t(L.uv.size());
        L.uv.push_back(L.uv[v]);
      }
      v = copy[v];
    }
  }
  return true;
}

std::vector<HalvingRound> halve_to_pack(const std::vector<geometry::AdjacentPair>& pairs,
                                        const HalvingOptions& options, double utilisation_target,
                                        int texture_size, double padding_px,
                                        int threads, UvLayout& layout,
                                        std::vector<std::array<Vec2, 3>>& corner_uvs, PackFigures& packed) {
  std::vector<HalvingRound> rounds;
  if (layout.island_count > options.max_islands) return rounds;
  UvLayout trial = layout;
  const double kept_before = kept_pair_share(pairs, layout);
  auto more = [&](int round) {
    return packed.utilisation < options.below &&
           (round < options.rounds || (round < options.rounds_below_target && packed.utilisation < utilisation_target));
  };
  for (int round = 0; more(round); ++round) {
    // Below both targets, the utilisation's may cost a little continuity:
    // max_cut_below_target of the pairs, in whole pairs rounded up (a soup
    // of a few dozen pairs could otherwise never cut one: BoxesMeta's soup
    // at seed 59, a cube unfolded as a bent strip, packed at 0.43; half a
    // pair more absorbs the shares' rounding).
    const double pair_count = double(std::max<size_t>(1, pairs.size()));
    const double allowance = (std::ceil(options.max_cut_below_target * pair_count) + 0.5) / pair_count;
    const double min_kept = kept_before < options.min_kept_pairs && packed.utilisation < utilisation_target
                                ? kept_before - allowance
                                : options.min_kept_pairs;
    const auto islands = island_triangles(trial);
    std::vector<double> area(islands.size(), 0);
    for (size_t i = 0; i < islands.size(); ++i)
      for (uint32_t t : islands[i]) area[i] += 0.5 * std::abs(signed_area2(trial, t));
    const double largest = *std::max_element(area.begin(), area.end());
    HalvingRound h;
    const UvLayout before_round = trial;
    for (size_t i = 0; i < islands.size(); ++i)
      if (area[i] >= 0.5 * largest) h.halved += halve_island(trial, uint32_t(i));
    h.kept_pairs = kept_pair_share(pairs, trial);
    // Halving all of them cuts too many pairs: the one whose halving cuts
    // the fewest alone may not.
    if (h.halved > 1 && h.kept_pairs < min_kept) {
      UvLayout best;
      h.halved = 0;
      h.kept_pairs = 0;
      for (size_t i = 0; i < islands.size(); ++i) {
        if (area[i] < 0.5 * largest) continue;
        UvLayout one = before_round;
        if (!halve_island(one, uint32_t(i))) continue;
        const double kept = kept_pair_share(pairs, one);
        if (kept > h.kept_pairs) h.kept_pairs = kept, h.halved = 1, best = std::move(one);
      }
      trial = h.halved ? std::move(best) : before_round;
    }
    if (h.halved == 0 || h.kept_pairs < min_kept) {
      rounds.push_back(h);
      break;
    }
    std::vector<std::array<Vec2, 3>> uvs;
    const PackFigures tried = pack_islands(trial, texture_size, padding_px, threads, uvs);
    h.packed = true;
    h.utilisation = tried.utilisation;
    h.kept = tried.utilisation > packed.utilisation;
    rounds.push_back(h);
    if (!h.kept) break;
    packed = tried;
    corner_uvs = std::move(uvs);
    layout = trial;
  }
  return rounds;
}

}  // namespace soupuv::uvsolve::detail
