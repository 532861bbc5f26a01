// CandidateList: the soup triangles that can be the nearest one to some point
// of a box (nearest-candidate culling), gathered once per box by
// TriangleBvh::gather and then scanned by TriangleBvh::distance_among for
// every grid point in the box.
//
// Layout: the candidates' bounding boxes in float, relative to the box
// center (small numbers, so float keeps ~1e-7 of the cell size), one array
// per coordinate, padded to a multiple of kBlock with boxes infinitely far
// away. The per-point lower-bound test then runs as straight-line float code
// over a block (4 candidates per SSE instruction) instead of one branchy
// double test per candidate; only the few candidates whose box is closer than
// the best distance so far get the exact double point-triangle distance.
// `slack` bounds the float rounding of a box distance, so a candidate is
// skipped only when its box is certainly farther than the best distance.
#pragma once

#include <cstdint>
#include <vector>

#include "soupuv/vec.h"

namespace soupuv::proxy {

struct CandidateList {
  static constexpr size_t kBlock = 16;

  Vec3 center{0, 0, 0};  // local origin of lo/hi
  float extent = 0;      // max |local coordinate| stored (for the rounding slack)
  std::vector<uint32_t> ids;  // triangle ids; padding entries are UINT32_MAX
  std::vector<float> lo_x, lo_y, lo_z, hi_x, hi_y, hi_z;
  size_t count = 0;      // real candidates (ids.size() is padded)

  void clear(Vec3 local_origin) {
    center = local_origin;
    extent = 0;
    count = 0;
    for (auto* v : {&lo_x, &lo_y, &lo_z, &hi_x, &hi_y, &hi_z}) v->clear();
    ids.clear();
  }
  size_t size() const { return count; }
};

}  // namespace soupuv::proxy
