// A picture of a UV layout: every triangle's UV edges drawn into a square
// image (white background, triangles filled light grey, edges dark; flipped
// triangles red), as PNG — the debug output a person looks at to see islands
// and seams.
//
// Input : UVs, 3 per triangle (glTF convention: v = 0 is the image's top row).
// Output: PNG bytes of size x size pixels.
#pragma once

#include <cstdint>
#include <vector>

#include "soupuv/vec.h"

namespace soupuv::quality {

std::vector<uint8_t> uv_layout_png(const std::vector<Vec2>& corner_uvs, int size = 1024);

// RGBA8 pixels -> PNG bytes (stb_image_write).
std::vector<uint8_t> encode_png(const std::vector<uint8_t>& rgba, int width, int height);

}  // namespace soupuv::quality
