// Narrow band of the offset field f(x) = d(x, soup) - o on a sparse grid.
//
// Input:  the soup's BVH, its bounding box, the offset o, the cell size h.
// Output: the leaf cells of size h whose corners change sign (exactly the
//         cells the level set f = 0 crosses), and f at their corners — found
//         coarse-to-fine: a coarser cell survives only when |f(center)| <= its
//         half-diagonal (d is 1-Lipschitz, so no crossing cell is ever
//         dropped); the children of the surviving 2h cells are decided by
//         their corners. Work and memory are proportional to the cells near
//         the surface, not to the volume.
//         With `outer_only`, cells that cannot touch the outer shell are
//         pruned at every level: a cell is certainly inside (f <= 0 on all of
//         it), certainly outside, or band; band cells whose 6-connected
//         region of not-certainly-inside cells never reaches the grid border
//         enclose a cavity (the inner offset shell of a closed soup) and are
//         dropped with their subtree. Any path from the outer shell to the
//         border stays in f > 0, so it never crosses a certainly-inside cell:
//         no cell of the outer shell is lost. The only dense memory is one
//         byte per cell of the level being pruned (levels with more than
//         2^25 cells are not pruned).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "soupuv/progress.h"
#include "soupuv/geometry/distance_bvh.h"
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
  // Per cell of `cells`, the index into corner_keys/corner_values of its
  // corner v = dx | dy << 1 | dz << 2 (filled by build_narrow_band; a band
  // made by hand may leave it empty and is read through value()).
  std::vector<std::array<uint32_t, 8>> cell_corners;
  std::vector<uint64_t> corner_keys;    // corners of the candidate leaf cells, sorted, unique
  std::vector<double> corner_values;    // f = d - o at corner_keys
  size_t distance_evaluations = 0;
  size_t pruned_cells = 0;              // band cells dropped as cavity (all levels)

  Vec3 corner_position(uint64_t key) const {
    auto c = grid_coords(key);
    return origin + Vec3{c[0] * cell, c[1] * cell, c[2] * cell};
  }
  // f at a corner of a leaf cell (binary search).
  double value(uint64_t key) const;
  // f at the 8 corners of cells[n] (v = dx | dy << 1 | dz << 2).
  std::array<double, 8> cell_values(size_t n) const;
};

// `box` bounds the soup; the grid pads it by o + 2h on every side.
NarrowBand build_narrow_band(const geometry::DistanceBvh& soup_bvh, const Box3& box, double offset,
                             double cell, Progress& progress, bool outer_only = true);

}  // namespace soupuv::proxy
