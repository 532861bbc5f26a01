// UV overlap on a texel grid (private to the transfer module; the island
// relaxation checks with it that a relaxed island grows into nothing).
//
// Input : UV triangles in [0,1]^2 (points outside are clipped away).
// Output: per texel of an N x N grid, how many triangles cover its centre
//         (strictly inside: triangles sharing an edge do not both count its
//         points), and the overlap "excess" sum over texels of max(0, count -
//         1): 0 for a layout without overlap, +1 for each extra layer.
// Cost  : O(N^2) memory; O(texels in the triangle's box) per triangle.
// Limit : sampling at texel centres misses overlaps thinner than a texel.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "soupuv/vec.h"

namespace soupuv::transfer::detail {

class OverlapGrid {
 public:
  explicit OverlapGrid(int size);

  // Adds (+1) or removes (-1) one triangle's coverage.
  void add(const std::array<Vec2, 3>& uv, int delta);
  long excess() const { return excess_; }

 private:
  template <class F>
  void for_each_texel(const std::array<Vec2, 3>& uv, F&& f) const;
  int size_;
  std::vector<uint16_t> count_;
  long excess_ = 0;
};

}  // namespace soupuv::transfer::detail
