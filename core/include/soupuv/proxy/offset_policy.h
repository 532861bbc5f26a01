// Offset and resolution policy (paper §5, §9.1 / Table 1).
//
// Input:  the options and the soup's bounding box.
// Output: the absolute offset o for a mode, and the grid resolution from the
//         sampling argument: the level set d = o bends with radius >= o on its
//         convex parts, so sampling at cell size o/2 resolves it (Nyquist);
//         along the longest extent L that is 2L/o cells — Table 1's 200 samples
//         for a 1 % offset of the r = 1, h = 2 cylinder.
#pragma once

#include "soupuv/proxy/proxy.h"

namespace soupuv::proxy {

// Absolute offset for absolute / relative modes (automatic: use the ladder).
double absolute_offset(OffsetMode mode, double value, double diagonal);

// Cells along the longest extent for `offset`: options.resolution if given,
// else ceil(2 L / o) clamped to [min_resolution, max_resolution].
int sampling_resolution(const ProxyOptions& options, double longest_extent, double offset);

// Uncapped sampling resolution ceil(2 L / o), to tell whether a cap bit.
int nyquist_resolution(double longest_extent, double offset);

}  // namespace soupuv::proxy
