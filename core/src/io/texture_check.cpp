// The generated UV-check texture (see soupuv/io/texture.h): coloured checker
// cells so that distortion and seams are visible, grid lines so that stretch
// is measurable by eye, and an L-shaped marker per cell so that a mirrored or
// rotated chart is recognisable. PNG-encoded with stb_image_write.
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "soupuv/errors.h"
#include "soupuv/io/texture.h"

#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>

namespace soupuv::io {

namespace {

using Rgb = std::array<uint8_t, 3>;

// Eight hues far enough apart that neighbouring cells never look alike.
constexpr std::array<Rgb, 8> kPalette = {{
    {230, 80, 70}, {240, 170, 50}, {210, 220, 60}, {90, 200, 90},
    {60, 190, 200}, {70, 120, 230}, {150, 90, 220}, {220, 90, 180},
}};

Rgb scaled(Rgb c, double s) {
  return {static_cast<uint8_t>(c[0] * s), static_cast<uint8_t>(c[1] * s),
          static_cast<uint8_t>(c[2] * s)};
}

void append_bytes(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<uint8_t>*>(context);
  auto* bytes = static_cast<const uint8_t*>(data);
  out->insert(out->end(), bytes, bytes + size);
}

}  // namespace

Texture uv_check_texture(int size) {
  if (size < 64 || size > 4096 || (size & (size - 1)) != 0)
    throw Error(ErrorCode::invalid_input,
                "UV-check texture size must be a power of two in 64..4096");
  const int cells = 8;
  const int cell = size / cells;
  const int line = std::max(1, size / 512);        // cell border width
  const int sub = cell / 4;                        // thin sub-grid spacing
  const int marker_long = cell / 3, marker_short = cell / 6;
  const int marker_width = std::max(2, cell / 24);

  std::vector<uint8_t> rgb(static_cast<size_t>(size) * size * 3);
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      int ci = x / cell, cj = y / cell;
      int lx = x % cell, ly = y % cell;
      // Hue varies along both axes, brightness alternates like a checker.
      Rgb c = kPalette[(ci + 3 * cj) % kPalette.size()];
      c = scaled(c, (ci + cj) % 2 == 0 ? 1.0 : 0.62);
      bool border = lx < line || ly < line;
      bool subgrid = (lx % sub) == 0 || (ly % sub) == 0;
      // The "L": a long horizontal bar along the top and a short vertical bar
      // down the left, inset from the cell's top-left corner.
      int mx = lx - 2 * line - 2, my = ly - 2 * line - 2;
      bool marker = (my >= 0 && my < marker_width && mx >= 0 && mx < marker_long) ||
                    (mx >= 0 && mx < marker_width && my >= 0 && my < marker_short);
      if (border) c = {20, 20, 20};
      else if (marker) c = {255, 255, 255};
      else if (subgrid) c = scaled(c, 0.8);
      uint8_t* px = &rgb[(static_cast<size_t>(y) * size + x) * 3];
      px[0] = c[0]; px[1] = c[1]; px[2] = c[2];
    }
  }

  Texture texture;
  texture.mime_type = "image/png";
  texture.width = texture.height = static_cast<uint32_t>(size);
  if (!stbi_write_png_to_func(append_bytes, &texture.bytes, size, size, 3, rgb.data(),
                              size * 3))
    throw Error(ErrorCode::internal, "PNG encoding of the UV-check texture failed");
  return texture;
}

}  // namespace soupuv::io
