// Four closed-form triangle fields per AVX2 pass (see
// tracer_closed_form_batch.h). Lane by lane the arithmetic of
// closed_form_field (tracer_closed_form.cpp): the case split of the edge
// logs chosen per lane by blends, the solid angle from one atan2, its sign
// that of h (0 in the plane).
#include "tracer_closed_form_batch.h"

#include <cstdlib>

#include "tracer_vmath.h"

namespace soupuv::field::tracer {

namespace {

bool use_vector() {
#ifdef SOUPUV_TRACER_VMATH
  // TEMPORARY A/B switch (removed before the final commit).
  if (const char* s = std::getenv("SOUPUV_CLOSED_SCALAR"); s && *s == '1') return false;
  return vmath_supported();
#else
  return false;
#endif
}

#ifdef SOUPUV_TRACER_VMATH
__attribute__((target("avx2,fma"))) inline __m256d dot(const __m256d a[3], const __m256d b[3]) {
  return _mm256_fmadd_pd(a[0], b[0], _mm256_fmadd_pd(a[1], b[1], _mm256_mul_pd(a[2], b[2])));
}

__attribute__((target("avx2,fma"))) void load3(const double (*p)[ClosedFormBatch::kLanes], __m256d v[3]) {
  for (int c = 0; c < 3; ++c) v[c] = _mm256_load_pd(p[c]);
}

__attribute__((target("avx2,fma"))) void evaluate_avx2(const ClosedFormBatch::Lanes& L, int count, double* e) {
  __m256d r[3][3], R[3], n[3];
  for (int k = 0; k < 3; ++k) {
    load3(L.r[k], r[k]);
    R[k] = _mm256_sqrt_pd(dot(r[k], r[k]));
  }
  load3(L.n, n);
  const __m256d zero = _mm256_setzero_pd();
  // h exactly as closed_form_field rounds it (no FMA; this file is built
  // with -ffp-contract=off): its h == 0 decides the in-plane principal value
  // and its sign the side.
  const __m256d h = _mm256_sub_pd(
      zero, _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(r[0][0], n[0]), _mm256_mul_pd(r[0][1], n[1])),
                          _mm256_mul_pd(r[0][2], n[2])));
  const __m256d h2 = _mm256_mul_pd(h, h);
  __m256d s[3] = {zero, zero, zero};  // sum of f_i m_i
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    __m256d l[3], m[3];
    load3(L.l[i], l);
    load3(L.m[i], m);
    const __m256d sm = dot(r[i], l), sp = dot(r[j], l), t0 = dot(r[i], m);
    const __m256d len = _mm256_load_pd(L.len[i]);
    // Case sm < 0 < sp (the foot of x inside the edge): both factors sum
    // positive terms; the squared distance to the edge's line floored.
    const __m256d plus_j = _mm256_add_pd(R[j], sp), minus_i = _mm256_sub_pd(R[i], sm);
    __m256d num = _mm256_mul_pd(plus_j, minus_i);
    __m256d den = _mm256_max_pd(_mm256_fmadd_pd(t0, t0, h2), _mm256_mul_pd(_mm256_set1_pd(1e-28), _mm256_mul_pd(len, len)));
    const __m256d before = _mm256_cmp_pd(sp, zero, _CMP_LE_OQ);  // sp <= 0: the edge lies before x
    num = _mm256_blendv_pd(num, minus_i, before);
    den = _mm256_blendv_pd(den, _mm256_sub_pd(R[j], sp), before);
    const __m256d after = _mm256_cmp_pd(sm, zero, _CMP_GE_OQ);  // sm >= 0: the edge lies after x (checked first)
    num = _mm256_blendv_pd(num, plus_j, after);
    den = _mm256_blendv_pd(den, _mm256_add_pd(R[i], sm), after);
    const __m256d f = vlog(_mm256_div_pd(num, den));
    for (int c = 0; c < 3; ++c) s[c] = _mm256_fmadd_pd(f, m[c], s[c]);
  }
  // Solid angle: |det[r0 r1 r2]| over R0 R1 R2 + (r0.r1) R2 + (r0.r2) R1 + (r1.r2) R0.
  const __m256d c12[3] = {
      _mm256_fmsub_pd(r[1][1], r[2][2], _mm256_mul_pd(r[1][2], r[2][1])),
      _mm256_fmsub_pd(r[1][2], r[2][0], _mm256_mul_pd(r[1][0], r[2][2])),
      _mm256_fmsub_pd(r[1][0], r[2][1], _mm256_mul_pd(r[1][1], r[2][0])),
  };
  const __m256d sign = _mm256_set1_pd(-0.0);
  const __m256d det = _mm256_andnot_pd(sign, dot(r[0], c12));
  __m256d den = _mm256_mul_pd(_mm256_mul_pd(R[0], R[1]), R[2]);
  den = _mm256_fmadd_pd(dot(r[0], r[1]), R[2], den);
  den = _mm256_fmadd_pd(dot(r[0], r[2]), R[1], den);
  den = _mm256_fmadd_pd(dot(r[1], r[2]), R[0], den);
  __m256d omega = _mm256_mul_pd(_mm256_set1_pd(2.0), vatan2(det, den));
  // Signed by the side of the plane; 0 in it (h == 0), whatever atan2 gave.
  omega = _mm256_and_pd(omega, _mm256_cmp_pd(h, zero, _CMP_NEQ_UQ));
  omega = _mm256_xor_pd(omega, _mm256_and_pd(h, sign));
  // Lanes past count hold an earlier triangle: masked out (NaN included).
  const __m256d valid = _mm256_castsi256_pd(
      _mm256_cmpgt_epi64(_mm256_set1_epi64x(count), _mm256_setr_epi64x(0, 1, 2, 3)));
  const __m256d density = _mm256_load_pd(L.density);
  alignas(32) double out[4];
  for (int c = 0; c < 3; ++c) {
    const __m256d g = _mm256_and_pd(_mm256_mul_pd(density, _mm256_fmadd_pd(omega, n[c], s[c])), valid);
    _mm256_store_pd(out, g);
    e[c] += (out[0] + out[1]) + (out[2] + out[3]);
  }
}
#endif

}  // namespace

const bool ClosedFormBatch::vector_ = use_vector();

ClosedFormBatch::ClosedFormBatch() {
  // Lanes a partial pass leaves unused are evaluated and masked: start them
  // as a harmless triangle (unit right triangle one unit below x) rather
  // than zeros, whose 0/0 would take the log's slow path.
  const TriangleFrame f = triangle_frame({0, 0, -1}, {1, 0, -1}, {0, 1, -1});
  for (int l = 0; l < kLanes; ++l) {
    for (int k = 0; k < 3; ++k) {
      set(&lanes_.r[k][0][0], f.v[k], l);
      set(&lanes_.l[k][0][0], f.l[k], l);
      set(&lanes_.m[k][0][0], f.m[k], l);
      lanes_.len[k][l] = f.len[k];
    }
    set(&lanes_.n[0][0], f.n, l);
    lanes_.density[l] = 0;
  }
}

void ClosedFormBatch::evaluate(double* e) {
#ifdef SOUPUV_TRACER_VMATH
  evaluate_avx2(lanes_, count_, e);
#else
  (void)e;
#endif
  count_ = 0;
}

}  // namespace soupuv::field::tracer
