// Double-precision log and atan2 on four AVX2 lanes, for the tracer's
// vectorised closed form (tracer_closed_form_batch.cpp). Internal to
// core/src/field.
//
//   __m256d y = tracer::vlog(a);        // a > 0
//   __m256d z = tracer::vlog_ratio(n, d);  // log(n / d), n, d > 0
//   __m256d t = tracer::vatan2(y, x);   // finite y, x
//
// Accuracy: a few units in the last place of the result (tested against
// std::log / std::atan2 in tests/core/field/tracer_vmath_test.cpp), where the
// closed form needs ~1e-13 relative.
//  - vlog: a = 2^e m with m in [sqrt(1/2), sqrt(2)); log m = 2 atanh(s) with
//    s = (m - 1) / (m + 1), |s| <= 0.1716, as the odd series
//    2 (s + s^3/3 + ... + s^19/19): the first left-out term is below 2.3e-17
//    relative. m - 1 is exact (Sterbenz), so log a keeps its relative accuracy
//    next to a = 1. e ln 2 is added as e ln2_hi (exact: ln2_hi has 32
//    significant bits) plus e ln2_lo. vlog_ratio(n, d) takes s from the
//    two mantissas, one division in all (see there). Lanes outside the normal positive range
//    (0, subnormal, negative, inf, NaN) are recomputed by std::log, so every
//    edge case (a point on a vertex gives log(inf)) is std::log's.
//  - vatan2 (one division): reduced to a = min(|x|,|y|) / max(|x|,|y|) in [0, 1], then to
//    the nearest c_j = tan(j pi/16), j = 0..4: atan a = atan c_j +
//    atan((a - c_j) / (1 + a c_j)) with |t| <= tan(pi/32) = 0.0985, where the
//    series t - t^3/3 + ... - t^15/15 leaves out below 7.6e-18 relative. Then
//    pi/2 - . when |y| > |x|, pi - . when x's sign bit is set, and y's sign.
//    atan2(0, 0) = 0 and atan2(0, -0) = pi as in std; not for inf or NaN.
#pragma once

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>

#include <cfloat>
#include <cmath>
#define SOUPUV_TRACER_VMATH 1

namespace soupuv::field::tracer {

// Whether this CPU runs the AVX2+FMA code (checked once).
bool vmath_supported();

namespace vmath_detail {

// atan reduction points: c_j = tan(j pi/16) rounded, off_j = atan(c_j) of that
// rounded value (so the two agree to rounding), split points between c_j and
// c_{j+1} at tan((2j+1) pi/32).
struct AtanTable {
  double c[5], off[5], split[4];
};
AtanTable make_atan_table();
inline const AtanTable kAtan = make_atan_table();

// ln 2 = kLn2Hi + kLn2Lo; kLn2Hi has 32 significant bits, so e * kLn2Hi is
// exact for any exponent e of a double.
constexpr double kLn2Hi = 0x1.62e42feep-1;
constexpr double kLn2Lo = static_cast<double>(0.693147180559945309417232121458176568L - 0x1.62e42feep-1L);

// a = 2^e m with m in [1, 2), for positive normal a (other lanes: garbage).
__attribute__((target("avx2,fma"))) inline void split_exponent(__m256d a, __m256d& m, __m256d& e) {
  const __m256i bits = _mm256_castpd_si256(a);
  m = _mm256_castsi256_pd(_mm256_or_si256(_mm256_and_si256(bits, _mm256_set1_epi64x(0x000FFFFFFFFFFFFFLL)),
                                          _mm256_set1_epi64x(0x3FF0000000000000LL)));
  // The biased exponent (sign bit 0) as a double: placed in the mantissa of
  // 2^52, minus 2^52 and the bias.
  e = _mm256_sub_pd(
      _mm256_castsi256_pd(_mm256_or_si256(_mm256_srli_epi64(bits, 52), _mm256_set1_epi64x(0x4330000000000000LL))),
      _mm256_set1_pd(4503599627370496.0 + 1023.0));
}

// e ln 2 + log((1 + s) / (1 - s)), |s| <= 0.1716.
__attribute__((target("avx2,fma"))) inline __m256d log_from(__m256d e, __m256d s) {
  const __m256d z = _mm256_mul_pd(s, s);
  // 2 (1 + z/3 + z^2/5 + ... + z^9/19), Horner from the small end.
  __m256d p = _mm256_set1_pd(2.0 / 19);
  p = _mm256_fmadd_pd(p, z, _mm256_set1_pd(2.0 / 17));
  p = _mm256_fmadd_pd(p, z, _mm256_set1_pd(2.0 / 15));
  p = _mm256_fmadd_pd(p, z, _mm256_set1_pd(2.0 / 13));
  p = _mm256_fmadd_pd(p, z, _mm256_set1_pd(2.0 / 11));
  p = _mm256_fmadd_pd(p, z, _mm256_set1_pd(2.0 / 9));
  p = _mm256_fmadd_pd(p, z, _mm256_set1_pd(2.0 / 7));
  p = _mm256_fmadd_pd(p, z, _mm256_set1_pd(2.0 / 5));
  p = _mm256_fmadd_pd(p, z, _mm256_set1_pd(2.0 / 3));
  // 2s + s z (...): the leading 2s exact, the rest a small correction.
  const __m256d log_m = _mm256_fmadd_pd(_mm256_mul_pd(s, z), p, _mm256_add_pd(s, s));
  return _mm256_fmadd_pd(e, _mm256_set1_pd(kLn2Hi), _mm256_fmadd_pd(e, _mm256_set1_pd(kLn2Lo), log_m));
}

// Lanes of a outside the positive normal range.
__attribute__((target("avx2,fma"))) inline int abnormal(__m256d a) {
  const __m256d normal = _mm256_and_pd(_mm256_cmp_pd(a, _mm256_set1_pd(DBL_MIN), _CMP_GE_OQ),
                                       _mm256_cmp_pd(a, _mm256_set1_pd(DBL_MAX), _CMP_LE_OQ));
  return ~_mm256_movemask_pd(normal) & 0xF;
}

}  // namespace vmath_detail

__attribute__((target("avx2,fma"))) inline __m256d vlog(__m256d a) {
  using namespace vmath_detail;
  const __m256d one = _mm256_set1_pd(1.0);
  __m256d m, e;
  split_exponent(a, m, e);
  const __m256d big = _mm256_cmp_pd(m, _mm256_set1_pd(M_SQRT2), _CMP_GT_OQ);
  m = _mm256_blendv_pd(m, _mm256_mul_pd(m, _mm256_set1_pd(0.5)), big);
  e = _mm256_add_pd(e, _mm256_and_pd(big, one));
  __m256d r = log_from(e, _mm256_div_pd(_mm256_sub_pd(m, one), _mm256_add_pd(m, one)));
  if (const int bad = abnormal(a)) {
    alignas(32) double in[4], out[4];
    _mm256_store_pd(in, a);
    _mm256_store_pd(out, r);
    for (int l = 0; l < 4; ++l)
      if (bad & (1 << l)) out[l] = std::log(in[l]);
    r = _mm256_load_pd(out);
  }
  return r;
}

// log(num / den) with one division: num = 2^a mn, den = 2^b md, the
// mantissa ratio brought into [sqrt(1/2), sqrt(2)] by doubling mn or md,
// and s = (mn - md) / (mn + md) (mn - md exact by Sterbenz). No rounding of
// num / den first, so next to a ratio of 1 it is more accurate than
// std::log(num / den). Lanes where num or den is not a positive normal
// double: std::log(num / den).
__attribute__((target("avx2,fma"))) inline __m256d vlog_ratio(__m256d num, __m256d den) {
  using namespace vmath_detail;
  const __m256d one = _mm256_set1_pd(1.0), two = _mm256_set1_pd(2.0), sqrt2 = _mm256_set1_pd(M_SQRT2);
  __m256d mn, en, md, ed;
  split_exponent(num, mn, en);
  split_exponent(den, md, ed);
  __m256d e = _mm256_sub_pd(en, ed);
  const __m256d big = _mm256_cmp_pd(mn, _mm256_mul_pd(sqrt2, md), _CMP_GT_OQ);
  const __m256d small = _mm256_cmp_pd(_mm256_mul_pd(sqrt2, mn), md, _CMP_LT_OQ);
  md = _mm256_blendv_pd(md, _mm256_mul_pd(md, two), big);
  mn = _mm256_blendv_pd(mn, _mm256_mul_pd(mn, two), small);
  e = _mm256_add_pd(e, _mm256_sub_pd(_mm256_and_pd(big, one), _mm256_and_pd(small, one)));
  __m256d r = log_from(e, _mm256_div_pd(_mm256_sub_pd(mn, md), _mm256_add_pd(mn, md)));
  if (const int bad = abnormal(num) | abnormal(den)) {
    alignas(32) double n[4], d[4], out[4];
    _mm256_store_pd(n, num);
    _mm256_store_pd(d, den);
    _mm256_store_pd(out, r);
    for (int l = 0; l < 4; ++l)
      if (bad & (1 << l)) out[l] = std::log(n[l] / d[l]);
    r = _mm256_load_pd(out);
  }
  return r;
}

__attribute__((target("avx2,fma"))) inline __m256d vatan2(__m256d y, __m256d x) {
  using namespace vmath_detail;
  const __m256d sign = _mm256_set1_pd(-0.0);
  const __m256d ax = _mm256_andnot_pd(sign, x), ay = _mm256_andnot_pd(sign, y);
  const __m256d hi = _mm256_max_pd(ax, ay), lo = _mm256_min_pd(ax, ay);
  // a = lo / hi is never formed: a > split_j is lo > split_j hi, and
  // (a - c) / (1 + a c) = (lo - c hi) / (hi + c lo), one division.
  __m256d c = _mm256_setzero_pd(), off = _mm256_setzero_pd();
  for (int j = 0; j < 4; ++j) {
    const __m256d above = _mm256_cmp_pd(lo, _mm256_mul_pd(_mm256_set1_pd(kAtan.split[j]), hi), _CMP_GT_OQ);
    c = _mm256_blendv_pd(c, _mm256_set1_pd(kAtan.c[j + 1]), above);
    off = _mm256_blendv_pd(off, _mm256_set1_pd(kAtan.off[j + 1]), above);
  }
  // 0/0 (both zero) is NaN: masked to 0.
  const __m256d t = _mm256_and_pd(_mm256_div_pd(_mm256_fnmadd_pd(c, hi, lo), _mm256_fmadd_pd(c, lo, hi)),
                                  _mm256_cmp_pd(hi, _mm256_setzero_pd(), _CMP_NEQ_OQ));
  const __m256d t2 = _mm256_mul_pd(t, t);
  // t (1 - t^2/3 + ... - t^14/15).
  __m256d p = _mm256_set1_pd(-1.0 / 15);
  p = _mm256_fmadd_pd(p, t2, _mm256_set1_pd(1.0 / 13));
  p = _mm256_fmadd_pd(p, t2, _mm256_set1_pd(-1.0 / 11));
  p = _mm256_fmadd_pd(p, t2, _mm256_set1_pd(1.0 / 9));
  p = _mm256_fmadd_pd(p, t2, _mm256_set1_pd(-1.0 / 7));
  p = _mm256_fmadd_pd(p, t2, _mm256_set1_pd(1.0 / 5));
  p = _mm256_fmadd_pd(p, t2, _mm256_set1_pd(-1.0 / 3));
  const __m256d atan_t = _mm256_fmadd_pd(_mm256_mul_pd(t, t2), p, t);
  __m256d th = _mm256_add_pd(off, atan_t);
  th = _mm256_blendv_pd(th, _mm256_sub_pd(_mm256_set1_pd(M_PI / 2), th), _mm256_cmp_pd(ay, ax, _CMP_GT_OQ));
  th = _mm256_blendv_pd(th, _mm256_sub_pd(_mm256_set1_pd(M_PI), th), x);  // blendv reads x's sign bit
  return _mm256_or_pd(th, _mm256_and_pd(y, sign));
}

}  // namespace soupuv::field::tracer
#endif
