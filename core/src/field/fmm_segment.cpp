// Fmm::segment_crosses: does a segment meet any source triangle? The tracer
// asks it before a step longer than the distance to the nearest triangle
// guarantees (TraceOptions::max_step_growth).
//
// Walks the source tree: a cell is skipped when the segment passes farther
// from its expansion centre than its radius (which covers every vertex of
// its triangles); in the leaves left, each triangle is tested exactly
// (geometry::segment_crosses_triangle). O(log n) cells for a short segment.
#include <algorithm>
#include <vector>

#include "soupuv/field/fmm.h"
#include "soupuv/field/triangle_integrals.h"
#include "soupuv/geometry/segment_triangle.h"

namespace soupuv::field {

namespace {

// Squared distance from x to the closed segment ab.
double segment_point_distance2(Vec3 a, Vec3 b, Vec3 x) {
  const Vec3 ab = b - a;
  const double len2 = norm2(ab);
  const double t = len2 > 0 ? std::clamp(dot(x - a, ab) / len2, 0.0, 1.0) : 0.0;
  return norm2(a + t * ab - x);
}

}  // namespace

bool Fmm::segment_crosses(Vec3 a, Vec3 b) const {
  if (scells_.empty()) return false;
  std::vector<int> stack{0};
  while (!stack.empty()) {
    const SourceCell& c = scells_[stack.back()];
    stack.pop_back();
    if (segment_point_distance2(a, b, c.mc) > c.radius * c.radius) continue;
    if (c.children == 0) {
      for (int k = c.first; k < c.first + c.count; ++k) {
        const uint32_t j = order_[k];
        if (geometry::segment_crosses_triangle(a, b, src_.a[j], src_.b[j], src_.c[j])) return true;
      }
      continue;
    }
    for (int ch = 0; ch < c.children; ++ch) stack.push_back(c.child_first + ch);
  }
  return false;
}

}  // namespace soupuv::field
