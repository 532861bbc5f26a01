// The field of a uniformly charged flat triangle in closed form, for the
// tracer: the same integral as triangle_integrals (triangle_integrals.h) but
// field only, from a per-triangle frame computed once (unit normal, edge
// directions and lengths), and with the normal part as one solid angle
// (Van Oosterom & Strackee 1983: tan(Omega/2) = det[r1 r2 r3] /
// (R1 R2 R3 + (r1.r2) R3 + (r1.r3) R2 + (r2.r3) R1)) instead of three
// per-edge atan2: one atan2, three logs and three square roots per call.
// Internal to core/src/field.
#pragma once

#include "soupuv/vec.h"

namespace soupuv::field::tracer {

struct TriangleFrame {
  Vec3 v[3];        // vertices
  Vec3 n;           // unit normal, (v1 - v0) x (v2 - v0) direction
  Vec3 l[3];        // unit edge directions v[i] -> v[i+1]
  Vec3 m[3];        // outward in-plane edge normals l x n
  double len[3] = {0, 0, 0};
  bool degenerate = true;  // zero area (within rounding): no field
};

TriangleFrame triangle_frame(Vec3 a, Vec3 b, Vec3 c);

// Integral over the triangle of (x - y) / |x - y|^3 dA(y): divide by the
// area for a unit total charge. In the plane the normal part is the
// principal value 0, as in triangle_integrals.
Vec3 closed_form_field(const TriangleFrame& t, Vec3 x);

// Integral over the triangle of 1 / |x - y| dA(y) (divide by the area for a
// unit total charge): sum over the edges of t0 * log term minus |h| times
// the solid angle, the same terms as closed_form_field. The collocation's
// near matrix (collocation.cpp) evaluates it four at a time
// (closed_form_potentials, tracer_closed_form_batch.h).
double closed_form_potential(const TriangleFrame& t, Vec3 x);

}  // namespace soupuv::field::tracer
