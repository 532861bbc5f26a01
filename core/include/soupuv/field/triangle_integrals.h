// Closed-form potential and field of a uniformly charged flat triangle
// (Wilton et al. 1984; Graglia 1993 — the paper's refs [56], [36]).
//
//   TriangleIntegrals r = triangle_integrals(a, b, c, x);
//   r.potential = ∫_T 1 / |x - y| dA(y)
//   r.field     = ∫_T (x - y) / |x - y|^3 dA(y)   (= -grad of r.potential)
//
// Divide by the area for a unit total charge. Exact at any x, including points
// in the triangle's plane (in the plane, the normal field is the principal
// value 0) and next to edges (the in-plane field grows like log near an edge).
// Degenerate triangles give zeros.
#pragma once

#include "soupuv/vec.h"

namespace soupuv::field {

struct TriangleIntegrals {
  double potential = 0;
  Vec3 field;
};

TriangleIntegrals triangle_integrals(Vec3 a, Vec3 b, Vec3 c, Vec3 x);

}  // namespace soupuv::field
