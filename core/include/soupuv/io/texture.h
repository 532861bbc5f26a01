// The image the written GLB carries as baseColorTexture on TEXCOORD_0: either
// a generated UV-check texture or a user-supplied PNG/JPEG embedded as-is.
//
// Input : a size in pixels (generated) or the bytes of a user image.
// Output: a Texture (encoded bytes + mime type + dimensions), or
//         soupuv::Error{invalid_input | unsupported | limit_exceeded} when the
//         user bytes are not a well-formed PNG/JPEG header or too large.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace soupuv::io {

struct Texture {
  std::vector<uint8_t> bytes;  // encoded file content (PNG or JPEG)
  std::string mime_type;       // "image/png" or "image/jpeg"
  uint32_t width = 0;
  uint32_t height = 0;
};

// Largest accepted side of a user image; glTF viewers commonly cap at 16384.
inline constexpr uint32_t kMaxTextureSide = 16384;

// A UV-check texture of size x size pixels (size a power of two, 64..4096):
// an 8x8 checker of coloured cells, each cell cut by thin grid lines, with a
// marker in each cell's top-left corner so orientation and mirroring are
// visible, and a seam is visible where the pattern breaks. PNG-encoded.
Texture uv_check_texture(int size = 1024);

// Checks the header of a user image (PNG signature + IHDR, or JPEG SOI + a
// SOFn frame header), reads its dimensions, and keeps the bytes unchanged.
// The pixels are not decoded: the viewer decodes them, we only embed them.
Texture texture_from_bytes(std::span<const uint8_t> bytes);

// Reads a file and calls texture_from_bytes.
Texture texture_from_file(const std::string& path);

}  // namespace soupuv::io
