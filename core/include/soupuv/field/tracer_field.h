// The tracer's field evaluator: the field of fixed charged sources at many
// moving points, built once on top of a charged Fmm (set_charges done).
//
//   TracerField tf(fmm);                  // keeps a reference to fmm
//   int leaf = tf.locate(x, old_leaf);    // target leaf of x (old_leaf: a guess)
//   tf.field(leaf, xs, count, E, nearest);   // all xs lie in `leaf`
//
// Inputs: the Fmm's frozen local expansions (L2P gives the far field) and its
// per-target-leaf near lists. Outputs: E (added to) and, optionally, the
// distance to the nearest triangle that `SourceGeometry::is_near` the point
// (infinity if none), which the tracer uses to shorten steps.
//
// Why a separate evaluator: the sources never move while tracing, so a step
// must only pay the target side. The near field runs over contiguous
// structure-of-arrays copies of the quadrature points and charges (tree
// order, so one source leaf is one contiguous range) with a vectorised loop;
// a whole source leaf is skipped past the per-triangle test when a bounding
// "guard" sphere proves none of its triangles is near the point, so the closed
// form runs only for triangles really close. Points that share a target leaf
// are evaluated together so a source leaf's data is loaded once for all.
// Same model and results (to rounding) as Fmm::evaluate, the slow twin.
#pragma once

#include <cstddef>
#include <vector>

#include "soupuv/field/fmm.h"
#include "soupuv/vec.h"

namespace soupuv::field {

class TracerField {
 public:
  explicit TracerField(const Fmm& fmm);

  // Target leaf containing x, or -1 outside the target tree's root cube.
  // `hint`: a leaf x probably still lies in (the previous step's), checked first.
  int locate(Vec3 x, int hint = -1) const;

  // Adds the field at x[0..count) to E[0..count). Every x must lie in `leaf`
  // (as returned by locate; -1 is allowed for points outside the tree). When
  // nearest is given, nearest[i] receives the distance from x[i] to the
  // nearest triangle evaluated by its near rule (infinity if none).
  void field(int leaf, const Vec3* x, int count, Vec3* E, double* nearest) const;

  size_t memory_bytes() const;

 private:
  // One source leaf: its triangles are tree positions [first, first + count),
  // their quadrature points [first * m, (first + count) * m) in the SoA arrays.
  // No triangle of the leaf is near a point farther than sqrt(guard2) from mc.
  struct Span {
    Vec3 mc;
    double guard2 = 0;
    int first = 0, count = 0;
  };

  const Fmm& fmm_;
  int m_;                                  // quadrature points per triangle
  std::vector<double> px_, py_, pz_, pq_;  // quadrature points and charges, tree order
  std::vector<int> span_of_cell_;          // source cell -> index into spans_ (-1: not a leaf)
  std::vector<Span> spans_;
};

}  // namespace soupuv::field
