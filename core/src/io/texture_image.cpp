// User-supplied texture images (see soupuv/io/texture.h). The bytes are
// embedded unchanged; we only check that they are what they claim to be — a
// PNG with a sane IHDR or a JPEG with a frame header — so that the GLB's
// mimeType is true and the validator and viewers accept the image. Pixels are
// never decoded here: decoding untrusted images is the viewer's business.
#include <algorithm>
#include <cstdint>
#include <fstream>
#include <iterator>

#include "soupuv/errors.h"
#include "soupuv/io/texture.h"

namespace soupuv::io {

namespace {

constexpr uint64_t kMaxTextureBytes = 256ull << 20;

uint32_t be32(const uint8_t* p) {
  return (uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) | (uint32_t(p[2]) << 8) | p[3];
}
uint32_t be16(const uint8_t* p) { return (uint32_t(p[0]) << 8) | p[1]; }

void check_dimensions(uint32_t width, uint32_t height, const char* kind) {
  if (width == 0 || height == 0)
    throw Error(ErrorCode::invalid_input, std::string(kind) + " texture has zero size");
  if (width > kMaxTextureSide || height > kMaxTextureSide)
    throw Error(ErrorCode::limit_exceeded,
                std::string(kind) + " texture is " + std::to_string(width) + "x" +
                    std::to_string(height) + ", more than " +
                    std::to_string(kMaxTextureSide) + " pixels on a side");
}

// PNG: 8-byte signature, then the IHDR chunk (length 13) must come first.
Texture png(std::span<const uint8_t> b) {
  static const uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (b.size() < 8 + 8 + 13 + 4 || !std::equal(kSignature, kSignature + 8, b.begin()))
    throw Error(ErrorCode::invalid_input, "texture is not a PNG file");
  const uint8_t* ihdr = b.data() + 8;
  if (be32(ihdr) != 13 || std::string(reinterpret_cast<const char*>(ihdr + 4), 4) != "IHDR")
    throw Error(ErrorCode::invalid_input, "PNG texture does not start with an IHDR chunk");
  Texture t;
  t.width = be32(ihdr + 8);
  t.height = be32(ihdr + 12);
  uint8_t bit_depth = ihdr[16], color_type = ihdr[17];
  bool depth_ok = bit_depth == 1 || bit_depth == 2 || bit_depth == 4 || bit_depth == 8 ||
                  bit_depth == 16;
  bool color_ok = color_type == 0 || color_type == 2 || color_type == 3 ||
                  color_type == 4 || color_type == 6;
  if (!depth_ok || !color_ok)
    throw Error(ErrorCode::invalid_input, "PNG texture has an invalid IHDR");
  check_dimensions(t.width, t.height, "PNG");
  t.mime_type = "image/png";
  return t;
}

// JPEG: SOI, then marker segments up to the first SOFn frame header, which
// holds the dimensions. Segment lengths are checked against the byte range.
Texture jpeg(std::span<const uint8_t> b) {
  if (b.size() < 4 || b[0] != 0xFF || b[1] != 0xD8 || b[2] != 0xFF)
    throw Error(ErrorCode::invalid_input, "texture is not a JPEG file");
  size_t pos = 2;
  while (pos + 4 <= b.size()) {
    if (b[pos] != 0xFF) throw Error(ErrorCode::invalid_input, "JPEG texture is corrupt");
    uint8_t marker = b[pos + 1];
    if (marker == 0xFF) { ++pos; continue; }  // fill byte
    if (marker == 0xD9 || marker == 0xDA) break;  // end of image / start of scan before a frame
    size_t length = be16(&b[pos + 2]);
    if (length < 2 || pos + 2 + length > b.size())
      throw Error(ErrorCode::invalid_input, "JPEG texture has a truncated segment");
    bool frame = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 &&
                 marker != 0xCC;
    if (frame) {
      if (length < 8) throw Error(ErrorCode::invalid_input, "JPEG frame header too short");
      Texture t;
      t.height = be16(&b[pos + 5]);
      t.width = be16(&b[pos + 7]);
      check_dimensions(t.width, t.height, "JPEG");
      t.mime_type = "image/jpeg";
      return t;
    }
    pos += 2 + length;
  }
  throw Error(ErrorCode::invalid_input, "JPEG texture has no frame header");
}

}  // namespace

Texture texture_from_bytes(std::span<const uint8_t> bytes) {
  if (bytes.size() > kMaxTextureBytes)
    throw Error(ErrorCode::limit_exceeded, "texture file is larger than 256 MiB");
  Texture t = (!bytes.empty() && bytes[0] == 0x89) ? png(bytes) : jpeg(bytes);
  t.bytes.assign(bytes.begin(), bytes.end());
  return t;
}

Texture texture_from_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::invalid_input, "cannot open texture " + path);
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  try {
    return texture_from_bytes(bytes);
  } catch (const Error& e) {
    throw Error(e.code(), path + ": " + e.what());
  }
}

}  // namespace soupuv::io
