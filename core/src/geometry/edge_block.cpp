#include "geometry/edge_block.h"

#include <immintrin.h>

#include <cstdlib>

namespace soupuv::geometry::detail {

namespace {

constexpr float kFar = 1e30f;  // padding: never near anything

void scalar_near_both(const std::vector<float>* c, const std::vector<float>* n, const std::vector<float>* v,
                      const uint32_t* corner, size_t k0, size_t k1, const float q[3], const float p[3], float r2,
                      bool with_prev, uint32_t min_corner, const CostBound* bound, std::vector<uint32_t>& out) {
  for (size_t k = k0; k < k1; ++k) {
    if (corner[k] < min_corner || corner[k] == UINT32_MAX) continue;
    const float dx = c[0][k] - q[0], dy = c[1][k] - q[1], dz = c[2][k] - q[2];
    const float dq = dx * dx + dy * dy + dz * dz;
    if (dq > r2) continue;
    const float ex = n[0][k] - p[0], ey = n[1][k] - p[1], ez = n[2][k] - p[2];
    const float dp = ex * ex + ey * ey + ez * ez;
    if (bound && dp <= r2 && !(dq + dp <= bound->query + bound->margin) &&
        !(dq + dp <= bound->per_corner[corner[k]] + bound->margin))
      continue;
    bool near = dp <= r2;
    if (!near && with_prev) {
      const float fx = v[0][k] - p[0], fy = v[1][k] - p[1], fz = v[2][k] - p[2];
      near = fx * fx + fy * fy + fz * fz <= r2;
    }
    if (near) out.push_back(uint32_t(k));
  }
}

__attribute__((target("avx2,fma"))) inline __m256 dist2(const float* x, const float* y, const float* z, size_t k,
                                                       __m256 px, __m256 py, __m256 pz) {
  const __m256 dx = _mm256_sub_ps(_mm256_loadu_ps(x + k), px);
  const __m256 dy = _mm256_sub_ps(_mm256_loadu_ps(y + k), py);
  const __m256 dz = _mm256_sub_ps(_mm256_loadu_ps(z + k), pz);
  return _mm256_fmadd_ps(dz, dz, _mm256_fmadd_ps(dy, dy, _mm256_mul_ps(dx, dx)));
}

__attribute__((target("avx2,fma"))) void avx2_near_both(const std::vector<float>* c, const std::vector<float>* n,
                                                        const std::vector<float>* v, const uint32_t* corner,
                                                        size_t k0, size_t k1, const float q[3], const float p[3],
                                                        float r2, bool with_prev, uint32_t min_corner,
                                                        const CostBound* bound, std::vector<uint32_t>& out) {
  // Unsigned corner >= min_corner as signed compares: both offset by 2^31.
  const __m256i bias = _mm256_set1_epi32(int(0x80000000u));
  const __m256i least = _mm256_xor_si256(_mm256_set1_epi32(int(min_corner)), bias);
  const __m256 qx = _mm256_set1_ps(q[0]), qy = _mm256_set1_ps(q[1]), qz = _mm256_set1_ps(q[2]);
  const __m256 px = _mm256_set1_ps(p[0]), py = _mm256_set1_ps(p[1]), pz = _mm256_set1_ps(p[2]);
  const __m256 reach = _mm256_set1_ps(r2);
  const __m256 query_bound = _mm256_set1_ps(bound ? bound->query + bound->margin : 0.0f);
  const __m256 margin = _mm256_set1_ps(bound ? bound->margin : 0.0f);
  for (size_t k = k0; k < k1; k += 8) {
    const __m256 dq = dist2(c[0].data(), c[1].data(), c[2].data(), k, qx, qy, qz);
    __m256 keep = _mm256_cmp_ps(dq, reach, _CMP_LE_OQ);
    if (!_mm256_movemask_ps(keep)) continue;
    const __m256i raw = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(corner + k));
    keep = _mm256_andnot_ps(_mm256_castsi256_ps(_mm256_cmpgt_epi32(least, _mm256_xor_si256(raw, bias))), keep);
    if (!_mm256_movemask_ps(keep)) continue;
    const __m256 dp = dist2(n[0].data(), n[1].data(), n[2].data(), k, px, py, pz);
    __m256 at_p = _mm256_cmp_ps(dp, reach, _CMP_LE_OQ);
    if (with_prev)
      at_p = _mm256_or_ps(at_p, _mm256_cmp_ps(dist2(v[0].data(), v[1].data(), v[2].data(), k, px, py, pz), reach,
                                              _CMP_LE_OQ));
    keep = _mm256_and_ps(keep, at_p);
    if (!_mm256_movemask_ps(keep)) continue;
    if (bound) {
      // The pair's cost against both edges' bounds (the candidate's gathered
      // only in the lanes still kept: padding ids are never read).
      const __m256 cost = _mm256_add_ps(dq, dp);
      const __m256 theirs = _mm256_mask_i32gather_ps(_mm256_setzero_ps(), bound->per_corner, raw, keep, 4);
      const __m256 cheap = _mm256_or_ps(_mm256_cmp_ps(cost, query_bound, _CMP_LE_OQ),
                                        _mm256_cmp_ps(cost, _mm256_add_ps(theirs, margin), _CMP_LE_OQ));
      keep = _mm256_and_ps(keep, cheap);
    }
    int mask = _mm256_movemask_ps(keep);
    while (mask) {
      const int lane = __builtin_ctz(unsigned(mask));
      out.push_back(uint32_t(k + size_t(lane)));
      mask &= mask - 1;
    }
  }
}

const bool kHasAvx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");

}  // namespace

void EdgeBlock::clear(bool with_prev) {
  with_prev_ = with_prev;
  runs_.clear();
  corner_.clear();
  for (int d = 0; d < 3; ++d) c_[d].clear(), n_[d].clear(), v_[d].clear();
}

void EdgeBlock::pad() {
  if (runs_.empty()) return;
  const size_t padded = (corner_.size() + 7) / 8 * 8;
  corner_.resize(padded, UINT32_MAX);
  for (int d = 0; d < 3; ++d) {
    c_[d].resize(padded, kFar);
    n_[d].resize(padded, kFar);
    if (with_prev_) v_[d].resize(padded, kFar);
  }
  runs_.back().end = uint32_t(padded);
}

void EdgeBlock::begin_run(const Vec3& lo, const Vec3& hi) {
  pad();
  runs_.push_back({{float(lo.x), float(lo.y), float(lo.z)}, {float(hi.x), float(hi.y), float(hi.z)},
                   uint32_t(corner_.size()), uint32_t(corner_.size())});
}

void EdgeBlock::add(uint32_t corner, const Vec3& at, const Vec3& next, const Vec3& prev) {
  corner_.push_back(corner);
  const double a[3] = {at.x, at.y, at.z}, b[3] = {next.x, next.y, next.z}, e[3] = {prev.x, prev.y, prev.z};
  for (int d = 0; d < 3; ++d) {
    c_[d].push_back(float(a[d]));
    n_[d].push_back(float(b[d]));
    if (with_prev_) v_[d].push_back(float(e[d]));
  }
}

void EdgeBlock::seal() { pad(); }

void EdgeBlock::near_both(const float q[3], const float p[3], float r2, bool with_prev, uint32_t min_corner,
                          const CostBound* bound, std::vector<uint32_t>& out) const {
  out.clear();
  if (with_prev && !with_prev_) std::abort();  // a caller's bug: the block holds no previous corners
  if (with_prev) bound = nullptr;  // the pair's other edge is not the block corner's own
  for (const Run& r : runs_) {
    // The run's box against the ball around q (the box bounds its corners
    // up to float rounding; r2 carries the callers' margin).
    float g2 = 0;
    for (int d = 0; d < 3; ++d) {
      const float g = q[d] < r.lo[d] ? r.lo[d] - q[d] : q[d] > r.hi[d] ? q[d] - r.hi[d] : 0.0f;
      g2 += g * g;
    }
    if (g2 > r2) continue;
    if (kHasAvx2)
      avx2_near_both(c_, n_, v_, corner_.data(), r.first, r.end, q, p, r2, with_prev, min_corner, bound, out);
    else
      scalar_near_both(c_, n_, v_, corner_.data(), r.first, r.end, q, p, r2, with_prev, min_corner, bound, out);
  }
  // Padding never passes (kFar), so every index is a real corner.
}

}  // namespace soupuv::geometry::detail
