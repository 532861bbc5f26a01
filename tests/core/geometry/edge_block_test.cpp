// The edge weld's batched candidate search (geometry/edge_block.h and
// CornerGrid::for_each_near_cell): against direct computations in double.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

#include "geometry/corner_grid.h"
#include "geometry/edge_block.h"

using namespace soupuv;
using namespace soupuv::geometry;

namespace {

// A soup of random small triangles in the unit cube.
Soup random_soup(size_t triangles, double size, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1), d(-size, size);
  Soup s;
  for (size_t t = 0; t < triangles; ++t) {
    const Vec3 c{u(rng), u(rng), u(rng)};
    const uint32_t v = uint32_t(s.positions.size());
    for (int k = 0; k < 3; ++k) s.positions.push_back(c + Vec3{d(rng), d(rng), d(rng)});
    s.triangles.push_back({v, v + 1, v + 2});
  }
  return s;
}

}  // namespace

// Every corner within the reach of any point of a cell is visited by that
// cell's block query, whatever the cell size against the reach.
TEST(CornerGridCell, VisitsEveryCornerWithinReachOfTheCell) {
  const Soup s = random_soup(3000, 0.02, 1);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(0, 1);
  for (const double ratio : {1.0 + 1e-6, 0.5, 1.7}) {
    const double reach = 0.03;
    const CornerGrid grid(s, bounding_box(s), reach * ratio, reach, /*with_next=*/true);
    for (int trial = 0; trial < 200; ++trial) {
      const Vec3 p{u(rng), u(rng), u(rng)};
      std::set<uint32_t> seen;
      size_t cells = 0;
      grid.for_each_near_cell(
          p, [&](const Vec3& lo, const Vec3& hi) {
            ++cells;
            EXPECT_LT(lo.x, hi.x);
          },
          [&](uint32_t c, const Vec3& at, const Vec3&) {
            EXPECT_EQ(at.x, s.corner(c / 3, c % 3).x);
            seen.insert(c);
          });
      for (uint32_t c = 0; c < 3 * s.triangles.size(); ++c) {
        if (norm(s.corner(c / 3, c % 3) - p) <= reach) {
          EXPECT_TRUE(seen.count(c)) << "ratio " << ratio;
        }
      }
      if (ratio > 1) {
        EXPECT_LE(cells, 27u);
      }
    }
  }
}

// near_both returns the block corners near both ends of a query edge (up to
// float rounding), above min_corner, and cheaper than the cost bound.
TEST(EdgeBlock, NearBothMatchesADirectTestInDouble) {
  const Soup s = random_soup(4000, 0.02, 3);
  const size_t corners = 3 * s.triangles.size();
  auto pos = [&](uint32_t c) { return s.corner(c / 3, c % 3); };
  auto next = [](uint32_t c) { return c - c % 3 + (c % 3 + 1) % 3; };
  auto prev = [](uint32_t c) { return c - c % 3 + (c % 3 + 2) % 3; };
  const double r = 0.05;
  std::mt19937 rng(4);
  std::uniform_int_distribution<uint32_t> pick(0, uint32_t(corners - 1));
  std::uniform_real_distribution<float> u(0, 1);
  std::vector<float> bound_of(corners);
  for (float& b : bound_of) b = u(rng) < 0.3f ? INFINITY : float(r * r) * u(rng);
  for (const bool with_prev : {false, true})
    for (const bool bounded : {false, true})
      for (int trial = 0; trial < 100; ++trial) {
        const uint32_t e = pick(rng);
        const Vec3 p = pos(e), q = pos(next(e)), o = q + Vec3{0.01, -0.01, 0.005};
        detail::EdgeBlock block;
        block.clear(with_prev);
        // Two runs: every corner, split at the median x (boxes from their corners).
        std::vector<uint32_t> order(corners);
        for (uint32_t c = 0; c < corners; ++c) order[c] = c;
        std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return pos(a).x < pos(b).x; });
        for (int half = 0; half < 2; ++half) {
          const size_t a = half * corners / 2, b = (half + 1) * corners / 2;
          Vec3 lo{1e9, 1e9, 1e9}, hi{-1e9, -1e9, -1e9};
          for (size_t i = a; i < b; ++i) {
            const Vec3 x = pos(order[i]);
            lo = {std::min(lo.x, x.x), std::min(lo.y, x.y), std::min(lo.z, x.z)};
            hi = {std::max(hi.x, x.x), std::max(hi.y, x.y), std::max(hi.z, x.z)};
          }
          block.begin_run(lo - o, hi - o);
          for (size_t i = a; i < b; ++i)
            block.add(order[i], pos(order[i]) - o, pos(next(order[i])) - o, pos(prev(order[i])) - o);
        }
        block.seal();
        const Vec3 qo = q - o, po = p - o;
        const float qf[3] = {float(qo.x), float(qo.y), float(qo.z)}, pf[3] = {float(po.x), float(po.y), float(po.z)};
        const uint32_t min_corner = e / 2;
        const detail::CostBound bound{bound_of.data(), bound_of[e], 0.0f};
        std::vector<uint32_t> hits;
        block.near_both(qf, pf, float(r * r), with_prev, min_corner, bounded ? &bound : nullptr, hits);
        std::set<uint32_t> got;
        for (uint32_t h : hits) got.insert(block.corner(h));
        EXPECT_EQ(got.size(), hits.size());
        for (uint32_t c = 0; c < corners; ++c) {
          const double dq = norm2(pos(c) - q), dn = norm2(pos(next(c)) - p), dv = norm2(pos(prev(c)) - p);
          const double dp = with_prev ? std::min(dn, dv) : dn;
          const double cost = dq + dn;
          const double cheapest = std::max<double>(bound_of[e], bound_of[c]);
          // Clear of the float rounding either way.
          const bool in = c >= min_corner && dq < 0.999 * r * r && dp < 0.999 * r * r &&
                          (!bounded || with_prev || cost < 0.999 * cheapest);
          const bool out = c < min_corner || dq > 1.001 * r * r || dp > 1.001 * r * r ||
                           (bounded && !with_prev && dn <= 1.001 * r * r && cost > 1.001 * cheapest);
          if (in) {
            EXPECT_TRUE(got.count(c)) << "corner " << c;
          }
          if (out) {
            EXPECT_FALSE(got.count(c)) << "corner " << c;
          }
        }
      }
}
