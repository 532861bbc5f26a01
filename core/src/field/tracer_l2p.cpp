// Field of a local expansion for the tracer (see tracer_l2p.h).
//
// Horner in x per row, the three field components in the lanes of a 4-double
// vector (GCC/Clang vector extensions: AVX2+FMA when the CPU has them, chosen
// once at run time; otherwise the same code on two SSE2 halves). The previous
// evaluation built the monomials one by one (each from an earlier one, by
// index) and then took three dot products: a chain of dependent gathers.
#include "tracer_l2p.h"

#include <map>

#include "soupuv/errors.h"

namespace soupuv::field::tracer {

namespace {

typedef double v4d __attribute__((vector_size(32)));
constexpr int kMaxDegree = 15;  // the power tables below

}  // namespace

FieldExpansion::FieldExpansion(const TaylorBasis& basis) {
  const int p = basis.order();
  degree_ = p - 1;
  n_ = p >= 1 ? TaylorBasis::size_for(p - 1) : 0;
  if (degree_ > kMaxDegree) throw Error(ErrorCode::unsupported, "FieldExpansion: FMM order above 16");
  std::map<std::array<int, 3>, int> index;
  for (int b = 0; b < basis.size(); ++b) index[basis.multi_index(b)] = b;
  for (int k = 0; k <= degree_; ++k)
    for (int j = 0; j + k <= degree_; ++j) {
      const int length = degree_ - j - k + 1;
      rows_.insert(rows_.end(), {j, k, static_cast<int>(up_[0].size()), length});
      for (int i = 0; i < length; ++i) {
        const std::array<int, 3> b{i, j, k};
        for (int c = 0; c < 3; ++c) {
          auto u = b;
          ++u[c];
          up_[c].push_back(index.at(u));
          factor_[c].push_back(b[c] + 1);
        }
      }
    }
}

void FieldExpansion::from_local(const double* L, double* g) const {
  // d/dx_c sum_b L_b d^b = sum_b' (b'_c + 1) L_{b' + e_c} d^b'; E = -grad.
  for (int m = 0; m < n_; ++m) {
    for (int c = 0; c < 3; ++c) g[4 * m + c] = -factor_[c][m] * L[up_[c][m]];
    g[4 * m + 3] = 0;
  }
}

namespace {

// out[0..3) = the field at d of the converted expansion g (rows: see rows_).
__attribute__((always_inline)) inline void horner_rows(const double* g, const int* rows, int nrows, int degree,
                                                       const double d[3], double* out) {
  double yp[kMaxDegree + 1], zp[kMaxDegree + 1];
  yp[0] = zp[0] = 1;
  for (int e = 1; e <= degree; ++e) {
    yp[e] = yp[e - 1] * d[1];
    zp[e] = zp[e - 1] * d[2];
  }
  const v4d x = {d[0], d[0], d[0], d[0]};
  v4d acc0 = {0, 0, 0, 0}, acc1 = acc0;
  for (int r = 0; r < nrows; ++r) {
    const int* row = rows + 4 * r;
    const double* c = g + 4 * row[2];
    v4d h;
    __builtin_memcpy(&h, c + 4 * (row[3] - 1), sizeof h);
    for (int i = row[3] - 2; i >= 0; --i) {
      v4d ci;
      __builtin_memcpy(&ci, c + 4 * i, sizeof ci);
      h = h * x + ci;
    }
    const double s = yp[row[0]] * zp[row[1]];
    // Two running sums: rows alternate between them (add latency).
    if (r & 1) acc1 += h * s;
    else acc0 += h * s;
  }
  const v4d e = acc0 + acc1;
  out[0] = e[0];
  out[1] = e[1];
  out[2] = e[2];
}

#if defined(__x86_64__) && defined(__GNUC__)
__attribute__((target("avx2,fma"))) void horner_avx2(const double* g, const int* rows, int nrows, int degree,
                                                      const double d[3], double* out) {
  horner_rows(g, rows, nrows, degree, d, out);
}
const bool kHasAvx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#endif

void horner_generic(const double* g, const int* rows, int nrows, int degree, const double d[3], double* out) {
  horner_rows(g, rows, nrows, degree, d, out);
}

}  // namespace

void FieldExpansion::evaluate(const double* g, Vec3 d, Vec3* E) const {
  const int nrows = static_cast<int>(rows_.size() / 4);
  if (nrows == 0) return;
  const double dd[3] = {d.x, d.y, d.z};
  double e[3];
#if defined(__x86_64__) && defined(__GNUC__)
  if (kHasAvx2) horner_avx2(g, rows_.data(), nrows, degree_, dd, e);
  else horner_generic(g, rows_.data(), nrows, degree_, dd, e);
#else
  horner_generic(g, rows_.data(), nrows, degree_, dd, e);
#endif
  *E += Vec3{e[0], e[1], e[2]};
}

}  // namespace soupuv::field::tracer
