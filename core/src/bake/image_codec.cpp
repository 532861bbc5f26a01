// PNG/JPEG decoding for the re-bake and PNG encoding of its result, with
// stb_image / stb_image_write (Debian's libstb-dev headers; static copies so
// they cannot clash with another translation unit's).
#include <cstring>

#include "soupuv/bake/rebake.h"
#include "soupuv/errors.h"

#define STBI_ONLY_PNG
#define STBI_ONLY_JPEG
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wdouble-promotion"
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#pragma GCC diagnostic pop

namespace soupuv::bake {

Image decode_image(std::span<const uint8_t> encoded) {
  if (encoded.size() > size_t(INT32_MAX)) throw Error(ErrorCode::limit_exceeded, "image larger than 2 GiB");
  int w = 0, h = 0, channels = 0;
  const auto* data = reinterpret_cast<const stbi_uc*>(encoded.data());
  if (!stbi_info_from_memory(data, int(encoded.size()), &w, &h, &channels))
    throw Error(ErrorCode::invalid_input, std::string("image cannot be decoded: ") + stbi_failure_reason());
  if (w <= 0 || h <= 0 || uint32_t(w) > io::kMaxTextureSide || uint32_t(h) > io::kMaxTextureSide)
    throw Error(ErrorCode::limit_exceeded, "image of " + std::to_string(w) + "x" + std::to_string(h) +
                                               " texels exceeds " + std::to_string(io::kMaxTextureSide) + " a side");
  stbi_uc* pixels = stbi_load_from_memory(data, int(encoded.size()), &w, &h, &channels, 4);
  if (!pixels) throw Error(ErrorCode::invalid_input, std::string("image cannot be decoded: ") + stbi_failure_reason());
  Image out;
  out.width = w;
  out.height = h;
  out.rgba.assign(pixels, pixels + size_t(w) * size_t(h) * 4);
  stbi_image_free(pixels);
  return out;
}

namespace {
void append_bytes(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<uint8_t>*>(context);
  const auto* p = static_cast<const uint8_t*>(data);
  out->insert(out->end(), p, p + size);
}
}  // namespace

// Used by rebake.cpp: RGBA8 -> PNG texture.
io::Texture encode_png(const Image& image) {
  io::Texture t;
  if (!stbi_write_png_to_func(append_bytes, &t.bytes, image.width, image.height, 4, image.rgba.data(),
                              image.width * 4))
    throw Error(ErrorCode::internal, "PNG encoding of the re-baked texture failed");
  t.mime_type = "image/png";
  t.width = uint32_t(image.width);
  t.height = uint32_t(image.height);
  return t;
}

}  // namespace soupuv::bake
