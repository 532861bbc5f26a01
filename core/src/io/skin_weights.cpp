#include "io/skin_weights.h"

#include <cmath>

namespace soupuv::io::detail {

bool weights_pass_validator(std::span<const std::array<float, 4>> sets) {
  float sum = 0;
  int nonzero = 0;
  for (int c = 0; c < 4; ++c)
    for (const auto& w : sets)
      if (w[c] != 0) {
        sum += w[c];
        ++nonzero;
      }
  return std::fabs(double(sum) - 1.0) <= 2e-7 * nonzero;
}

bool normalize_skin_weights(std::span<std::array<float, 4>> sets) {
  if (sets.empty() || weights_pass_validator(sets)) return false;
  double sum = 0;
  for (const auto& w : sets)
    for (float x : w) {
      if (!std::isfinite(x) || x < 0) return false;
      sum += x;
    }
  if (sum <= 0) return false;
  float* largest = &sets[0][0];
  for (auto& w : sets)
    for (float& x : w) {
      x = float(x / sum);
      if (x > *largest) largest = &x;
    }
  // Rounding each weight to float can leave the float32 sum a few ulps off
  // the validator's bound; the largest weight absorbs the rest.
  if (!weights_pass_validator(sets)) {
    float others = 0;
    for (int c = 0; c < 4; ++c)
      for (auto& w : sets)
        if (&w[c] != largest) others += w[c];
    *largest = 1.0f - others;
  }
  return true;
}

}  // namespace soupuv::io::detail
