// Single-precision point-charge kernels of the tracer's near field
// (TracerField, tracer_field.cpp). Internal to core/src/field.
//
// Why float: the tracer's target is a field relative error of 1e-4 against
// direct summation; float (rel. 6e-8, after one Newton step on rsqrt ~1e-7)
// keeps the sum of a near list of a few hundred point charges far below it,
// while AVX2 processes 8 lanes per instruction instead of 4 and avoids the
// double sqrt and division (the cost of the previous double kernel). Every
// coordinate is stored relative to a nearby origin (a source leaf's expansion
// centre, or the evaluation point itself), so float rounding is relative to
// distances of the leaf's size, not to the model's coordinates. The closed
// form (triangle_integrals) stays in double: it needs the digits.
//
// Layout of a block (TracerField: the leaf children of one source cell): its
// triangles in slots of 8 (the SIMD lanes); per group of 8 slots, 32 + 32 m floats:
//   cx[8] cy[8] cz[8] nr2[8]        centroid relative to the origin, (near_factor * radius)^2
//   then per quadrature point i < m:  px[8] py[8] pz[8] pq[8]   (pq = charge * weight * kChargeScale)
// Padding slots have charge 0, nr2 -1 (never near) and points far away.
#pragma once

#include <cstdint>

namespace soupuv::field::tracer {

constexpr int kLanes = 8;
// The block charges carry 1/8: the cube of the 1/2 that the AVX2 kernel's
// Newton step for 1/r leaves out (inv_sqrt_twice in tracer_kernels.cpp), one
// multiply less per source point; powers of two scale exactly, so the sums
// are bit for bit those of the unscaled form.
constexpr float kChargeScale = 0.125f;
// Floats per group of 8 slots for m quadrature points per triangle.
inline int group_floats(int m) { return 32 + 32 * m; }

// Adds to e[0..3) the field at x (relative to the block's origin) of every
// slot of `groups` groups that lane_masks[g] selects and that is not a near
// candidate; near_bits[g] receives the selected lanes of group g whose
// centroid lies within sqrt(nr2 * (1 + slack)) of x (slack covers float
// rounding: the caller re-checks them in double and evaluates them itself).
// The masks let one block hold several source leaves without padding between
// them: a caller that wants some of them selects their lanes.
void span_field(const float* block, int groups, int m, const float x[3], double* e, uint8_t* near_bits,
                const uint8_t* lane_masks);

// A symmetric rule given by barycentric coordinates and weights.
struct FloatRule {
  int points = 0;
  float l0[64], l1[64], l2[64], w[64];
};
// The degree-6 rule (12 points) on the triangle, and on its four midpoint
// children (48 points: the same rule on each child, weights / 4).
const FloatRule& degree6_rule();
const FloatRule& degree6_children_rule();

// Triangles for rule_field_batch, one per SIMD lane ("structure of arrays"):
// vertices relative to the evaluation point and the charge. kMax slots,
// a multiple of kLanes; unused slots of a partial last group are padding.
struct RuleTriangles {
  static constexpr int kMax = 32;
  int count = 0;
  alignas(32) float ax[kMax], ay[kMax], az[kMax], bx[kMax], by[kMax], bz[kMax], cx[kMax], cy[kMax], cz[kMax],
      q[kMax];
  // Adds a triangle (vertices relative to the evaluation point); true once full.
  bool add(const float A[3], const float B[3], const float C[3], float charge) {
    ax[count] = A[0]; ay[count] = A[1]; az[count] = A[2];
    bx[count] = B[0]; by[count] = B[1]; bz[count] = B[2];
    cx[count] = C[0]; cy[count] = C[1]; cz[count] = C[2];
    q[count] = charge;
    return ++count == kMax;
  }
};

// Adds to e[0..3) the field at the evaluation point of the `tri.count`
// triangles, each a charge spread by `rule`; empties `tri`. Eight triangles
// per SIMD pass (one per lane), so a 12-point rule costs 12 lane-steps per
// triangle, not 16 as with points across lanes; each triangle's points are
// summed in float, the triangles in double (the near triangles' fields
// largely cancel: a float sum over all of them measurably lost digits,
// 4.8e-6 rel. against 8.7e-7 with double sums).
void rule_field_batch(const FloatRule& rule, RuleTriangles& tri, double* e);

}  // namespace soupuv::field::tracer
