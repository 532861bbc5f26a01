// The closed-form triangle field (tracer_closed_form.h) of one point for many
// triangles, four per AVX2 pass in double (log and atan2 of tracer_vmath.h).
// Internal to core/src/field.
//
//   tracer::ClosedFormBatch b;
//   b.add(frame, q / area, x, e);   // per triangle; may add to e[0..3)
//   b.flush(e);                     // adds the rest; before x changes
//
// Inputs: per triangle its frame (triangle_frame) and charge density, and
// the point x (the same for every add until flush). Output: e[0..3) +=
// sum of density * closed_form_field(frame, x), the same arithmetic up to
// rounding (tests/core/field/tracer_closed_form_batch_test.cpp).
//
// Why: the closed form is three logs, one atan2 and three square roots per
// triangle, ~12 triangles per point next to the surface; glibc's scalar log
// and atan2 were most of its cost. A triangle's frame is copied into the
// lane arrays with the vertices made relative to x (as closed_form_field
// does), so a pass reads only aligned vectors. Without AVX2+FMA each add
// calls closed_form_field at once.
#pragma once

#include "soupuv/vec.h"
#include "tracer_closed_form.h"

namespace soupuv::field::tracer {

class ClosedFormBatch {
 public:
  static constexpr int kLanes = 4;
  ClosedFormBatch();

  void add(const TriangleFrame& f, double density, Vec3 x, double* e) {
    if (f.degenerate) return;
    if (!vector_) {
      const Vec3 g = density * closed_form_field(f, x);
      e[0] += g.x;
      e[1] += g.y;
      e[2] += g.z;
      return;
    }
    const int l = count_;
    for (int k = 0; k < 3; ++k) {
      set(&lanes_.r[k][0][0], f.v[k] - x, l);
      set(&lanes_.l[k][0][0], f.l[k], l);
      set(&lanes_.m[k][0][0], f.m[k], l);
      lanes_.len[k][l] = f.len[k];
    }
    set(&lanes_.n[0][0], f.n, l);
    lanes_.density[l] = density;
    if (++count_ == kLanes) evaluate(e);
  }
  void flush(double* e) {
    if (count_ > 0) evaluate(e);
  }

  // Lane arrays, [vector][component][lane].
  struct Lanes {
    alignas(32) double r[3][3][kLanes];  // vertices relative to x
    alignas(32) double l[3][3][kLanes];  // unit edge directions
    alignas(32) double m[3][3][kLanes];  // outward in-plane edge normals
    alignas(32) double n[3][kLanes];     // unit normal
    alignas(32) double len[3][kLanes];   // edge lengths
    alignas(32) double density[kLanes];  // charge per area
  };

 private:
  static void set(double* p, Vec3 v, int l) {
    p[l] = v.x;
    p[kLanes + l] = v.y;
    p[2 * kLanes + l] = v.z;
  }
  // Adds the first count_ lanes' fields to e and empties the batch.
  void evaluate(double* e);

  static const bool vector_;  // AVX2+FMA available
  Lanes lanes_;
  int count_ = 0;
};

}  // namespace soupuv::field::tracer
