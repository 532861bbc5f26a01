// A small software rasteriser for looking at a texture mapping: the soup (3
// corners per triangle) with its UVs and a texture, seen from four directions
// (front, right, back, above-left), z-buffered, lit by a headlight, in a 2x2
// grid. Orthographic views, so UVs interpolate linearly in screen space.
//
// Input : corner positions and UVs (3 per triangle, glTF convention), an
//         RGBA texture.
// Output: an RGBA image of 2*view x 2*view pixels.
#pragma once

#include <cstdint>
#include <vector>

#include "soupuv/vec.h"

namespace soupuv::render {

struct Rgba {
  int width = 0, height = 0;
  std::vector<uint8_t> pixels;  // row-major RGBA8, top row first
};

// PNG or JPEG bytes -> RGBA (stb_image); throws soupuv::Error on bad bytes.
Rgba decode_image(const std::vector<uint8_t>& bytes);

Rgba render_views(const std::vector<Vec3>& corners, const std::vector<Vec2>& uvs,
                  const Rgba& texture, int view = 512);

}  // namespace soupuv::render
