// Cartesian Taylor expansions of the Laplace kernel 1/|x - y| for the fast
// multipole method: the P2M, M2M, M2L, L2L, L2P and M2P operators of order p.
//
// Multipole moments about a centre c:  M_a = sum_j q_j (y_j - c)^a
// Far potential:   phi(x) = sum_a M_a k_a(x - c),  k_a(R) = (1/a!) d^a/dy^a 1/|x - y|
// Local expansion about z:  phi(x) = sum_b L_b (x - z)^b
// Multi-indices a = (i, j, k) with i + j + k <= p, ordered by total degree.
// The kernel derivatives come from the recurrence
//   |a| r^2 k_a = (2|a| - 1) sum_i R_i k_{a-e_i} - (|a| - 1) sum_i k_{a-2e_i}.
// The shift operators are flat lists of (from, to, power, coefficient) terms
// built once per order; M2L uses the scaled form described at m2l_start_.
#pragma once

#include <array>
#include <vector>

#include "soupuv/vec.h"

namespace soupuv::field {

class TaylorBasis {
 public:
  explicit TaylorBasis(int order);

  int order() const { return p_; }
  // Number of coefficients with total degree <= order.
  int size() const { return size_for(p_); }
  // Coefficients of total degree <= q (q may be order + 1 for M2P fields).
  static int size_for(int q) { return (q + 1) * (q + 2) * (q + 3) / 6; }
  const std::array<int, 3>& multi_index(int n) const { return index_[n]; }

  // k_a(R) for all |a| <= q into out[size_for(q)].
  void kernel(Vec3 R, int q, double* out) const;
  // (d)^a for all |a| <= q.
  void monomials(Vec3 d, int q, double* out) const;

  // M += moments of point charges q at x about centre c.
  void p2m(Vec3 c, const Vec3* x, const double* q, int n, double* M) const;
  // Mparent += child's moments shifted by d = child centre - parent centre.
  void m2m(const double* Mchild, Vec3 d, double* Mparent) const;
  // L += local expansion about the target centre of moments M, R = target centre - source centre.
  void m2l(const double* M, Vec3 R, double* L) const;
  // Lchild += parent expansion re-centred, d = child centre - parent centre.
  void l2l(const double* Lparent, Vec3 d, double* Lchild) const;
  // Potential and field (-grad) of a local expansion at offset d = x - centre.
  void l2p(const double* L, Vec3 d, double* phi, Vec3* E) const;
  // Potential and field of moments M directly at offset R = x - source centre.
  void m2p(const double* M, Vec3 R, double* phi, Vec3* E) const;

 private:
  struct Term {
    int from, to, power;
    double coef;
  };
  int at(int i, int j, int k) const { return lookup_[(i * (p_ + 3) + j) * (p_ + 3) + k]; }

  int p_;
  std::vector<std::array<int, 3>> index_;      // up to order p + 1
  std::vector<int> lookup_;                    // (i, j, k) -> linear index, -1 outside
  std::vector<Term> shift_;                    // M2M / L2L binomial shifts
  // M2L in scaled form: with D_c = c! k_c and Mt_a = M_a / a!,
  //   L_b += (-1)^|b| / b! * sum_{|a| <= p - |b|} D_{a+b} Mt_a,
  // where the a's are the first size_for(p - |b|) indices (degree order), so
  // the inner loop is contiguous in a and gathers only D (index a + b).
  std::vector<int> m2l_start_;                 // per b: offset into m2l_power_
  std::vector<int> m2l_power_;                 // index of a + b, a = 0, 1, ...
  std::vector<double> factorial_;              // a! per index up to order p + 1
  std::vector<double> out_scale_;              // (-1)^|b| / b! per b
  std::vector<std::array<int, 3>> down_;       // per coefficient: index of a - e_i (-1 if none)
  // monomial a = monomial `from` times coordinate `axis` (the first axis of a)
  struct MonoStep {
    int from = 0, axis = 0;
  };
  std::vector<MonoStep> mono_step_;
  // The kernel recurrence per coefficient a, flattened: indices of a - e_i and
  // a - 2e_i (index_.size(), a slot holding 0, where absent), (2|a|-1)/|a|, (|a|-1)/|a|.
  struct KernelTerm {
    int m1[3], m2[3];
    double c1, c2;
  };
  std::vector<KernelTerm> kterm_;
};

}  // namespace soupuv::field
