// A block of soup corners for the edge weld's candidate search: every
// corner that may lie near the queries of one grid cell, in float, relative
// to that cell's centre (private to geometry/edge_weld.cpp).
//
// Input : begin_run(box) for each grid cell of the block, then add(corner,
//         its position, the next corner's, the previous corner's) for each
//         of the cell's corners; positions relative to the block's origin.
// Output: near_both(q, p, r2, with_prev, out) appends to `out` the block
//         indices k (increasing) whose corner lies within sqrt(r2) of q and
//         whose next corner (or, with_prev, previous corner) lies within it
//         of p: the corners c whose edge c -> next(c) runs back along a
//         query edge p -> q (or prev(c) -> c runs along it, a flipped
//         neighbour). Only the runs whose box comes within sqrt(r2) of q are
//         tested (about 8 of a block's 27 cells). A prefilter: callers pass
//         r2 a little above their tolerance and test the survivors exactly
//         in double.
// Why   : a 124k scan's edge weld visited ~2,900 corners per query edge, one
//         query at a time through the grid (5.4 s of its 6.4 on two
//         threads); the queries of one cell share their corners, so those
//         are gathered once and each query tests them eight at a time
//         (AVX2, checked once at run time; a scalar loop otherwise).
// Cost  : O(block size) per query.
#pragma once

#include <cstdint>
#include <vector>

#include "soupuv/vec.h"

namespace soupuv::geometry::detail {

// Bounds on a pair's cost (the sum of both ends' squared distances): a pair
// dearer than query + margin and than per_corner[its corner] + margin is not
// returned. Ignored with with_prev (a flipped pair's other edge is not the
// block corner's own).
struct CostBound {
  const float* per_corner;
  float query, margin;
};

class EdgeBlock {
 public:
  // Empties the block; with_prev: add() keeps the previous corners' positions
  // (near_both's with_prev needs them; otherwise they are not stored).
  void clear(bool with_prev);
  // Starts a run of corners inside the box [lo, hi] (relative positions).
  void begin_run(const Vec3& lo, const Vec3& hi);
  void add(uint32_t corner, const Vec3& at, const Vec3& next, const Vec3& prev);
  size_t size() const { return corner_.size(); }
  uint32_t corner(size_t k) const { return corner_[k]; }
  // Ends the last run; call after the last add and before near_both.
  void seal();
  // min_corner: only corners with an id at least this are returned;
  // bound (may be null): see CostBound.
  void near_both(const float q[3], const float p[3], float r2, bool with_prev, uint32_t min_corner,
                 const CostBound* bound, std::vector<uint32_t>& out) const;

 private:
  // A run's corners [first, end), end padded to a multiple of 8 with far values.
  struct Run {
    float lo[3], hi[3];
    uint32_t first, end;
  };
  void pad();
  std::vector<Run> runs_;
  std::vector<uint32_t> corner_;
  std::vector<float> c_[3], n_[3], v_[3];  // corner, next, previous (with_prev_ only): x, y, z
  bool with_prev_ = false;
};

}  // namespace soupuv::geometry::detail
