// Single-precision near-field kernels of the tracer (see tracer_kernels.h).
//
// AVX2+FMA (8 float lanes) when the CPU has them, checked once at run time;
// otherwise a scalar loop with the same arithmetic (also what non-x86 builds
// run). 1/r comes from the approximate rsqrt (12 bits) refined by one Newton
// step (~23 bits): cheaper than sqrt and a division, and float-accurate.
#include "tracer_kernels.h"

#include <cmath>

#include "soupuv/field/quadrature.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define SOUPUV_X86_KERNELS 1
#endif

namespace soupuv::field::tracer {

namespace {

// Near candidates are chosen with a little slack so float rounding cannot
// miss a triangle the caller's double test calls near.
constexpr float kNearSlack = 1.0f + 1e-4f;

void span_field_scalar(const float* block, int groups, int m, const float x[3], double* e, uint8_t* near_bits,
                       const uint8_t* lane_masks) {
  const int gf = group_floats(m);
  float ex = 0, ey = 0, ez = 0;
  for (int g = 0; g < groups; ++g) {
    const float* b = block + static_cast<size_t>(g) * gf;
    uint8_t bits = 0;
    for (int l = 0; l < kLanes; ++l) {
      const float dx = x[0] - b[l], dy = x[1] - b[8 + l], dz = x[2] - b[16 + l];
      if (dx * dx + dy * dy + dz * dz < b[24 + l] * kNearSlack) bits |= uint8_t(1u << l);
    }
    bits &= lane_masks[g];
    near_bits[g] = bits;
    const unsigned skip = bits | uint8_t(~lane_masks[g]);
    if (skip == 0xff) continue;
    for (int i = 0; i < m; ++i) {
      const float* p = b + 32 + 32 * i;
      for (int l = 0; l < kLanes; ++l) {
        if (skip & (1u << l)) continue;
        const float dx = x[0] - p[l], dy = x[1] - p[8 + l], dz = x[2] - p[16 + l];
        const float inv = 1.0f / std::sqrt(dx * dx + dy * dy + dz * dz);
        const float w3 = (p[24 + l] / kChargeScale) * inv * inv * inv;
        ex += w3 * dx;
        ey += w3 * dy;
        ez += w3 * dz;
      }
    }
  }
  e[0] += ex;
  e[1] += ey;
  e[2] += ez;
}

void rule_field_batch_scalar(const FloatRule& rule, const RuleTriangles& t, double* e) {
  for (int j = 0; j < t.count; ++j) {
    float ex = 0, ey = 0, ez = 0;
    for (int k = 0; k < rule.points; ++k) {
      const float px = rule.l0[k] * t.ax[j] + rule.l1[k] * t.bx[j] + rule.l2[k] * t.cx[j];
      const float py = rule.l0[k] * t.ay[j] + rule.l1[k] * t.by[j] + rule.l2[k] * t.cy[j];
      const float pz = rule.l0[k] * t.az[j] + rule.l1[k] * t.bz[j] + rule.l2[k] * t.cz[j];
      const float inv = 1.0f / std::sqrt(px * px + py * py + pz * pz);
      const float w3 = t.q[j] * rule.w[k] * inv * inv * inv;
      // The point is at p relative to the evaluation point: the field points away from it.
      ex -= w3 * px;
      ey -= w3 * py;
      ez -= w3 * pz;
    }
    e[0] += ex;
    e[1] += ey;
    e[2] += ez;
  }
}

#ifdef SOUPUV_X86_KERNELS
__attribute__((target("avx2,fma"))) inline __m256 inv_sqrt(__m256 r2) {
  const __m256 y = _mm256_rsqrt_ps(r2);
  // Newton: y (1.5 - 0.5 r2 y^2)
  const __m256 t = _mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(0.5f), r2), _mm256_mul_ps(y, y));
  return _mm256_mul_ps(y, _mm256_sub_ps(_mm256_set1_ps(1.5f), t));
}

// 2 / sqrt(r2): Newton's y (3 - r2 y^2) without its factor 1/2, which the
// block charges carry instead (cubed: kChargeScale). Exactly twice
// inv_sqrt(r2): one multiply less.
__attribute__((target("avx2,fma"))) inline __m256 inv_sqrt_twice(__m256 r2) {
  const __m256 y = _mm256_rsqrt_ps(r2);
  return _mm256_mul_ps(y, _mm256_fnmadd_ps(r2, _mm256_mul_ps(y, y), _mm256_set1_ps(3.0f)));
}

__attribute__((target("avx2,fma"))) double hsum(__m256 v) {
  alignas(32) float s[8];
  _mm256_store_ps(s, v);
  return (double(s[0]) + s[1] + s[2] + s[3]) + (double(s[4]) + s[5] + s[6] + s[7]);
}

__attribute__((target("avx2,fma"))) void span_field_avx2(const float* block, int groups, int m, const float x[3],
                                                          double* e, uint8_t* near_bits, const uint8_t* lane_masks) {
  const int gf = group_floats(m);
  const __m256 X = _mm256_set1_ps(x[0]), Y = _mm256_set1_ps(x[1]), Z = _mm256_set1_ps(x[2]);
  const __m256 slack = _mm256_set1_ps(kNearSlack);
  const __m256i lane_bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
  __m256 ex = _mm256_setzero_ps(), ey = ex, ez = ex;
  for (int g = 0; g < groups; ++g) {
    const float* b = block + static_cast<size_t>(g) * gf;
    __m256 dx = _mm256_sub_ps(X, _mm256_loadu_ps(b));
    __m256 dy = _mm256_sub_ps(Y, _mm256_loadu_ps(b + 8));
    __m256 dz = _mm256_sub_ps(Z, _mm256_loadu_ps(b + 16));
    __m256 r2 = _mm256_fmadd_ps(dz, dz, _mm256_fmadd_ps(dy, dy, _mm256_mul_ps(dx, dx)));
    // The lane mask as all-ones lanes: bit l of the mask set -> lane l selected.
    const __m256i sel = _mm256_and_si256(_mm256_set1_epi32(lane_masks[g]), lane_bit);
    const __m256 selected = _mm256_castsi256_ps(_mm256_cmpeq_epi32(sel, lane_bit));
    const __m256 near =
        _mm256_and_ps(selected, _mm256_cmp_ps(r2, _mm256_mul_ps(_mm256_loadu_ps(b + 24), slack), _CMP_LT_OQ));
    near_bits[g] = static_cast<uint8_t>(_mm256_movemask_ps(near));
    // Only selected lanes that are not near candidates add their charges.
    // Next to the surface some groups have none left (3-6 % of the groups
    // a trace visits): skip their points.
    const __m256 take = _mm256_andnot_ps(near, selected);
    if (_mm256_movemask_ps(take) == 0) continue;
    for (int i = 0; i < m; ++i) {
      const float* p = b + 32 + 32 * i;
      dx = _mm256_sub_ps(X, _mm256_loadu_ps(p));
      dy = _mm256_sub_ps(Y, _mm256_loadu_ps(p + 8));
      dz = _mm256_sub_ps(Z, _mm256_loadu_ps(p + 16));
      r2 = _mm256_fmadd_ps(dz, dz, _mm256_fmadd_ps(dy, dy, _mm256_mul_ps(dx, dx)));
      const __m256 inv2 = inv_sqrt_twice(r2);
      // Near candidates get charge 0 here (the caller evaluates them).
      const __m256 q = _mm256_and_ps(take, _mm256_loadu_ps(p + 24));
      // (q / 8) (2 / r)^3 = q / r^3, exactly as with the plain Newton step.
      const __m256 w3 = _mm256_mul_ps(_mm256_mul_ps(q, inv2), _mm256_mul_ps(inv2, inv2));
      ex = _mm256_fmadd_ps(w3, dx, ex);
      ey = _mm256_fmadd_ps(w3, dy, ey);
      ez = _mm256_fmadd_ps(w3, dz, ez);
    }
  }
  e[0] += hsum(ex);
  e[1] += hsum(ey);
  e[2] += hsum(ez);
}

// Adds the 8 float lanes of v to the 4 double lanes of acc.
__attribute__((target("avx2,fma"))) inline __m256d add_wide(__m256d acc, __m256 v) {
  acc = _mm256_add_pd(acc, _mm256_cvtps_pd(_mm256_castps256_ps128(v)));
  return _mm256_add_pd(acc, _mm256_cvtps_pd(_mm256_extractf128_ps(v, 1)));
}

__attribute__((target("avx2,fma"))) void rule_field_batch_avx2(const FloatRule& rule, const RuleTriangles& t,
                                                                double* e) {
  __m256d sx = _mm256_setzero_pd(), sy = sx, sz = sx;
  for (int g = 0; g < t.count; g += kLanes) {
    const __m256 ax = _mm256_load_ps(t.ax + g), ay = _mm256_load_ps(t.ay + g), az = _mm256_load_ps(t.az + g);
    const __m256 bx = _mm256_load_ps(t.bx + g), by = _mm256_load_ps(t.by + g), bz = _mm256_load_ps(t.bz + g);
    const __m256 cx = _mm256_load_ps(t.cx + g), cy = _mm256_load_ps(t.cy + g), cz = _mm256_load_ps(t.cz + g);
    const __m256 q = _mm256_load_ps(t.q + g);
    __m256 ex = _mm256_setzero_ps(), ey = ex, ez = ex;
    for (int k = 0; k < rule.points; ++k) {
      const __m256 l0 = _mm256_set1_ps(rule.l0[k]), l1 = _mm256_set1_ps(rule.l1[k]), l2 = _mm256_set1_ps(rule.l2[k]);
      const __m256 px = _mm256_fmadd_ps(l2, cx, _mm256_fmadd_ps(l1, bx, _mm256_mul_ps(l0, ax)));
      const __m256 py = _mm256_fmadd_ps(l2, cy, _mm256_fmadd_ps(l1, by, _mm256_mul_ps(l0, ay)));
      const __m256 pz = _mm256_fmadd_ps(l2, cz, _mm256_fmadd_ps(l1, bz, _mm256_mul_ps(l0, az)));
      const __m256 r2 = _mm256_fmadd_ps(pz, pz, _mm256_fmadd_ps(py, py, _mm256_mul_ps(px, px)));
      const __m256 inv = inv_sqrt(r2);
      const __m256 qw = _mm256_mul_ps(q, _mm256_set1_ps(rule.w[k]));
      const __m256 w3 = _mm256_mul_ps(_mm256_mul_ps(qw, inv), _mm256_mul_ps(inv, inv));
      ex = _mm256_fnmadd_ps(w3, px, ex);
      ey = _mm256_fnmadd_ps(w3, py, ey);
      ez = _mm256_fnmadd_ps(w3, pz, ez);
    }
    sx = add_wide(sx, ex);
    sy = add_wide(sy, ey);
    sz = add_wide(sz, ez);
  }
  alignas(32) double d[4];
  _mm256_store_pd(d, sx);
  e[0] += (d[0] + d[1]) + (d[2] + d[3]);
  _mm256_store_pd(d, sy);
  e[1] += (d[0] + d[1]) + (d[2] + d[3]);
  _mm256_store_pd(d, sz);
  e[2] += (d[0] + d[1]) + (d[2] + d[3]);
}

const bool kHasAvx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#endif

FloatRule make_rule(const std::vector<std::array<double, 3>>& points, const std::vector<double>& weights) {
  FloatRule r;
  r.points = static_cast<int>(weights.size());
  for (int k = 0; k < r.points; ++k) {
    r.l0[k] = static_cast<float>(points[k][0]);
    r.l1[k] = static_cast<float>(points[k][1]);
    r.l2[k] = static_cast<float>(points[k][2]);
    r.w[k] = static_cast<float>(weights[k]);
  }
  return r;
}

}  // namespace

void span_field(const float* block, int groups, int m, const float x[3], double* e, uint8_t* near_bits,
                const uint8_t* lane_masks) {
#ifdef SOUPUV_X86_KERNELS
  if (kHasAvx2) return span_field_avx2(block, groups, m, x, e, near_bits, lane_masks);
#endif
  span_field_scalar(block, groups, m, x, e, near_bits, lane_masks);
}

void rule_field_batch(const FloatRule& rule, RuleTriangles& tri, double* e) {
  if (tri.count == 0) return;
  // Padding lanes: no charge, vertices on the unit axes (a rule point is then
  // never at the origin, and 0 * finite stays 0).
  for (int j = tri.count; j % kLanes != 0; ++j) {
    tri.ax[j] = 1; tri.ay[j] = 0; tri.az[j] = 0;
    tri.bx[j] = 0; tri.by[j] = 1; tri.bz[j] = 0;
    tri.cx[j] = 0; tri.cy[j] = 0; tri.cz[j] = 1;
    tri.q[j] = 0;
  }
#ifdef SOUPUV_X86_KERNELS
  if (kHasAvx2) rule_field_batch_avx2(rule, tri, e);
  else rule_field_batch_scalar(rule, tri, e);
#else
  rule_field_batch_scalar(rule, tri, e);
#endif
  tri.count = 0;
}

const FloatRule& degree6_rule() {
  static const FloatRule rule = [] {
    const TriangleRule& r = triangle_rule(6);
    return make_rule(r.points, r.weights);
  }();
  return rule;
}

const FloatRule& degree6_children_rule() {
  // Child triangles by their corners' barycentric coordinates in the parent
  // (a, b, c; ab, bc, ca the edge midpoints).
  static const FloatRule rule = [] {
    using B3 = std::array<double, 3>;
    const B3 a{1, 0, 0}, b{0, 1, 0}, c{0, 0, 1}, ab{0.5, 0.5, 0}, bc{0, 0.5, 0.5}, ca{0.5, 0, 0.5};
    const std::array<std::array<B3, 3>, 4> children{{{a, ab, ca}, {ab, b, bc}, {ca, bc, c}, {bc, ca, ab}}};
    const TriangleRule& r = triangle_rule(6);
    std::vector<B3> points;
    std::vector<double> weights;
    for (const auto& ch : children)
      for (size_t k = 0; k < r.weights.size(); ++k) {
        B3 p{0, 0, 0};
        for (int v = 0; v < 3; ++v)
          for (int d = 0; d < 3; ++d) p[d] += r.points[k][v] * ch[v][d];
        points.push_back(p);
        weights.push_back(0.25 * r.weights[k]);
      }
    return make_rule(points, weights);
  }();
  return rule;
}

}  // namespace soupuv::field::tracer
