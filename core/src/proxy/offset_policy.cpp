// Offset and resolution policy. See soupuv/proxy/offset_policy.h.
#include "soupuv/proxy/offset_policy.h"

#include <algorithm>
#include <cmath>

namespace soupuv::proxy {

double absolute_offset(OffsetMode mode, double value, double diagonal) {
  return mode == OffsetMode::absolute ? value : value * diagonal;
}

int nyquist_resolution(double longest_extent, double offset) {
  double cells = std::ceil(2 * longest_extent / offset - 1e-9);
  return int(std::min(cells, 1e6));
}

int sampling_resolution(const ProxyOptions& options, double longest_extent, double offset) {
  if (options.resolution > 0) return options.resolution;
  return std::clamp(nyquist_resolution(longest_extent, offset), options.min_resolution,
                    options.max_resolution);
}

}  // namespace soupuv::proxy
