// CandidateList: the soup triangles that can be the nearest one to some point
// of a box (nearest-candidate culling), gathered once per box by
// DistanceBvh::gather and then scanned by DistanceBvh::distance_among for
// every grid point in the box.
//
// Layout: the candidates' bounding boxes in float, relative to the box
// center (small numbers, so float keeps ~1e-7 of the cell size), one array
// per coordinate, padded to a multiple of kBlock with boxes infinitely far
// away. The per-point lower-bound test then runs as straight-line float code
// over a block (4 candidates per SSE instruction) instead of one branchy
// double test per candidate; only the few candidates whose box is closer than
// the best distance so far get the exact double point-triangle distance.
// Besides its box, each candidate has its plane (unit normal n, w = n . a in
// local coordinates): |n . p - w| is a second lower bound of the distance,
// much tighter than the box for a tilted triangle seen from above, which is
// how the grid points see the soup (measured on the 100k noisy sphere: the
// box alone let ~12 of ~90 candidates through to the exact test).
// The rounding slack (see distance_among) keeps every skip certain.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "soupuv/vec.h"

namespace soupuv::geometry {

struct CandidateList {
  static constexpr size_t kBlock = 16;

  Vec3 center{0, 0, 0};  // local origin of lo/hi
  float extent = 0;      // max |local coordinate| stored (for the rounding slack)
  std::vector<uint32_t> ids;  // triangle ids; padding entries are UINT32_MAX
  std::vector<float> lo_x, lo_y, lo_z, hi_x, hi_y, hi_z;
  std::vector<float> n_x, n_y, n_z, w;  // planes; 0 for degenerate triangles
  size_t count = 0;      // real candidates (ids.size() is padded)

  void clear(Vec3 local_origin) {
    center = local_origin;
    extent = 0;
    count = 0;
    for (auto* v : arrays()) v->clear();
    ids.clear();
  }
  size_t size() const { return count; }
  std::array<std::vector<float>*, 10> arrays() { return {&lo_x, &lo_y, &lo_z, &hi_x, &hi_y, &hi_z, &n_x, &n_y, &n_z, &w}; }
};

}  // namespace soupuv::geometry
