// Tables and the CPU check of the AVX2 log / atan2 (see tracer_vmath.h).
#include "tracer_vmath.h"

#ifdef SOUPUV_TRACER_VMATH

namespace soupuv::field::tracer {

bool vmath_supported() {
  static const bool ok = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return ok;
}

namespace vmath_detail {

AtanTable make_atan_table() {
  AtanTable t;
  for (int j = 0; j <= 4; ++j) {
    t.c[j] = std::tan(j * M_PI / 16);
    t.off[j] = std::atan(t.c[j]);
  }
  for (int j = 0; j < 4; ++j) t.split[j] = std::tan((2 * j + 1) * M_PI / 32);
  return t;
}

}  // namespace vmath_detail
}  // namespace soupuv::field::tracer

#endif
