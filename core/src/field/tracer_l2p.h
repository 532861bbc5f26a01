// The field of an FMM local expansion, for the tracer (internal to
// core/src/field). A local expansion of order p, phi(x) = sum_b L_b d^b with
// d = x - centre (taylor.h), has the field E = -grad phi, three polynomials of
// degree p - 1. The tracer evaluates each leaf's expansion at many points, so
// it converts the expansion once (from_local) and then pays per point only
// one Horner pass.
//
// Layout of a converted expansion: the monomials d^b = x^i y^j z^k grouped in
// rows of equal (j, k); per row, i = 0 .. p-1-j-k, and per monomial four
// doubles (Ex, Ey, Ez, 0) of its coefficient, so the three components run in
// the lanes of one SIMD register: E = sum over rows of y^j z^k P_jk(x), each
// P_jk by Horner in x.
#pragma once

#include <vector>

#include "soupuv/field/taylor.h"
#include "soupuv/vec.h"

namespace soupuv::field::tracer {

class FieldExpansion {
 public:
  explicit FieldExpansion(const TaylorBasis& basis);

  // Doubles per converted expansion.
  int size() const { return 4 * n_; }
  // g[0..size()) from the local expansion L[0..basis.size()).
  void from_local(const double* L, double* g) const;
  // Adds the field at offset d from the expansion centre to *E.
  void evaluate(const double* g, Vec3 d, Vec3* E) const;

 private:
  int n_ = 0;                      // monomials of degree <= p - 1
  int degree_ = 0;                 // p - 1
  // Per row: j, k, its first monomial, its length (i = 0 .. length - 1).
  std::vector<int> rows_;
  // Per monomial in row order: the basis index of b + e_c and the factor b_c + 1, c = x, y, z.
  std::vector<int> up_[3];
  std::vector<double> factor_[3];
};

}  // namespace soupuv::field::tracer
