// Four closed-form triangle fields per AVX2 pass (see
// tracer_closed_form_batch.h). Lane by lane the arithmetic of
// closed_form_field (tracer_closed_form.cpp): the case split of the edge
// logs chosen per lane by blends, the solid angle from one atan2, its sign
// that of h (0 in the plane).
#include "tracer_closed_form_batch.h"

#include <algorithm>

#include "tracer_vmath.h"

namespace soupuv::field::tracer {

namespace {

bool use_vector() {
#ifdef SOUPUV_TRACER_VMATH
  return vmath_supported();
#else
  return false;
#endif
}

#ifdef SOUPUV_TRACER_VMATH
__attribute__((target("avx2,fma"))) inline __m256d dot(const __m256d a[3], const __m256d b[3]) {
  return _mm256_fmadd_pd(a[0], b[0], _mm256_fmadd_pd(a[1], b[1], _mm256_mul_pd(a[2], b[2])));
}

// One double per lane, `get` of that lane's frame.
template <class Get>
__attribute__((target("avx2,fma"))) inline __m256d lanes(const TriangleFrame* const f[4], Get get) {
  return _mm256_setr_pd(get(*f[0]), get(*f[1]), get(*f[2]), get(*f[3]));
}
// The same for a Vec3 `get`, one vector per component.
template <class Get>
__attribute__((target("avx2,fma"))) inline void lanes3(const TriangleFrame* const f[4], Get get, __m256d v[3]) {
  v[0] = lanes(f, [&](const TriangleFrame& t) { return get(t).x; });
  v[1] = lanes(f, [&](const TriangleFrame& t) { return get(t).y; });
  v[2] = lanes(f, [&](const TriangleFrame& t) { return get(t).z; });
}

// Edge i's log term per lane (the case split of closed_form_field chosen
// by blends) and its in-plane distance t0; r[k] = v[k] - x, R[k] = |r[k]|,
// l and m edge i's direction and outward normal, h2 = h^2.
__attribute__((target("avx2,fma"))) inline __m256d edge_log(const TriangleFrame* const f[4], const __m256d r[3][3],
                                                             const __m256d R[3], const __m256d l[3],
                                                             const __m256d m[3], __m256d h2, int i, __m256d& t0) {
  const int j = (i + 1) % 3;
  const __m256d zero = _mm256_setzero_pd();
  const __m256d sm = dot(r[i], l), sp = dot(r[j], l);
  t0 = dot(r[i], m);
  const __m256d len = lanes(f, [i](const TriangleFrame& t) { return t.len[i]; });
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
  return vlog_ratio(num, den);
}

// |solid angle| per lane: 2 atan2(|det[r0 r1 r2]|, R0 R1 R2 + (r0.r1) R2 + (r0.r2) R1 + (r1.r2) R0).
__attribute__((target("avx2,fma"))) inline __m256d solid_angle(const __m256d r[3][3], const __m256d R[3]) {
  const __m256d c12[3] = {
      _mm256_fmsub_pd(r[1][1], r[2][2], _mm256_mul_pd(r[1][2], r[2][1])),
      _mm256_fmsub_pd(r[1][2], r[2][0], _mm256_mul_pd(r[1][0], r[2][2])),
      _mm256_fmsub_pd(r[1][0], r[2][1], _mm256_mul_pd(r[1][1], r[2][0])),
  };
  const __m256d det = _mm256_andnot_pd(_mm256_set1_pd(-0.0), dot(r[0], c12));
  __m256d den = _mm256_mul_pd(_mm256_mul_pd(R[0], R[1]), R[2]);
  den = _mm256_fmadd_pd(dot(r[0], r[1]), R[2], den);
  den = _mm256_fmadd_pd(dot(r[0], r[2]), R[1], den);
  den = _mm256_fmadd_pd(dot(r[1], r[2]), R[0], den);
  return _mm256_mul_pd(_mm256_set1_pd(2.0), vatan2(det, den));
}

// r[k] = v[k] - x per lane, R[k] = |r[k]|, and h = the signed height of x
// over the plane, rounded as closed_form_field rounds it (no FMA; this file
// is built with -ffp-contract=off): h == 0 decides the in-plane case.
__attribute__((target("avx2,fma"))) inline __m256d relative_corners(const TriangleFrame* const f[4], const __m256d x[3],
                                                                     __m256d r[3][3], __m256d R[3], __m256d n[3]) {
  for (int k = 0; k < 3; ++k) {
    lanes3(f, [k](const TriangleFrame& t) { return t.v[k]; }, r[k]);
    for (int c = 0; c < 3; ++c) r[k][c] = _mm256_sub_pd(r[k][c], x[c]);
    R[k] = _mm256_sqrt_pd(dot(r[k], r[k]));
  }
  lanes3(f, [](const TriangleFrame& t) { return t.n; }, n);
  return _mm256_sub_pd(_mm256_setzero_pd(),
                       _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(r[0][0], n[0]), _mm256_mul_pd(r[0][1], n[1])),
                                     _mm256_mul_pd(r[0][2], n[2])));
}

// Four potentials at one point x (closed_form_potential lane by lane).
__attribute__((target("avx2,fma"))) void potentials_avx2(const TriangleFrame* const f[4], Vec3 xp, double* out) {
  const __m256d x[3] = {_mm256_set1_pd(xp.x), _mm256_set1_pd(xp.y), _mm256_set1_pd(xp.z)};
  __m256d r[3][3], R[3], n[3];
  const __m256d h = relative_corners(f, x, r, R, n);
  const __m256d h2 = _mm256_mul_pd(h, h);
  __m256d sum_tf = _mm256_setzero_pd();
  for (int i = 0; i < 3; ++i) {
    __m256d l[3], m[3], t0;
    lanes3(f, [i](const TriangleFrame& t) { return t.l[i]; }, l);
    lanes3(f, [i](const TriangleFrame& t) { return t.m[i]; }, m);
    const __m256d log_term = edge_log(f, r, R, l, m, h2, i, t0);
    sum_tf = _mm256_add_pd(sum_tf, _mm256_mul_pd(t0, log_term));
  }
  // |h| times the solid angle; 0 in the plane (h == 0), whatever atan2 gave.
  const __m256d ah = _mm256_andnot_pd(_mm256_set1_pd(-0.0), h);
  __m256d out_of_plane = _mm256_mul_pd(ah, solid_angle(r, R));
  out_of_plane = _mm256_and_pd(out_of_plane, _mm256_cmp_pd(h, _mm256_setzero_pd(), _CMP_NEQ_UQ));
  _mm256_storeu_pd(out, _mm256_sub_pd(sum_tf, out_of_plane));
}

__attribute__((target("avx2,fma"))) void evaluate_avx2(const TriangleFrame* const f[4], const Vec3* xs,
                                                       const double* densities, int count, double* e) {
  const __m256d x[3] = {_mm256_setr_pd(xs[0].x, xs[1].x, xs[2].x, xs[3].x),
                        _mm256_setr_pd(xs[0].y, xs[1].y, xs[2].y, xs[3].y),
                        _mm256_setr_pd(xs[0].z, xs[1].z, xs[2].z, xs[3].z)};
  __m256d r[3][3], R[3], n[3];
  const __m256d zero = _mm256_setzero_pd();
  const __m256d h = relative_corners(f, x, r, R, n);
  const __m256d h2 = _mm256_mul_pd(h, h);
  __m256d s[3] = {zero, zero, zero};  // sum of f_i m_i
  for (int i = 0; i < 3; ++i) {
    __m256d l[3], m[3];
    lanes3(f, [i](const TriangleFrame& t) { return t.l[i]; }, l);
    lanes3(f, [i](const TriangleFrame& t) { return t.m[i]; }, m);
    __m256d t0;
    const __m256d log_term = edge_log(f, r, R, l, m, h2, i, t0);
    for (int c = 0; c < 3; ++c) s[c] = _mm256_fmadd_pd(log_term, m[c], s[c]);
  }
  const __m256d sign = _mm256_set1_pd(-0.0);
  __m256d omega = solid_angle(r, R);
  // Signed by the side of the plane; 0 in it (h == 0), whatever atan2 gave.
  omega = _mm256_and_pd(omega, _mm256_cmp_pd(h, zero, _CMP_NEQ_UQ));
  omega = _mm256_xor_pd(omega, _mm256_and_pd(h, sign));
  // Lanes past count repeat lane 0: masked out (NaN included).
  const __m256d valid = _mm256_castsi256_pd(
      _mm256_cmpgt_epi64(_mm256_set1_epi64x(count), _mm256_setr_epi64x(0, 1, 2, 3)));
  const __m256d density = _mm256_loadu_pd(densities);
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

void closed_form_potentials(const TriangleFrame* const* frames, int count, Vec3 x, double* out) {
#ifdef SOUPUV_TRACER_VMATH
  static const bool vector = use_vector();
  if (vector) {
    int k = 0;
    for (; k + 4 <= count; k += 4) potentials_avx2(frames + k, x, out + k);
    if (k < count) {
      // The tail: lanes past count repeat the last frame, their values dropped.
      const TriangleFrame* f[4];
      double v[4];
      for (int l = 0; l < 4; ++l) f[l] = frames[std::min(k + l, count - 1)];
      potentials_avx2(f, x, v);
      for (int l = 0; k + l < count; ++l) out[k + l] = v[l];
    }
    return;
  }
#endif
  for (int k = 0; k < count; ++k) out[k] = closed_form_potential(*frames[k], x);
}

void ClosedFormBatch::evaluate(double* e) {
#ifdef SOUPUV_TRACER_VMATH
  // Lanes past count_ repeat lane 0 (their fields are masked out).
  for (int l = count_; l < kLanes; ++l) {
    frame_[l] = frame_[0];
    x_[l] = x_[0];
  }
  evaluate_avx2(frame_, x_, density_, count_, e);
#else
  (void)e;
#endif
  count_ = 0;
}

}  // namespace soupuv::field::tracer
