// Triangles of a UV layout found by place, and exact tests of how two
// triangles overlap (private to the UV solve; attach_islands.h and
// seam_smooth.h move triangles onto an island and must know what they lap).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "soupuv/vec.h"
#include "uvsolve/uv_layout.h"

namespace soupuv::uvsolve::detail {

using Corners = std::array<Vec2, 3>;

// A triangle whose box spans more grid cells than this is listed with its
// island's large triangles instead (CAD soups mix huge and tiny triangles).
constexpr int64_t kMaxCellsPerTriangle = 64;

// Whether two triangles' interiors overlap: no edge normal of either
// separates them. Triangles that only touch (a shared edge or corner) are
// separated up to a tolerance of 1e-7 of the edge tested.
inline bool interiors_overlap(const Corners& p, const Corners& q) {
  auto separated_by_an_edge_of = [](const Corners& a, const Corners& b) {
    for (int k = 0; k < 3; ++k) {
      const Vec2 e = a[(k + 1) % 3] - a[k];
      const double len = std::sqrt(dot(e, e));
      if (!(len > 0)) continue;
      const Vec2 axis{-e.y / len, e.x / len};
      double a_lo = INFINITY, a_hi = -INFINITY, b_lo = INFINITY, b_hi = -INFINITY;
      for (int c = 0; c < 3; ++c) {
        const double x = dot(axis, a[c]), y = dot(axis, b[c]);
        a_lo = std::min(a_lo, x), a_hi = std::max(a_hi, x);
        b_lo = std::min(b_lo, y), b_hi = std::max(b_hi, y);
      }
      const double tol = 1e-7 * len;
      if (a_hi <= b_lo + tol || b_hi <= a_lo + tol) return true;
    }
    return false;
  };
  return !separated_by_an_edge_of(p, q) && !separated_by_an_edge_of(q, p);
}

// Area of the intersection of two triangles (either orientation): the
// first clipped by the second's three edges (Sutherland-Hodgman).
inline double overlap_area(Corners p, Corners q) {
  auto ccw = [](Corners& c) {
    if (cross(c[1] - c[0], c[2] - c[0]) < 0) std::swap(c[1], c[2]);
  };
  ccw(p), ccw(q);
  Vec2 poly[9], next[9];
  int m = 3;
  for (int c = 0; c < 3; ++c) poly[c] = p[c];
  for (int k = 0; k < 3 && m > 0; ++k) {
    const Vec2 a = q[k], e = q[(k + 1) % 3] - q[k];
    auto side = [&](Vec2 x) { return cross(e, x - a); };
    int o = 0;
    for (int i = 0; i < m; ++i) {
      const Vec2 u = poly[i], v = poly[(i + 1) % m];
      const double su = side(u), sv = side(v);
      if (su >= 0) next[o++] = u;
      if ((su >= 0) != (sv >= 0)) next[o++] = u + (su / (su - sv)) * (v - u);
    }
    m = o;
    for (int i = 0; i < m; ++i) poly[i] = next[i];
  }
  double a2 = 0;
  for (int i = 1; i + 1 < m; ++i) a2 += cross(poly[i] - poly[0], poly[i + 1] - poly[0]);
  return 0.5 * std::abs(a2);
}

// The layout's triangles in a uniform grid, per island; an island's
// triangles are found from the cells a query box touches.
class IslandGrid {
 public:
  explicit IslandGrid(double cell) : inv_(1.0 / cell) {}
  void insert(uint32_t island, uint32_t t, const Corners& c) {
    const Box b = box(c);
    if ((b.x1 - b.x0 + 1) * (b.y1 - b.y0 + 1) > kMaxCellsPerTriangle) {
      large_[island].push_back(t);
      return;
    }
    for (int64_t x = b.x0; x <= b.x1; ++x)
      for (int64_t y = b.y0; y <= b.y1; ++y) cells_[key(island, x, y)].push_back(t);
  }
  // Calls visit(t) for the island's triangles whose cells meet the box of
  // `c` (a triangle may come more than once; other islands' may come too).
  template <class Visit>
  bool any_near(uint32_t island, const Corners& c, Visit&& visit) const {
    if (auto it = large_.find(island); it != large_.end())
      for (uint32_t t : it->second)
        if (visit(t)) return true;
    const Box b = box(c);
    for (int64_t x = b.x0; x <= b.x1; ++x)
      for (int64_t y = b.y0; y <= b.y1; ++y)
        if (auto it = cells_.find(key(island, x, y)); it != cells_.end())
          for (uint32_t t : it->second)
            if (visit(t)) return true;
    return false;
  }

 private:
  struct Box {
    int64_t x0, y0, x1, y1;
  };
  Box box(const Corners& c) const {
    const double x0 = std::min({c[0].x, c[1].x, c[2].x}), x1 = std::max({c[0].x, c[1].x, c[2].x});
    const double y0 = std::min({c[0].y, c[1].y, c[2].y}), y1 = std::max({c[0].y, c[1].y, c[2].y});
    return {int64_t(std::floor(x0 * inv_)), int64_t(std::floor(y0 * inv_)), int64_t(std::floor(x1 * inv_)),
            int64_t(std::floor(y1 * inv_))};
  }
  static uint64_t key(uint32_t island, int64_t x, int64_t y) {
    // Collisions only add candidates, which the caller filters by island.
    return (uint64_t(island) * 0x9E3779B97F4A7C15ull) ^ (uint64_t(x) * 0xC2B2AE3D27D4EB4Full) ^
           (uint64_t(y) * 0x165667B19E3779F9ull);
  }
  double inv_;
  std::unordered_map<uint64_t, std::vector<uint32_t>> cells_;
  std::unordered_map<uint32_t, std::vector<uint32_t>> large_;
};

inline Corners corners_of(const UvLayout& L, uint32_t t) {
  return {L.uv[L.corner_vertex[t][0]], L.uv[L.corner_vertex[t][1]], L.uv[L.corner_vertex[t][2]]};
}

}  // namespace soupuv::uvsolve::detail
