// Narrow band of the offset field f(x) = d(x, soup) - o on a sparse grid.
//
// Input:  the soup's BVH, its bounding box, the offset o, the cell size h.
// Output: the leaf cells of size h whose corners change sign (exactly the
//         cells the level set f = 0 crosses), and f at their corners — found
//         coarse-to-fine: a coarser cell survives only when |f(center)| <= its
//         half-diagonal (d is 1-Lipschitz, so no crossing cell is ever
//         dropped); the children of the surviving 2h cells are decided by
//         their corners. Work and memory are proportional to the cells near
//         the surface, not to the volume; nothing dense is ever allocated.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "soupuv/progress.h"
#include "soupuv/proxy/triangle_bvh.h"
#include "soupuv/vec.h"

namespace soupuv::proxy {

// Integer grid coordinates packed 20 bits per axis (grids up to 2^20 cells).
constexpr int kGridBits = 20;
inline uint64_t grid_key(uint64_t i, uint64_t j, uint64_t k) {
  return i | (j << kGridBits) | (k << (2 * kGridBits));
}
inline std::array<int, 3> grid_coords(uint64_t key) {
  const uint64_t m = (uint64_t{1} << kGridBits) - 1;
  return {int(key & m), int((key >> kGridBits) & m), int((key >> (2 * kGridBits)) & m)};
}

struct NarrowBand {
  Vec3 origin;            // position of grid corner (0,0,0)
  double cell = 0;        // cell size h
  std::array<int, 3> dims{};  // cells along each axis
  double offset = 0;
  std::vector<uint64_t> cells;          // sign-changing leaf cells (key of their lowest corner), sorted
  std::vector<uint64_t> corner_keys;    // corners of the candidate leaf cells, sorted, unique
  std::vector<double> corner_values;    // f = d - o at corner_keys
  size_t distance_evaluations = 0;

  Vec3 corner_position(uint64_t key) const {
    auto c = grid_coords(key);
    return origin + Vec3{c[0] * cell, c[1] * cell, c[2] * cell};
  }
  // f at a corner of a leaf cell (binary search).
  double value(uint64_t key) const;
};

// `box` bounds the soup; the grid pads it by o + 2h on every side.
NarrowBand build_narrow_band(const TriangleBvh& soup_bvh, const Box3& box, double offset,
                             double cell, Progress& progress);

}  // namespace soupuv::proxy
