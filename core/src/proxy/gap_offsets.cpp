// Per-triangle offsets that keep gaps between far-apart parts open. See
// soupuv/proxy/gap_offsets.h.
#include "soupuv/proxy/gap_offsets.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <queue>
#include <unordered_map>

#include "soupuv/errors.h"

namespace soupuv::proxy {
namespace {

// Closest distance between segments [p1, q1] and [p2, q2] (clamped
// parameters; the parallel case falls back to the end points).
double segment_segment_distance(Vec3 p1, Vec3 q1, Vec3 p2, Vec3 q2) {
  const Vec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r);
  double s = 0, t = 0;
  if (a <= 0 && e <= 0) return norm(r);
  if (a <= 0) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = dot(d1, r);
    if (e <= 0) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = dot(d1, d2), denom = a * e - b * b;
      s = denom > 1e-14 * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      // t outside [0, 1]: clamp it and recompute s for the clamped t.
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return norm((p1 + s * d1) - (p2 + t * d2));
}

// Union-find over soup corners, for the weld.
struct UnionFind {
  std::vector<uint32_t> parent;
  explicit UnionFind(size_t n) : parent(n) {
    for (size_t i = 0; i < n; ++i) parent[i] = uint32_t(i);
  }
  uint32_t find(uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(uint32_t a, uint32_t b) { parent[find(a)] = find(b); }
};

// Triangles that touch (share a corner up to the weld tolerance), as CSR
// lists. Corners are bucketed on a grid of the tolerance, so each corner
// compares with the 27 buckets around it only.
void touching_triangles(const TriangleBvh& bvh, double tolerance, std::vector<uint32_t>& start,
                        std::vector<uint32_t>& list) {
  const size_t n = bvh.size();
  UnionFind weld(3 * n);
  const double cell = tolerance > 0 ? tolerance : 1e-300;
  auto bucket = [&](Vec3 p) {
    return std::array<int64_t, 3>{int64_t(std::floor(p.x / cell)), int64_t(std::floor(p.y / cell)),
                                  int64_t(std::floor(p.z / cell))};
  };
  auto key = [](const std::array<int64_t, 3>& b) {
    return uint64_t(b[0]) * 0x9E3779B97F4A7C15ull ^ uint64_t(b[1]) * 0xC2B2AE3D27D4EB4Full ^
           uint64_t(b[2]) * 0x165667B19E3779F9ull;
  };
  std::unordered_map<uint64_t, std::vector<uint32_t>> buckets;
  for (uint32_t c = 0; c < 3 * n; ++c) buckets[key(bucket(bvh.triangle(c / 3)[c % 3]))].push_back(c);
  for (uint32_t c = 0; c < 3 * n; ++c) {
    const Vec3 p = bvh.triangle(c / 3)[c % 3];
    const auto b = bucket(p);
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          auto it = buckets.find(key({b[0] + dx, b[1] + dy, b[2] + dz}));
          if (it == buckets.end()) continue;
          for (uint32_t other : it->second)
            if (other < c && norm(bvh.triangle(other / 3)[other % 3] - p) <= tolerance) weld.unite(c, other);
        }
  }
  // Triangles per welded vertex, then each triangle's neighbours through its corners.
  std::unordered_map<uint32_t, std::vector<uint32_t>> around;
  for (uint32_t c = 0; c < 3 * n; ++c) around[weld.find(c)].push_back(c / 3);
  std::vector<std::vector<uint32_t>> adjacent(n);
  for (auto& [vertex, tris] : around) {
    std::sort(tris.begin(), tris.end());
    tris.erase(std::unique(tris.begin(), tris.end()), tris.end());
    for (uint32_t a : tris)
      for (uint32_t b : tris)
        if (a != b) adjacent[a].push_back(b);
  }
  start.assign(n + 1, 0);
  list.clear();
  for (size_t t = 0; t < n; ++t) {
    std::sort(adjacent[t].begin(), adjacent[t].end());
    adjacent[t].erase(std::unique(adjacent[t].begin(), adjacent[t].end()), adjacent[t].end());
    list.insert(list.end(), adjacent[t].begin(), adjacent[t].end());
    start[t + 1] = uint32_t(list.size());
  }
}

}  // namespace

double triangle_triangle_distance(const std::array<Vec3, 3>& a, const std::array<Vec3, 3>& b) {
  double best = INFINITY;
  for (int i = 0; i < 3; ++i) {
    best = std::min(best, point_triangle_distance(a[i], b[0], b[1], b[2]));
    best = std::min(best, point_triangle_distance(b[i], a[0], a[1], a[2]));
    for (int j = 0; j < 3; ++j)
      best = std::min(best, segment_segment_distance(a[i], a[(i + 1) % 3], b[j], b[(j + 1) % 3]));
  }
  return best;
}

GapOffsets gap_offsets(const TriangleBvh& bvh, const GapOffsetOptions& options) {
  const double o = options.offset;
  if (!(o > 0) || !(options.min_offset > 0) || options.min_offset > o || !(options.margin >= 0) ||
      !(options.detour >= 1))
    throw Error(ErrorCode::invalid_input, "gap offsets: need 0 < min_offset <= offset, margin >= 0, detour >= 1");
  const size_t n = bvh.size();
  GapOffsets result;
  result.shift.assign(n, 0.0);
  result.smallest_offset = o;
  if (n == 0) return result;

  std::vector<uint32_t> start, adjacent;
  touching_triangles(bvh, options.weld_tolerance, start, adjacent);
  std::vector<Vec3> centroid(n);
  std::vector<double> radius(n);  // largest centroid-corner distance
  for (uint32_t t = 0; t < n; ++t) {
    const auto& tri = bvh.triangle(t);
    centroid[t] = (tri[0] + tri[1] + tri[2]) / 3.0;
    radius[t] = std::max({norm(tri[0] - centroid[t]), norm(tri[1] - centroid[t]), norm(tri[2] - centroid[t])});
  }
  // Only gaps below 2 (o + m) narrow an offset: a far triangle must be
  // closer than that.
  const double gap_limit = 2 * (o + options.margin);

  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
#pragma omp parallel num_threads(threads)
  {
    // Walk distances by triangle, reset after each walk through `touched`.
    std::vector<double> walk(n, INFINITY);
    std::vector<char> settled(n, 0);
    std::vector<uint32_t> touched;
    CandidateList near;
    std::vector<std::pair<double, uint32_t>> candidates;  // (distance, triangle)
    using Item = std::pair<double, uint32_t>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
#pragma omp for schedule(dynamic, 16)
    for (long ti = 0; ti < long(n); ++ti) {
      const uint32_t t = uint32_t(ti);
      // The triangles within gap_limit in space, nearest first: the first
      // one that is far along the soup gives the gap.
      Box3 box;
      for (const Vec3& p : bvh.triangle(t)) box.add(p);
      bvh.gather(box, gap_limit, near);
      candidates.clear();
      for (size_t k = 0; k < near.size(); ++k) {
        const uint32_t u = near.ids[k];
        if (u == t) continue;
        const double d = triangle_triangle_distance(bvh.triangle(t), bvh.triangle(u));
        if (d < gap_limit) candidates.push_back({d, u});
      }
      std::sort(candidates.begin(), candidates.end());
      // Dijkstra over touching triangles (centroid to centroid), run only as
      // far as the candidate at hand needs: it stops once the candidate is
      // settled (its walk is exact) or the next walk exceeds the bound (then
      // the candidate's walk does too). On a smooth patch the walk to a near
      // candidate is about its distance, so the search stays within about
      // gap_limit instead of detour * gap_limit.
      walk[t] = 0;
      touched.push_back(t);
      queue.push({0.0, t});
      auto extend = [&](double bound, uint32_t target) {
        while (!settled[target] && !queue.empty() && queue.top().first <= bound) {
          auto [d, u] = queue.top();
          queue.pop();
          if (d > walk[u]) continue;
          settled[u] = 1;
          for (uint32_t e = start[u]; e < start[u + 1]; ++e) {
            const uint32_t v = adjacent[e];
            const double dv = d + norm(centroid[v] - centroid[u]);
            if (dv < walk[v]) {
              if (walk[v] == INFINITY) touched.push_back(v);
              walk[v] = dv;
              queue.push({dv, v});
            }
          }
        }
      };
      double gap = INFINITY;
      for (const auto& [d, u] : candidates) {
        const double bound = options.detour * d + radius[t] + radius[u];
        extend(bound, u);
        if (!(settled[u] && walk[u] <= bound)) {
          gap = d;
          break;
        }
      }
      while (!queue.empty()) queue.pop();
      if (gap < gap_limit) {
        const double local = std::clamp(0.5 * gap - options.margin, options.min_offset, o);
        result.shift[t] = o - local;
      }
      for (uint32_t v : touched) walk[v] = INFINITY, settled[v] = 0;
      touched.clear();
    }
  }
  for (double s : result.shift)
    if (s > 0) {
      ++result.narrowed;
      result.smallest_offset = std::min(result.smallest_offset, o - s);
    }
  return result;
}

}  // namespace soupuv::proxy
