// A uniform hash grid over a soup's triangle corners, for the welds'
// "which corners lie near this point" query.
//
// Input : a soup and a cell size (callers pick it: never finer than their
//         tolerance, so every corner within the tolerance of p lies in the 27
//         cells around p's cell).
// Output: for_each_near(p, f) calls f(corner id) for every corner in those
//         27 cells, cell by cell (x, then y, then z), each bucket in corner
//         order — a fixed order, so callers' candidate lists are deterministic.
// Cost  : O(corners) to build; a query costs the corners in its 27 cells.
#pragma once

#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "soupuv/soup.h"

namespace soupuv::geometry {

class CornerGrid {
 public:
  CornerGrid(const Soup& soup, const Box3& box, double cell) : lo_(box.lo), cell_(cell) {
    const size_t corners = soup.triangles.size() * 3;
    buckets_.reserve(corners);
    for (size_t c = 0; c < corners; ++c) {
      const Vec3 p = soup.positions[soup.triangles[c / 3][c % 3]];
      buckets_[key(coord(p.x, lo_.x), coord(p.y, lo_.y), coord(p.z, lo_.z))].push_back(uint32_t(c));
    }
  }

  template <class Visit>
  void for_each_near(const Vec3& p, Visit&& visit) const {
    const int64_t cx = coord(p.x, lo_.x), cy = coord(p.y, lo_.y), cz = coord(p.z, lo_.z);
    for (int64_t dx = -1; dx <= 1; ++dx)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dz = -1; dz <= 1; ++dz) {
          if (cx + dx < 0 || cy + dy < 0 || cz + dz < 0) continue;
          auto it = buckets_.find(key(cx + dx, cy + dy, cz + dz));
          if (it == buckets_.end()) continue;
          for (uint32_t c : it->second) visit(c);
        }
  }

 private:
  int64_t coord(double v, double lo) const { return int64_t(std::floor((v - lo) / cell_)); }
  // 21 bits per axis: callers keep the grid within 2^20 cells per axis, and
  // coordinates are offset by the box minimum.
  static uint64_t key(int64_t x, int64_t y, int64_t z) {
    return (uint64_t(x) & 0x1fffff) | ((uint64_t(y) & 0x1fffff) << 21) |
           ((uint64_t(z) & 0x1fffff) << 42);
  }

  Vec3 lo_;
  double cell_;
  std::unordered_map<uint64_t, std::vector<uint32_t>> buckets_;
};

}  // namespace soupuv::geometry
