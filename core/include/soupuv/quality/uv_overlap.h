// How much of the texture a map uses, and how much of it twice: the
// definitions of eval/uvmetrics.py, so the diagnostics and the yardstick
// agree (a test holds them together).
//
// Input : one UV per triangle corner; which triangles count (include[t] != 0;
//         uvmetrics.py counts the non-degenerate triangles with UVs inside
//         [0,1]^2); the raster size (uvmetrics.py: 512).
// Output: utilisation = sum of |UV area| of the counted triangles (overlaps
//         not removed); overlap = share of rasterised triangle area (pixel
//         centres of a raster x raster grid, half-open edges by the top-left
//         rule, every triangle turned counter-clockwise) on pixels covered by
//         two triangles or more.
// Cost  : O(raster^2) memory, O(pixels in the triangles' boxes) time.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "soupuv/vec.h"

namespace soupuv::quality {

struct UvOverlap {
  double utilisation = 0;
  double overlap = 0;
};

UvOverlap uv_overlap(const std::vector<std::array<Vec2, 3>>& uvs, const std::vector<uint8_t>& include,
                     int raster = 512);

}  // namespace soupuv::quality
