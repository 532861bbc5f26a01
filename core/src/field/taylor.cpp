// Cartesian Taylor FMM operators (see taylor.h for the conventions).
#include "soupuv/field/taylor.h"

#include <cmath>

namespace soupuv::field {

namespace {
double binomial(int n, int k) {
  double r = 1;
  for (int i = 1; i <= k; ++i) r = r * (n - k + i) / i;
  return r;
}
}  // namespace

TaylorBasis::TaylorBasis(int order) : p_(order) {
  const int q = p_ + 1;  // kernel order needed by M2P fields
  const int dim = p_ + 3;
  lookup_.assign(dim * dim * dim, -1);
  for (int deg = 0; deg <= q; ++deg)
    for (int i = deg; i >= 0; --i)
      for (int j = deg - i; j >= 0; --j) {
        int k = deg - i - j;
        lookup_[(i * dim + j) * dim + k] = static_cast<int>(index_.size());
        index_.push_back({i, j, k});
      }
  const int n = size_for(p_);
  down_.resize(index_.size());
  for (size_t a = 0; a < index_.size(); ++a)
    for (int d = 0; d < 3; ++d) {
      auto m = index_[a];
      down_[a][d] = m[d] > 0 ? (--m[d], at(m[0], m[1], m[2])) : -1;
    }
  mono_step_.resize(index_.size());
  for (size_t a = 1; a < index_.size(); ++a)
    for (int c = 0; c < 3; ++c)
      if (down_[a][c] >= 0) {
        mono_step_[a] = {down_[a][c], c};
        break;
      }
  const int zero = static_cast<int>(index_.size());
  kterm_.resize(index_.size());
  for (size_t a = 1; a < index_.size(); ++a) {
    const auto& A = index_[a];
    const int deg = A[0] + A[1] + A[2];
    KernelTerm& t = kterm_[a];
    t.c1 = (2.0 * deg - 1) / deg;
    t.c2 = (deg - 1.0) / deg;
    for (int d = 0; d < 3; ++d) {
      const int m1 = down_[a][d];
      t.m1[d] = m1 >= 0 ? m1 : zero;
      t.m2[d] = (m1 >= 0 && down_[m1][d] >= 0) ? down_[m1][d] : zero;
    }
  }
  // shift: (y - c_parent)^a = sum_{b <= a} C(a, b) d^(a-b) (y - c_child)^b
  for (int a = 0; a < n; ++a) {
    auto A = index_[a];
    for (int b = 0; b < n; ++b) {
      auto B = index_[b];
      if (B[0] > A[0] || B[1] > A[1] || B[2] > A[2]) continue;
      double c = binomial(A[0], B[0]) * binomial(A[1], B[1]) * binomial(A[2], B[2]);
      shift_.push_back({b, a, at(A[0] - B[0], A[1] - B[1], A[2] - B[2]), c});
    }
  }
  // m2l: L_b += (-1)^|b| C(a+b, a) k_{a+b}(R) M_a for |a| + |b| <= p, with
  // C(a+b, a) = (a+b)! / (a! b!) folded into the scaled operands (taylor.h).
  factorial_.resize(index_.size());
  for (size_t a = 0; a < index_.size(); ++a) {
    const auto& A = index_[a];
    factorial_[a] = 1;
    for (int d = 0; d < 3; ++d)
      for (int f = 2; f <= A[d]; ++f) factorial_[a] *= f;
  }
  out_scale_.resize(n);
  m2l_start_.assign(n + 1, 0);
  for (int b = 0; b < n; ++b) {
    auto B = index_[b];
    const int degb = B[0] + B[1] + B[2];
    out_scale_[b] = (degb % 2 ? -1.0 : 1.0) / factorial_[b];
    const int na = size_for(p_ - degb);
    for (int a = 0; a < na; ++a) {
      auto A = index_[a];
      m2l_power_.push_back(at(A[0] + B[0], A[1] + B[1], A[2] + B[2]));
    }
    m2l_start_[b + 1] = static_cast<int>(m2l_power_.size());
  }
}

void TaylorBasis::kernel(Vec3 R, int q, double* out) const {
  const int n = size_for(q);
  const int zero = static_cast<int>(index_.size());  // the scratch slot that stays 0
  double buf[1024];
  std::vector<double> big;
  double* k = buf;
  if (zero + 1 > 1024) {
    big.resize(zero + 1);
    k = big.data();
  }
  k[zero] = 0;
  const double r2 = dot(R, R);
  k[0] = 1.0 / std::sqrt(r2);
  const double inv_r2 = 1.0 / r2;
  const double Rd[3] = {R.x, R.y, R.z};
  // Branch-free recurrence: absent terms read the zero slot (kterm_).
  for (int a = 1; a < n; ++a) {
    const KernelTerm& t = kterm_[a];
    const double s1 = Rd[0] * k[t.m1[0]] + Rd[1] * k[t.m1[1]] + Rd[2] * k[t.m1[2]];
    const double s2 = k[t.m2[0]] + k[t.m2[1]] + k[t.m2[2]];
    k[a] = (t.c1 * s1 - t.c2 * s2) * inv_r2;
  }
  for (int a = 0; a < n; ++a) out[a] = k[a];
}

void TaylorBasis::monomials(Vec3 d, int q, double* out) const {
  const int n = size_for(q);
  const double dc[3] = {d.x, d.y, d.z};
  out[0] = 1;
  // The monomial one degree lower times one coordinate (mono_step_): one
  // multiply per term, no search (this ran per quadrature point in P2M and
  // per target in L2P: ~11 % of a charge solve with the search).
  for (int a = 1; a < n; ++a) out[a] = out[mono_step_[a].from] * dc[mono_step_[a].axis];
}

void TaylorBasis::p2m(Vec3 c, const Vec3* x, const double* q, int n, double* M) const {
  const int m = size();
  double mono[512];
  std::vector<double> big;
  double* w = mono;
  if (m > 512) {
    big.resize(m);
    w = big.data();
  }
  for (int j = 0; j < n; ++j) {
    monomials(x[j] - c, p_, w);
    for (int a = 0; a < m; ++a) M[a] += q[j] * w[a];
  }
}

namespace {
// Scratch space for one expansion's monomials: on the stack for the orders we
// use (no heap allocation per translation), on the heap beyond.
class MonomialScratch {
 public:
  explicit MonomialScratch(int n) {
    if (n > kStack) {
      big_.resize(n);
      data_ = big_.data();
    }
  }
  double* data() { return data_; }

 private:
  static constexpr int kStack = 1024;
  double stack_[kStack];
  std::vector<double> big_;
  double* data_ = stack_;
};
}  // namespace

void TaylorBasis::m2m(const double* Mchild, Vec3 d, double* Mparent) const {
  MonomialScratch scratch(size());
  double* w = scratch.data();
  monomials(d, p_, w);
  for (const Term& t : shift_) Mparent[t.to] += t.coef * w[t.power] * Mchild[t.from];
}

void TaylorBasis::m2l(const double* M, Vec3 R, double* L) const {
  const int n = size();
  double kbuf[1024], mbuf[1024];
  std::vector<double> big;
  double* k = kbuf;
  double* mt = mbuf;
  if (n > 1024) {
    big.resize(2 * n);
    k = big.data();
    mt = k + n;
  }
  kernel(R, p_, k);
  for (int a = 0; a < n; ++a) {
    k[a] *= factorial_[a];
    mt[a] = M[a] / factorial_[a];
  }
  for (int b = 0; b < n; ++b) {
    const int* pw = &m2l_power_[m2l_start_[b]];
    const int count = m2l_start_[b + 1] - m2l_start_[b];
    // Four independent partial sums: a single running sum is bound by the
    // floating-point add latency (measured: the M2L ran ~3x slower).
    double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
    int a = 0;
    for (; a + 4 <= count; a += 4) {
      s0 += k[pw[a]] * mt[a];
      s1 += k[pw[a + 1]] * mt[a + 1];
      s2 += k[pw[a + 2]] * mt[a + 2];
      s3 += k[pw[a + 3]] * mt[a + 3];
    }
    for (; a < count; ++a) s0 += k[pw[a]] * mt[a];
    L[b] += out_scale_[b] * ((s0 + s1) + (s2 + s3));
  }
}

void TaylorBasis::l2l(const double* Lparent, Vec3 d, double* Lchild) const {
  MonomialScratch scratch(size());
  double* w = scratch.data();
  monomials(d, p_, w);
  // the shift list maps b -> a with a >= b; a local expansion shifts from a down to b
  for (const Term& t : shift_) Lchild[t.from] += t.coef * w[t.power] * Lparent[t.to];
}

void TaylorBasis::l2p(const double* L, Vec3 d, double* phi, Vec3* E) const {
  const int n = size();
  double wbuf[1024];
  std::vector<double> big;
  double* w = wbuf;
  if (n > 1024) {
    big.resize(n);
    w = big.data();
  }
  monomials(d, p_, w);
  double f = 0, gx = 0, gy = 0, gz = 0;
  for (int b = 0; b < n; ++b) {
    const auto& B = index_[b];
    f += L[b] * w[b];
    if (B[0]) gx += B[0] * L[b] * w[down_[b][0]];
    if (B[1]) gy += B[1] * L[b] * w[down_[b][1]];
    if (B[2]) gz += B[2] * L[b] * w[down_[b][2]];
  }
  if (phi) *phi += f;
  if (E) *E -= Vec3{gx, gy, gz};
}

void TaylorBasis::m2p(const double* M, Vec3 R, double* phi, Vec3* E) const {
  const int n = size();
  const int q = p_ + 1;
  std::vector<double> k(size_for(q));
  kernel(R, q, k.data());
  double f = 0, ex = 0, ey = 0, ez = 0;
  for (int a = 0; a < n; ++a) {
    const auto& A = index_[a];
    f += M[a] * k[a];
    ex += M[a] * (A[0] + 1) * k[at(A[0] + 1, A[1], A[2])];
    ey += M[a] * (A[1] + 1) * k[at(A[0], A[1] + 1, A[2])];
    ez += M[a] * (A[2] + 1) * k[at(A[0], A[1], A[2] + 1)];
  }
  if (phi) *phi += f;
  if (E) *E += Vec3{ex, ey, ez};
}

}  // namespace soupuv::field
