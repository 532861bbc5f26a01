// The gap-keeping proxy (keep_gaps, gap_offsets.h) against slow twins and
// known shapes: shifted BVH distances against brute force, the per-triangle
// gaps against an all-pairs computation, and two parts closer than 2o that
// the plain offset surface fuses but keep_gaps keeps apart.
#include <gtest/gtest.h>

#include <cmath>
#include <queue>
#include <random>

#include "proxy_expect.h"
#include "soupuv/proxy/gap_offsets.h"
#include "soupuv/proxy/proxy.h"
#include "soupuv/proxy/triangle_bvh.h"
#include "testing/shapes.h"

namespace soupuv::proxy {
namespace {

Soup two_cubes(double gap, double noise) {
  TriMesh a = shapes::cube(1.0, 4), b = shapes::cube(1.0, 4);
  shapes::translate(b, {1.0 + gap, 0, 0});
  return shapes::merge(shapes::to_soup(a, noise, 3), shapes::to_soup(b, noise, 4));
}

TEST(GapOffsets, TriangleTriangleDistanceKnownValues) {
  std::array<Vec3, 3> a{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};
  std::array<Vec3, 3> above{{{0, 0, 2}, {1, 0, 2}, {0, 1, 2}}};
  EXPECT_NEAR(triangle_triangle_distance(a, above), 2.0, 1e-15);
  // Edge against edge, skew: the closest points are inside both edges.
  std::array<Vec3, 3> skew{{{0.5, -1, 1}, {0.5, -3, 1}, {0.5, -1, 3}}};
  std::array<Vec3, 3> flat{{{0, -0.5, 0}, {1, -0.5, 0}, {0.5, 5, -4}}};
  EXPECT_NEAR(triangle_triangle_distance(skew, flat), triangle_triangle_distance(flat, skew), 1e-15);
  // Brute force over points of both triangles never beats it.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  double sampled = INFINITY;
  for (int i = 0; i < 20000; ++i) {
    double s = u(rng), t = u(rng);
    if (s + t > 1) s = 1 - s, t = 1 - t;
    Vec3 p = skew[0] + s * (skew[1] - skew[0]) + t * (skew[2] - skew[0]);
    sampled = std::min(sampled, point_triangle_distance(p, flat[0], flat[1], flat[2]));
  }
  EXPECT_LE(triangle_triangle_distance(skew, flat), sampled + 1e-12);
  EXPECT_NEAR(triangle_triangle_distance(skew, flat), sampled, 1e-2);
}

TEST(GapOffsets, ShiftedBvhMatchesBruteForce) {
  Soup soup = shapes::to_soup(shapes::torus(1.0, 0.3, 24, 12), 0.01, 3);
  TriangleBvh bvh(soup);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.6, 1.6), s(0, 0.2);
  std::vector<double> shift(bvh.size());
  for (double& x : shift) x = u(rng) > 0 ? s(rng) : 0.0;
  bvh.set_shifts(shift);
  auto brute = [&](Vec3 p) {
    double best = INFINITY;
    for (uint32_t t = 0; t < bvh.size(); ++t) {
      const auto& tri = bvh.triangle(t);
      best = std::min(best, point_triangle_distance(p, tri[0], tri[1], tri[2]) + shift[t]);
    }
    return best;
  };
  CandidateList list;
  for (int i = 0; i < 300; ++i) {
    Vec3 p{u(rng), u(rng), u(rng) * 0.5};
    const double exact = brute(p);
    EXPECT_NEAR(bvh.distance(p), exact, 1e-12);
    // The candidate-list path: a small box around p, gathered with the
    // radius the narrow band uses (distance at the center + half-diagonal).
    Box3 box;
    box.add(p - Vec3{0.05, 0.05, 0.05});
    box.add(p + Vec3{0.05, 0.05, 0.05});
    bvh.gather(box, bvh.distance(box.center()) + 0.05 * std::sqrt(3.0) + 1e-9, list);
    EXPECT_NEAR(bvh.distance_among(p, list), exact, 1e-12);
  }
}

// Slow twin: adjacency by comparing every pair of corners, walks by a full
// Dijkstra from every triangle, gaps by every pair of triangles.
std::vector<double> brute_shifts(const TriangleBvh& bvh, const GapOffsetOptions& o) {
  const size_t n = bvh.size();
  std::vector<Vec3> c(n);
  std::vector<double> r(n);
  for (uint32_t t = 0; t < n; ++t) {
    const auto& tri = bvh.triangle(t);
    c[t] = (tri[0] + tri[1] + tri[2]) / 3.0;
    r[t] = std::max({norm(tri[0] - c[t]), norm(tri[1] - c[t]), norm(tri[2] - c[t])});
  }
  std::vector<std::vector<uint32_t>> adj(n);
  for (uint32_t a = 0; a < n; ++a)
    for (uint32_t b = 0; b < n; ++b) {
      if (a == b) continue;
      bool touch = false;
      for (const Vec3& p : bvh.triangle(a))
        for (const Vec3& q : bvh.triangle(b)) touch |= norm(p - q) <= o.weld_tolerance;
      if (touch) adj[a].push_back(b);
    }
  std::vector<double> shift(n, 0.0);
  for (uint32_t t = 0; t < n; ++t) {
    std::vector<double> walk(n, INFINITY);
    using Item = std::pair<double, uint32_t>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> q;
    walk[t] = 0;
    q.push({0, t});
    while (!q.empty()) {
      auto [d, u] = q.top();
      q.pop();
      if (d > walk[u]) continue;
      for (uint32_t v : adj[u])
        if (d + norm(c[v] - c[u]) < walk[v]) q.push({walk[v] = d + norm(c[v] - c[u]), v});
    }
    double gap = INFINITY;
    for (uint32_t u = 0; u < n; ++u) {
      if (u == t) continue;
      const double d = triangle_triangle_distance(bvh.triangle(t), bvh.triangle(u));
      if (walk[u] > o.detour * d + r[t] + r[u]) gap = std::min(gap, d);
    }
    if (gap < 2 * (o.offset + o.margin))
      shift[t] = o.offset - std::clamp(0.5 * gap - o.margin, o.min_offset, o.offset);
  }
  return shift;
}

TEST(GapOffsets, MatchTheAllPairsTwin) {
  // Two cubes side by side, and a sphere beside a cube.
  TriMesh ball = shapes::icosphere(0.5, 2), box = shapes::cube(1.0, 3);
  shapes::translate(box, {1.2, 0, 0});
  Soup mixed = shapes::merge(shapes::to_soup(ball, 0.002, 8), shapes::to_soup(box, 0.002, 9));
  for (const Soup& soup : {two_cubes(0.3, 0.002), mixed}) {
    TriangleBvh bvh(soup);
    GapOffsetOptions o;
    o.offset = 0.35;
    o.min_offset = 0.05;
    o.margin = 0.04;
    o.weld_tolerance = 0.03;  // above the noise: copies lie up to 2 * 0.002 * sqrt(3) * diagonal apart
    GapOffsets fast = gap_offsets(bvh, o);
    std::vector<double> slow = brute_shifts(bvh, o);
    ASSERT_EQ(fast.shift.size(), slow.size());
    size_t narrowed = 0;
    for (size_t t = 0; t < slow.size(); ++t) {
      EXPECT_NEAR(fast.shift[t], slow[t], 1e-12) << t;
      narrowed += slow[t] > 0;
    }
    EXPECT_EQ(fast.narrowed, narrowed);
    EXPECT_GT(narrowed, 0u);  // both shapes have gaps below 2o
  }
}

TEST(GapOffsets, ConvexAndWideShapesHaveNoGaps) {
  GapOffsetOptions o;
  o.offset = 0.2;
  o.min_offset = 0.05;
  o.margin = 0.04;
  o.weld_tolerance = 0.03;  // above the noise: copies lie up to 2 * 0.002 * sqrt(3) * diagonal apart
  // A noisy cube and a torus whose hole (1.4 across) is wider than 2o.
  for (const Soup& soup : {shapes::to_soup(shapes::cube(1.0, 4), 0.002, 1),
                           shapes::to_soup(shapes::torus(1.0, 0.3, 24, 12), 0.002, 2)}) {
    TriangleBvh bvh(soup);
    EXPECT_EQ(gap_offsets(bvh, o).narrowed, 0u);
  }
}

TEST(GapOffsets, KeepGapsKeepsTwoCloseCubesApart) {
  // Gap 0.3 < 2o = 0.5: the plain offset surface fuses the cubes into one
  // shell; with keep_gaps each cube keeps its own, and every proxy check
  // holds (min distance measured to the local shells).
  Soup soup = two_cubes(0.3, 0.002);
  ProxyOptions o;
  o.offset_mode = OffsetMode::absolute;
  o.offset = 0.25;
  ProxyResult fused = build_proxy(soup, o);
  expect_valid_proxy(fused, soup, 1);
  EXPECT_EQ(fused.gap_narrowed_triangles, 0u);
  o.keep_gaps = true;
  ProxyResult kept = build_proxy(soup, o);
  expect_valid_proxy(kept, soup, 2);
  EXPECT_GT(kept.gap_narrowed_triangles, 0u);
  EXPECT_LT(kept.gap_smallest_offset, 0.15);
  EXPECT_EQ(kept.genus, 0);
  // The slit: no proxy vertex lies in the middle of the gap.
  for (const Vec3& v : kept.proxy.mesh.vertices)
    EXPECT_FALSE(std::abs(v.x - 0.65) < 0.02 && std::abs(v.y) < 0.3 && std::abs(v.z) < 0.3);
}

}  // namespace
}  // namespace soupuv::proxy
