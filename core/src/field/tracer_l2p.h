// The field of an FMM local expansion, for the tracer (internal to
// core/src/field). A local expansion of order p, phi(x) = sum_b L_b d^b with
// d = x - centre (taylor.h), has the field E = -grad phi, three polynomials of
// degree p - 1. The tracer evaluates each leaf's expansion at many points, so
// it converts the expansion once (from_local) and then pays per point only
// the degree p - 1 monomials and three dot products, without the generic
// L2P's per-coefficient index lookups and branches.
#pragma once

#include <vector>

#include "soupuv/field/taylor.h"
#include "soupuv/vec.h"

namespace soupuv::field::tracer {

class FieldExpansion {
 public:
  explicit FieldExpansion(const TaylorBasis& basis);

  // Doubles per converted expansion: x, y and z coefficient blocks.
  int size() const { return 3 * n_; }
  // g[0..size()) from the local expansion L[0..basis.size()).
  void from_local(const double* L, double* g) const;
  // Adds the field at offset d from the expansion centre to *E.
  void evaluate(const double* g, Vec3 d, Vec3* E) const;

 private:
  int n_ = 0;                    // monomials of degree <= p - 1
  std::vector<int> parent_;      // monomial b = monomial parent_[b] times d[axis_[b]]
  std::vector<int> axis_;
  std::vector<int> up_[3];       // index of b + e_c in the basis
  std::vector<double> factor_[3]; // b_c + 1
};

}  // namespace soupuv::field::tracer
