// Batched M2L of the tracer (see tracer_m2l.h).
//
// Four sources per pass, one per lane of a 4-double vector (GCC/Clang vector
// extensions: AVX2+FMA when the CPU has them, chosen once at run time;
// otherwise the same code on two SSE2 halves).
#include "tracer_m2l.h"

#include <cmath>
#if defined(__SSE__)
#include <xmmintrin.h>
#endif
#include <cstdint>
#include <map>

namespace soupuv::field::tracer {

namespace {

typedef double v4d __attribute__((vector_size(32)));
typedef float v8f __attribute__((vector_size(32)));

// Lanes of a partial last group: no moments, and an offset that keeps the
// recurrence finite (0 * finite stays 0).
constexpr double kPadOffset = 1.0;

// While alive, this thread's SSE/AVX arithmetic flushes subnormal results
// and operands to zero (MXCSR FTZ and DAZ); the old mode comes back after.
// Why: in single precision a source's high moments and the far kernel
// derivatives meet below FLT_MIN (1.2e-38) on some soups, and every
// subnormal operand costs the CPU a microcode assist. On table-exact the
// float M2L took 2.9x the time without the flush (perf samples of
// apply_float_avx2, 3,239 -> 1,134), its map byte for byte the same: terms
// below 1e-38 of the coefficients they are summed into change nothing.
class FlushSubnormals {
 public:
#if defined(__SSE__)
  FlushSubnormals() : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | kFtz | kDaz); }
  ~FlushSubnormals() { _mm_setcsr(saved_); }

 private:
  static constexpr unsigned kFtz = 0x8000, kDaz = 0x0040;
  unsigned saved_;
#endif
};

}  // namespace

BatchM2L::BatchM2L(const TaylorBasis& basis) {
  const int p = basis.order();
  n_ = TaylorBasis::size_for(p);
  std::map<std::array<int, 3>, int> index;
  for (int a = 0; a < n_; ++a) index[basis.multi_index(a)] = a;
  auto at = [&](std::array<int, 3> m) {
    auto it = index.find(m);
    return it == index.end() ? -1 : it->second;
  };
  m1_.assign(3 * n_, n_);
  m2_.assign(3 * n_, n_);
  c1_.assign(n_, 0);
  c2_.assign(n_, 0);
  factorial_.assign(n_, 1);
  inv_factorial_.assign(n_, 1);
  out_scale_.assign(n_, 0);
  for (int a = 0; a < n_; ++a) {
    const auto& A = basis.multi_index(a);
    const int deg = A[0] + A[1] + A[2];
    for (int d = 0; d < 3; ++d)
      for (int f = 2; f <= A[d]; ++f) factorial_[a] *= f;
    inv_factorial_[a] = 1.0 / factorial_[a];
    out_scale_[a] = (deg % 2 ? -1.0 : 1.0) / factorial_[a];
    if (deg == 0) continue;
    c1_[a] = (2.0 * deg - 1) / deg;
    c2_[a] = (deg - 1.0) / deg;
    for (int d = 0; d < 3; ++d) {
      if (A[d] == 0) continue;
      auto m = A;
      --m[d];
      m1_[3 * a + d] = at(m);
      if (m[d] > 0) {
        --m[d];
        m2_[3 * a + d] = at(m);
      }
    }
  }
  // The a's of one b are the first size_for(p - |b|) indices (degree order),
  // so the inner loop runs over M contiguously and gathers only D.
  start_.assign(n_ + 1, 0);
  for (int b = 0; b < n_; ++b) {
    const auto& B = basis.multi_index(b);
    const int na = TaylorBasis::size_for(p - (B[0] + B[1] + B[2]));
    for (int a = 0; a < na; ++a) {
      const auto& A = basis.multi_index(a);
      power_.push_back(at({A[0] + B[0], A[1] + B[1], A[2] + B[2]}));
    }
    start_[b + 1] = static_cast<int>(power_.size());
  }
}

struct BatchM2L::Tables {
  int n;
  const int *m1, *m2, *start, *power;
  const double *c1, *c2, *factorial, *inv_factorial, *out_scale;
};

BatchM2L::Tables BatchM2L::tables() const {
  return {n_,         m1_.data(),        m2_.data(),         start_.data(),    power_.data(),
          c1_.data(), c2_.data(), factorial_.data(), inv_factorial_.data(), out_scale_.data()};
}

namespace {

using Tables = BatchM2L::Tables;

// 3 n + 1 SIMD vectors of scratch (k: n + 1, mt: n, acc: n), 32-byte aligned
// by hand: std::vector of a vector type came back only 16-byte aligned, and
// the AVX2 code stores whole vectors with aligned moves. A target cell's list
// is hundreds of M2Ls, so one allocation per call is noise.
template <class V, class Lane>
V* aligned_scratch(std::vector<Lane>& storage, int n) {
  constexpr size_t lanes = sizeof(V) / sizeof(Lane);
  storage.assign(lanes * (3 * static_cast<size_t>(n) + 1) + lanes, Lane{0});
  const auto base = reinterpret_cast<uintptr_t>(storage.data());
  return reinterpret_cast<V*>((base + 31) & ~uintptr_t{31});
}

// k: n + 1 vectors (the last one stays 0), mt: n vectors, acc: n vectors.
__attribute__((always_inline)) inline void apply_body(const Tables& t, const double* const* M, const Vec3* R,
                                                      int count, double* L, v4d* k, v4d* mt, v4d* acc) {
  const int n = t.n;
  for (int b = 0; b < n; ++b) acc[b] = v4d{0, 0, 0, 0};
  k[n] = v4d{0, 0, 0, 0};
  for (int g = 0; g < count; g += 4) {
    const int lanes = count - g < 4 ? count - g : 4;
    v4d rx, ry, rz, inv_r2;
    const double* m[4];
    for (int l = 0; l < 4; ++l) {
      const bool real = l < lanes;
      const Vec3 r = real ? R[g + l] : Vec3{kPadOffset, 0, 0};
      rx[l] = r.x;
      ry[l] = r.y;
      rz[l] = r.z;
      const double r2 = r.x * r.x + r.y * r.y + r.z * r.z;
      inv_r2[l] = 1.0 / r2;
      k[0][l] = 1.0 / std::sqrt(r2);
      m[l] = real ? M[g + l] : nullptr;
    }
    // Kernel derivatives k_a(R) by the recurrence (taylor.h), four lanes at once.
    for (int a = 1; a < n; ++a) {
      const int* i1 = t.m1 + 3 * a;
      const int* i2 = t.m2 + 3 * a;
      const v4d s1 = rx * k[i1[0]] + ry * k[i1[1]] + rz * k[i1[2]];
      const v4d s2 = k[i2[0]] + k[i2[1]] + k[i2[2]];
      k[a] = (t.c1[a] * s1 - t.c2[a] * s2) * inv_r2;
    }
    for (int a = 0; a < n; ++a) {
      k[a] *= t.factorial[a];
      for (int l = 0; l < 4; ++l) mt[a][l] = m[l] ? m[l][a] * t.inv_factorial[a] : 0.0;
    }
    for (int b = 0; b < n; ++b) {
      const int* pw = t.power + t.start[b];
      const int na = t.start[b + 1] - t.start[b];
      // Independent partial sums: one running sum is bound by the add latency.
      v4d s0 = {0, 0, 0, 0}, s1 = s0, s2 = s0, s3 = s0;
      int a = 0;
      for (; a + 4 <= na; a += 4) {
        s0 += k[pw[a]] * mt[a];
        s1 += k[pw[a + 1]] * mt[a + 1];
        s2 += k[pw[a + 2]] * mt[a + 2];
        s3 += k[pw[a + 3]] * mt[a + 3];
      }
      for (; a < na; ++a) s0 += k[pw[a]] * mt[a];
      acc[b] += (s0 + s1) + (s2 + s3);
    }
  }
  for (int b = 0; b < n; ++b) L[b] += t.out_scale[b] * ((acc[b][0] + acc[b][1]) + (acc[b][2] + acc[b][3]));
}

#if defined(__x86_64__) && defined(__GNUC__)
__attribute__((target("avx2,fma"))) void apply_avx2(const Tables& t, const double* const* M, const Vec3* R,
                                                     int count, double* L, v4d* k, v4d* mt, v4d* acc) {
  apply_body(t, M, R, count, L, k, mt, acc);
}
const bool kHasAvx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#endif

void apply_generic(const Tables& t, const double* const* M, const Vec3* R, int count, double* L, v4d* k, v4d* mt,
                   v4d* acc) {
  apply_body(t, M, R, count, L, k, mt, acc);
}

// apply_body in float, eight lanes (see BatchM2L::apply_float). k: n + 1
// vectors (the last one stays 0), mt: n vectors, acc: n vectors.
__attribute__((always_inline)) inline void apply_body_float(const Tables& t, const double* const* M, const Vec3* R,
                                                            int count, double* L, v8f* k, v8f* mt, v8f* acc) {
  const int n = t.n;
  for (int b = 0; b < n; ++b) acc[b] = v8f{0, 0, 0, 0, 0, 0, 0, 0};
  k[n] = v8f{0, 0, 0, 0, 0, 0, 0, 0};
  for (int g = 0; g < count; g += 8) {
    const int lanes = count - g < 8 ? count - g : 8;
    v8f rx, ry, rz, inv_r2;
    const double* m[8];
    for (int l = 0; l < 8; ++l) {
      const bool real = l < lanes;
      const Vec3 r = real ? R[g + l] : Vec3{kPadOffset, 0, 0};
      rx[l] = static_cast<float>(r.x);
      ry[l] = static_cast<float>(r.y);
      rz[l] = static_cast<float>(r.z);
      const double r2 = r.x * r.x + r.y * r.y + r.z * r.z;
      inv_r2[l] = static_cast<float>(1.0 / r2);
      k[0][l] = static_cast<float>(1.0 / std::sqrt(r2));
      m[l] = real ? M[g + l] : nullptr;
    }
    for (int a = 1; a < n; ++a) {
      const int* i1 = t.m1 + 3 * a;
      const int* i2 = t.m2 + 3 * a;
      const v8f s1 = rx * k[i1[0]] + ry * k[i1[1]] + rz * k[i1[2]];
      const v8f s2 = k[i2[0]] + k[i2[1]] + k[i2[2]];
      k[a] = (static_cast<float>(t.c1[a]) * s1 - static_cast<float>(t.c2[a]) * s2) * inv_r2;
    }
    for (int a = 0; a < n; ++a) {
      k[a] *= static_cast<float>(t.factorial[a]);
      for (int l = 0; l < 8; ++l) mt[a][l] = m[l] ? static_cast<float>(m[l][a] * t.inv_factorial[a]) : 0.0f;
    }
    for (int b = 0; b < n; ++b) {
      const int* pw = t.power + t.start[b];
      const int na = t.start[b + 1] - t.start[b];
      v8f s0 = {0, 0, 0, 0, 0, 0, 0, 0}, s1 = s0, s2 = s0, s3 = s0;
      int a = 0;
      for (; a + 4 <= na; a += 4) {
        s0 += k[pw[a]] * mt[a];
        s1 += k[pw[a + 1]] * mt[a + 1];
        s2 += k[pw[a + 2]] * mt[a + 2];
        s3 += k[pw[a + 3]] * mt[a + 3];
      }
      for (; a < na; ++a) s0 += k[pw[a]] * mt[a];
      acc[b] += (s0 + s1) + (s2 + s3);
    }
  }
  for (int b = 0; b < n; ++b) {
    double sum = 0;
    for (int l = 0; l < 8; ++l) sum += acc[b][l];
    L[b] += t.out_scale[b] * sum;
  }
}

#if defined(__x86_64__) && defined(__GNUC__)
__attribute__((target("avx2,fma"))) void apply_float_avx2(const Tables& t, const double* const* M, const Vec3* R,
                                                           int count, double* L, v8f* k, v8f* mt, v8f* acc) {
  apply_body_float(t, M, R, count, L, k, mt, acc);
}
#endif

void apply_float_generic(const Tables& t, const double* const* M, const Vec3* R, int count, double* L, v8f* k,
                         v8f* mt, v8f* acc) {
  apply_body_float(t, M, R, count, L, k, mt, acc);
}

}  // namespace

void BatchM2L::apply(const double* const* M, const Vec3* R, int count, double* L) const {
  if (count <= 0) return;
  const Tables t = tables();
  std::vector<double> storage;
  v4d* k = aligned_scratch<v4d>(storage, n_);
  v4d* mt = k + n_ + 1;
  v4d* acc = mt + n_;
#if defined(__x86_64__) && defined(__GNUC__)
  if (kHasAvx2) return apply_avx2(t, M, R, count, L, k, mt, acc);
#endif
  apply_generic(t, M, R, count, L, k, mt, acc);
}

void BatchM2L::apply_float(const double* const* M, const Vec3* R, int count, double* L) const {
  if (count <= 0) return;
  const FlushSubnormals flush;
  const Tables t = tables();
  std::vector<float> storage;
  v8f* k = aligned_scratch<v8f>(storage, n_);
  v8f* mt = k + n_ + 1;
  v8f* acc = mt + n_;
#if defined(__x86_64__) && defined(__GNUC__)
  if (kHasAvx2) return apply_float_avx2(t, M, R, count, L, k, mt, acc);
#endif
  apply_float_generic(t, M, R, count, L, k, mt, acc);
}

}  // namespace soupuv::field::tracer
