// Multipole-to-local translation of many source cells into one target cell,
// for the tracer (internal to core/src/field). Same operator as
// TaylorBasis::m2l (taylor.h: Cartesian Taylor expansions, scaled form
//   L_b += (-1)^|b| / b! * sum_{|a| <= p - |b|} D_{a+b} M_a / a!,
//   D_c = c! k_c(R), R = target centre - source centre),
// summed over `count` sources at once.
//
// Inputs: the source moments M[i] (basis.size() doubles each) and offsets
// R[i]; output: L (basis.size() doubles, added to).
//
// Why a separate M2L: a target cell takes its M2L sources in one list (up
// to a few hundred), and the kernel recurrence and the contraction have the
// same index pattern for every source. Four sources run side by side in the
// four double lanes of a SIMD register, so each gathered kernel derivative
// serves four sources and no lane waits on another; the generic per-pair
// M2L (one source at a time, gathers per term) was a fifth of the tracer's
// time.
#pragma once

#include <vector>

#include "soupuv/field/taylor.h"
#include "soupuv/vec.h"

namespace soupuv::field::tracer {

class BatchM2L {
 public:
  explicit BatchM2L(const TaylorBasis& basis);

  // L += sum_i M2L(M[i], R[i]). R[i] must be non-zero (well separated cells).
  void apply(const double* const* M, const Vec3* R, int count, double* L) const;
  // The same in single precision, eight sources per pass (L still summed
  // in double over the passes): for the tracer, whose field target (1e-4
  // rel.) is far above float rounding; not for the charge solve.
  void apply_float(const double* const* M, const Vec3* R, int count, double* L) const;

  int size() const { return n_; }
  // Multiply-adds of one operation's contraction: the pairs (a, b) with
  // |a| + |b| <= p.
  size_t terms() const { return power_.size(); }

  // The tables below as raw pointers, the form the SIMD kernels in the .cpp take.
  struct Tables;

 private:
  Tables tables() const;

  int n_ = 0;  // coefficients of total degree <= p
  // Kernel recurrence per coefficient a >= 1 (taylor.h): indices of a - e_i
  // and a - 2e_i (n_, a slot that holds 0, where absent), (2|a|-1)/|a|, (|a|-1)/|a|.
  std::vector<int> m1_, m2_;  // 3 per coefficient
  std::vector<double> c1_, c2_;
  std::vector<double> factorial_, inv_factorial_, out_scale_;
  std::vector<int> start_;  // per b: first entry of power_
  std::vector<int> power_;  // index of a + b for a = 0, 1, ... (degree order)
};

}  // namespace soupuv::field::tracer
