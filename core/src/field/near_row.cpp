// The plain-rule part of a near-matrix row (near_row.h).
#include "near_row.h"

#include <cmath>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define SOUPUV_X86_KERNELS 1
#endif

namespace soupuv::field::detail {
namespace {

// Columns [k0, k1) one at a time, in the order and rounding of the
// collocation operator's former scalar loop.
void plain_columns_scalar(const NearColumns& c, int m, const double* w, Vec3 x, size_t k0, size_t k1, float* val,
                          uint8_t* near) {
  for (size_t k = k0; k < k1; ++k) {
    const double ex = x.x - c.cx[k], ey = x.y - c.cy[k], ez = x.z - c.cz[k];
    near[k] = (ex * ex + ey * ey) + ez * ez < c.near_r2[k];
    double v = 0;
    for (int q = 0; q < m; ++q) {
      const size_t i = size_t(q) * c.count + k;
      const double dx = x.x - c.px[i], dy = x.y - c.py[i], dz = x.z - c.pz[i];
      v += w[q] / std::sqrt(dx * dx + dy * dy + dz * dz);
    }
    val[k] = static_cast<float>(v);
  }
}

#ifdef SOUPUV_X86_KERNELS
// 1 / sqrt(r2) for four doubles: the float estimate, two Newton steps
// y (3/2 - r2/2 y^2). Lanes outside float's normal range (a point on a
// quadrature point gives inf, as the exact form does) take the exact form.
__attribute__((target("avx2,fma"))) inline __m256d inv_sqrt_pd(__m256d r2) {
  const __m256d lo = _mm256_set1_pd(1e-36), hi = _mm256_set1_pd(1e36);
  const __m256d odd = _mm256_or_pd(_mm256_cmp_pd(r2, lo, _CMP_LT_OQ), _mm256_cmp_pd(r2, hi, _CMP_GT_OQ));
  __m256d y = _mm256_cvtps_pd(_mm_rsqrt_ps(_mm256_cvtpd_ps(r2)));
  const __m256d h = _mm256_mul_pd(_mm256_set1_pd(0.5), r2), three_halves = _mm256_set1_pd(1.5);
  y = _mm256_mul_pd(y, _mm256_fnmadd_pd(h, _mm256_mul_pd(y, y), three_halves));
  y = _mm256_mul_pd(y, _mm256_fnmadd_pd(h, _mm256_mul_pd(y, y), three_halves));
  if (_mm256_movemask_pd(odd)) y = _mm256_blendv_pd(y, _mm256_div_pd(_mm256_set1_pd(1.0), _mm256_sqrt_pd(r2)), odd);
  return y;
}

__attribute__((target("avx2,fma"))) void plain_near_row_avx2(const NearColumns& c, int m, const double* w, Vec3 x,
                                                             float* val, uint8_t* near) {
  const __m256d xx = _mm256_set1_pd(x.x), xy = _mm256_set1_pd(x.y), xz = _mm256_set1_pd(x.z);
  const size_t n4 = c.count / 4 * 4;
  for (size_t k = 0; k < n4; k += 4) {
    const __m256d ex = _mm256_sub_pd(xx, _mm256_loadu_pd(&c.cx[k]));
    const __m256d ey = _mm256_sub_pd(xy, _mm256_loadu_pd(&c.cy[k]));
    const __m256d ez = _mm256_sub_pd(xz, _mm256_loadu_pd(&c.cz[k]));
    // (ex^2 + ey^2) + ez^2 unfused: the decision matches is_near's.
    const __m256d d2 = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(ex, ex), _mm256_mul_pd(ey, ey)), _mm256_mul_pd(ez, ez));
    const int mask = _mm256_movemask_pd(_mm256_cmp_pd(d2, _mm256_loadu_pd(&c.near_r2[k]), _CMP_LT_OQ));
    for (int l = 0; l < 4; ++l) near[k + l] = (mask >> l) & 1;
    __m256d v = _mm256_setzero_pd();
    for (int q = 0; q < m; ++q) {
      const size_t i = size_t(q) * c.count + k;
      const __m256d dx = _mm256_sub_pd(xx, _mm256_loadu_pd(&c.px[i]));
      const __m256d dy = _mm256_sub_pd(xy, _mm256_loadu_pd(&c.py[i]));
      const __m256d dz = _mm256_sub_pd(xz, _mm256_loadu_pd(&c.pz[i]));
      const __m256d r2 = _mm256_fmadd_pd(dz, dz, _mm256_fmadd_pd(dy, dy, _mm256_mul_pd(dx, dx)));
      v = _mm256_fmadd_pd(_mm256_set1_pd(w[q]), inv_sqrt_pd(r2), v);
    }
    _mm_storeu_ps(&val[k], _mm256_cvtpd_ps(v));
  }
  plain_columns_scalar(c, m, w, x, n4, c.count, val, near);
}

const bool kHasAvx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#endif

}  // namespace

void plain_near_row(const NearColumns& c, int m, const double* weights, Vec3 x, float* val, uint8_t* near) {
#ifdef SOUPUV_X86_KERNELS
  if (kHasAvx2) return plain_near_row_avx2(c, m, weights, x, val, near);
#endif
  plain_columns_scalar(c, m, weights, x, 0, c.count, val, near);
}

}  // namespace soupuv::field::detail
