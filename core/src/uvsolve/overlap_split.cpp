#include "uvsolve/overlap_split.h"

#include <algorithm>
#include <cmath>
#include <deque>

#include "soupuv/quality/uv_overlap.h"

namespace soupuv::uvsolve::detail {
namespace {

// Calls f(index) for every sample point of the grid (origin, cell, width)
// inside the counter-clockwise triangle p (quality::for_each_pixel_centre's
// rule: two triangles side by side never share a sample).
template <class F>
void for_each_sample(const std::array<Vec2, 3>& p, Vec2 origin, double cell, int width, int height, F&& f) {
  std::array<Vec2, 3> q;
  for (int k = 0; k < 3; ++k) q[k] = (1.0 / cell) * (p[k] - origin);
  quality::for_each_pixel_centre(q, width, height, [&](int i, int j) { f(size_t(j) * width + i); });
}

// A triangle overlapping by at most this many samples may stay, while the
// island's laps stay under kLapShare of its samples (the overlap target is
// 1 % of the covered area).
constexpr size_t kLapSamples = 2;

}  // namespace

size_t overlap_samples(const std::vector<std::array<Vec2, 3>>& triangles, double cell) {
  if (triangles.empty()) return 0;
  Vec2 lo{INFINITY, INFINITY}, hi{-INFINITY, -INFINITY};
  for (const auto& p : triangles)
    for (const Vec2& q : p) {
      lo = {std::min(lo.x, q.x), std::min(lo.y, q.y)};
      hi = {std::max(hi.x, q.x), std::max(hi.y, q.y)};
    }
  double h = cell;
  const double cells = (hi.x - lo.x) * (hi.y - lo.y) / (h * h);
  if (cells > double(1 << 24)) h *= std::sqrt(cells / double(1 << 24));
  const int width = int(std::ceil((hi.x - lo.x) / h)) + 1, height = int(std::ceil((hi.y - lo.y) / h)) + 1;
  std::vector<uint8_t> taken(size_t(width) * height, 0);
  size_t clashes = 0;
  for (const auto& p : triangles)
    for_each_sample(p, lo, h, width, height, [&](size_t s) {
      clashes += taken[s];
      taken[s] = 1;
    });
  return clashes;
}

size_t overlap_samples(const UvLayout& L, const std::vector<uint32_t>& tris, double cell) {
  std::vector<std::array<Vec2, 3>> triangles(tris.size());
  for (size_t i = 0; i < tris.size(); ++i) {
    const auto& cv = L.corner_vertex[tris[i]];
    triangles[i] = {L.uv[cv[0]], L.uv[cv[1]], L.uv[cv[2]]};
  }
  return overlap_samples(triangles, cell);
}

OverlapSplitFigures split_overlaps(double cell, int threads, UvLayout& L) {
  OverlapSplitFigures f;
  f.cell = cell;
  const auto islands = island_triangles(L);
  std::vector<std::vector<std::vector<uint32_t>>> pieces_of(islands.size());
  size_t overlapping = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(std::max(1, threads)) reduction(+ : overlapping)
  for (size_t isl = 0; isl < islands.size(); ++isl) {
    const auto& tris = islands[isl];
    if (tris.size() < 2) continue;
    Vec2 lo{INFINITY, INFINITY}, hi{-INFINITY, -INFINITY}, centroid{0, 0};
    double area = 0;
    for (uint32_t t : tris) {
      Vec2 c{0, 0};
      for (uint32_t v : L.corner_vertex[t]) {
        const Vec2 p = L.uv[v];
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
        c = c + (1.0 / 3) * p;
      }
      const double a = std::abs(0.5 * signed_area2(L, t));
      centroid = centroid + a * c;
      area += a;
    }
    if (area > 0) centroid = (1.0 / area) * centroid;
    // The grid: `cell` unless the island would need more than 2^24 samples.
    double h = cell;
    const double cells = (hi.x - lo.x) * (hi.y - lo.y) / (h * h);
    if (cells > double(1 << 24)) h *= std::sqrt(cells / double(1 << 24));
    const int width = int(std::ceil((hi.x - lo.x) / h)) + 1, height = int(std::ceil((hi.y - lo.y) / h)) + 1;
    std::vector<uint8_t> taken(size_t(width) * height, 0);
    // Edge neighbours inside the island (by shared vertices).
    std::vector<std::pair<uint64_t, uint32_t>> uses;
    for (uint32_t i = 0; i < tris.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        uint32_t a = L.corner_vertex[tris[i]][k], b = L.corner_vertex[tris[i]][(k + 1) % 3];
        if (a > b) std::swap(a, b);
        uses.push_back({(uint64_t(a) << 32) | b, i});
      }
    std::sort(uses.begin(), uses.end());
    std::vector<std::vector<uint32_t>> nb(tris.size());
    for (size_t i = 1; i < uses.size(); ++i)
      if (uses[i].first == uses[i - 1].first) {
        nb[uses[i].second].push_back(uses[i - 1].second);
        nb[uses[i - 1].second].push_back(uses[i].second);
      }
    auto late = [&](uint32_t i) { return L.unfolded.empty() ? 0 : int(L.unfolded[tris[i]]); };
    auto corners = [&](uint32_t i) {
      const auto& cv = L.corner_vertex[tris[i]];
      return std::array<Vec2, 3>{L.uv[cv[0]], L.uv[cv[1]], L.uv[cv[2]]};
    };
    // Seed: the triangle whose centroid is nearest the island's.
    uint32_t seed = 0;
    double best = INFINITY;
    for (uint32_t i = 0; i < tris.size(); ++i) {
      const auto p = corners(i);
      const double d = norm((1.0 / 3) * (p[0] + p[1] + p[2]) - centroid);
      if (d < best) best = d, seed = i;
    }
    // The lap budget: this share of the island's samples.
    const double lap_budget = kLapShare * area / (h * h);
    double lap_used = 0;
    std::vector<int> piece(tris.size(), -1);
    std::vector<size_t> mine, written;
    int pieces = 0;
    size_t assigned = 0, next_seed = 0;
    while (assigned < tris.size()) {
      if (pieces > 0) {
        for (size_t s : written) taken[s] = 0;
        while (piece[next_seed] >= 0) ++next_seed;
        seed = uint32_t(next_seed);
      }
      written.clear();
      std::vector<uint8_t> tried(tris.size(), 0);
      // Two queues: triangles the transfer placed go first, those the fold
      // cut unfolded only take what space is left.
      std::deque<uint32_t> queue[2];
      queue[late(seed)].push_back(seed);
      tried[seed] = 1;
      bool first = true;
      while (!queue[0].empty() || !queue[1].empty()) {
        std::deque<uint32_t>& q = queue[0].empty() ? queue[1] : queue[0];
        const uint32_t i = q.front();
        q.pop_front();
        mine.clear();
        size_t clashes = 0;
        for_each_sample(corners(i), lo, h, width, height, [&](size_t s) {
          if (taken[s]) ++clashes;
          mine.push_back(s);
        });
        // A lap of a sample or two (a noisy scan's sliver folds) is let
        // through within a small budget: splitting there would cut the
        // triangle off as a piece of its own for a speck of overlap.
        const bool tolerated = clashes <= kLapSamples && lap_used + clashes <= lap_budget;
        if (clashes > 0 && !tolerated && !first) continue;  // the seed always starts its piece
        lap_used += clashes;
        first = false;
        for (size_t s : mine) taken[s] = 1;
        written.insert(written.end(), mine.begin(), mine.end());
        piece[i] = pieces;
        ++assigned;
        for (uint32_t j : nb[i])
          if (!tried[j] && piece[j] < 0) {
            tried[j] = 1;
            queue[late(j)].push_back(j);
          }
      }
      ++pieces;
    }
    if (pieces > 1) {
      ++overlapping;
      pieces_of[isl].resize(pieces);
      for (uint32_t i = 0; i < tris.size(); ++i) pieces_of[isl][piece[i]].push_back(tris[i]);
    }
  }
  f.overlapping_islands = overlapping;
  for (auto& list : pieces_of)
    for (size_t p = 0; p < list.size(); ++p) {
      if (list[p].size() == 1) {
        ++f.singleton_pieces;
        if (!L.unfolded.empty() && L.unfolded[list[p][0]]) ++f.unfolded_singletons;
      }
      if (p == 0) continue;
      for (uint32_t t : list[p]) L.island[t] = L.island_count;
      ++L.island_count;
      ++f.pieces_added;
    }
  if (f.pieces_added) split_vertices_by_island(L);
  return f;
}

}  // namespace soupuv::uvsolve::detail
