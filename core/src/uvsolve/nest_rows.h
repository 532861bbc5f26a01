// Small islands nested side by side in a row (private to the UV solve's
// packing, pack_islands.cpp).
//
// Input : islands one after the other, each as its triangles in its own
//         frame (its box's corner at the origin, the row running along +x),
//         and the gap (UV units) every two islands keep.
// Output: each island's shift along x: the least that keeps every one of
//         its triangles at least the gap (Euclidean) from every triangle
//         of the islands before it, and not left of the island before it.
// Why   : grouped islands are a few texels across and pay the padding on
//         every side; boxes side by side lose a triangle's empty half and
//         a gap per island, while a triangle turned apex-down beside one
//         apex-up sits in that half (a row of triangles like a strip). The
//         caller tries each island as it is and turned by 180 degrees and
//         keeps the turn with the smaller shift.
// How   : two convex shapes come closer than the gap over one interval of
//         shifts, and the last shift of it is where a corner of one meets
//         the gap's capsule around an edge of the other; so the shift is
//         the largest such meeting over corner-edge pairs, both ways.
// Cost  : per island, its triangles against those of the few islands
//         before it within reach (the row's earlier islands are skipped by
//         their box, which is exact: a box a gap away is a gap away).
#pragma once

#include <array>
#include <vector>

#include "soupuv/vec.h"

namespace soupuv::uvsolve::detail {

using RowTriangle = std::array<Vec2, 3>;

class RowNester {
 public:
  explicit RowNester(double gap) : gap_(gap) {}
  // The shift the island `tris` (its own frame) would take next.
  double shift_for(const RowTriangle* tris, size_t count) const;
  // Puts the island at `shift` (from shift_for) in the row.
  void add(const RowTriangle* tris, size_t count, double width, double shift);
  // The row's length so far: the right end of its rightmost box.
  double length() const { return length_; }

 private:
  struct Placed {
    size_t first, count;  // its triangles in tris_, row frame
    double left, right;   // its box along x
  };
  double gap_;
  std::vector<RowTriangle> tris_;
  std::vector<Placed> placed_;
  double length_ = 0;
};

// The least shift s of `moving` along +x such that for every shift at or
// above s, `moving` + (s, 0) keeps at least `gap` from `fixed` (two
// triangles; -infinity when no shift brings them within the gap).
double least_clear_shift(const RowTriangle& fixed, const RowTriangle& moving, double gap);

}  // namespace soupuv::uvsolve::detail
