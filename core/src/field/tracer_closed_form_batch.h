// The closed-form triangle field (tracer_closed_form.h) of one point for many
// triangles, four per AVX2 pass in double (log and atan2 of tracer_vmath.h).
// Internal to core/src/field.
//
//   tracer::ClosedFormBatch b;
//   b.add(frame, q / area, x, e);   // per triangle; may add to e[0..3)
//   b.flush(e);                     // adds the rest
//
// Inputs: per add a triangle's frame (triangle_frame; kept by pointer until
// the flush), its charge density and the point x. Output: e[0..3) += the sum
// of density * closed_form_field(frame, x) over the adds, the same
// arithmetic up to rounding (tests/core/field/tracer_closed_form_batch_test.cpp).
//
// Why: the closed form is three logs, one atan2 and three square roots per
// triangle, ~12 triangles per point next to the surface; glibc's scalar log
// and atan2 were most of its cost. Here ~30 ns per triangle against ~80 ns
// scalar; the trace's CPU per evaluation fell 3-13 % (session 10, 1 thread,
// A/B in one binary: 12,800 -12.7 %, 51,200 -3.3 %, 204,800 -10.6 %).
// Without AVX2+FMA each add calls closed_form_field at once.
#pragma once

#include "soupuv/vec.h"
#include "tracer_closed_form.h"

namespace soupuv::field::tracer {

class ClosedFormBatch {
 public:
  static constexpr int kLanes = 4;

  // `f` must stay alive until the flush (the tracer's frames live as long
  // as its TracerField).
  void add(const TriangleFrame& f, double density, Vec3 x, double* e) {
    if (f.degenerate) return;
    if (!vector_) {
      const Vec3 g = density * closed_form_field(f, x);
      e[0] += g.x;
      e[1] += g.y;
      e[2] += g.z;
      return;
    }
    frame_[count_] = &f;
    x_[count_] = x;
    density_[count_] = density;
    if (++count_ == kLanes) evaluate(e);
  }
  void flush(double* e) {
    if (count_ > 0) evaluate(e);
  }

 private:
  // Adds the first count_ lanes' fields to e and empties the batch.
  void evaluate(double* e);

  static const bool vector_;  // AVX2+FMA available
  // Only pointers are kept: a pass reads the frames straight into vectors,
  // lane by lane. Copying them into lane arrays at add, then loading whole
  // vectors that overlap four recent scalar stores, stalled each load
  // (failed store forwarding).
  const TriangleFrame* frame_[kLanes] = {};
  Vec3 x_[kLanes];
  double density_[kLanes] = {};
  int count_ = 0;
};

// out[k] = closed_form_potential(*frames[k], x) for k < count, four per AVX2
// pass (lane by lane the same terms; the log and atan2 of tracer_vmath.h,
// a few ulp from std's). Degenerate frames must not be passed. Why: the
// collocation's near matrix spent a fifth of its set-up in the scalar
// closed form's logs and atan2 (docs/tuning.md, session 35).
void closed_form_potentials(const TriangleFrame* const* frames, int count, Vec3 x, double* out);

}  // namespace soupuv::field::tracer
