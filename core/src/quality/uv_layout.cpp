#include "soupuv/quality/uv_layout.h"

#include <algorithm>
#include <cmath>

#include "soupuv/errors.h"

// Static so our copy of stb does not clash with another translation unit's.
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wunused-function"
#include <stb/stb_image_write.h>
#pragma GCC diagnostic pop

namespace soupuv::quality {

namespace {

void append(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<uint8_t>*>(context);
  auto* bytes = static_cast<uint8_t*>(data);
  out->insert(out->end(), bytes, bytes + size);
}

struct Canvas {
  int size;
  std::vector<uint8_t> rgba;
  void put(int x, int y, uint8_t r, uint8_t g, uint8_t b) {
    if (x < 0 || y < 0 || x >= size || y >= size) return;
    uint8_t* p = &rgba[4 * (size_t(y) * size + x)];
    p[0] = r; p[1] = g; p[2] = b; p[3] = 255;
  }
  void line(Vec2 a, Vec2 b, uint8_t r, uint8_t g, uint8_t bl) {
    double steps = std::ceil(std::max(std::abs(b.x - a.x), std::abs(b.y - a.y))) + 1;
    if (!(steps < 4 * size)) steps = 4 * size;  // NaN or absurd: bounded
    for (int i = 0; i <= int(steps); ++i) {
      Vec2 p = a + (b - a) * (i / steps);
      put(int(std::floor(p.x)), int(std::floor(p.y)), r, g, bl);
    }
  }
  void fill(Vec2 a, Vec2 b, Vec2 c, uint8_t r, uint8_t g, uint8_t bl) {
    int x0 = std::max(0, int(std::floor(std::min({a.x, b.x, c.x}))));
    int x1 = std::min(size - 1, int(std::ceil(std::max({a.x, b.x, c.x}))));
    int y0 = std::max(0, int(std::floor(std::min({a.y, b.y, c.y}))));
    int y1 = std::min(size - 1, int(std::ceil(std::max({a.y, b.y, c.y}))));
    double area = cross(b - a, c - a);
    if (!(std::abs(area) > 0)) return;
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        Vec2 p{x + 0.5, y + 0.5};
        double w0 = cross(b - p, c - p) / area, w1 = cross(c - p, a - p) / area;
        if (w0 >= 0 && w1 >= 0 && w0 + w1 <= 1) put(x, y, r, g, bl);
      }
  }
};

}  // namespace

std::vector<uint8_t> encode_png(const std::vector<uint8_t>& rgba, int width, int height) {
  std::vector<uint8_t> out;
  if (!stbi_write_png_to_func(append, &out, width, height, 4, rgba.data(), width * 4))
    throw Error(ErrorCode::internal, "PNG encoding failed");
  return out;
}

std::vector<uint8_t> uv_layout_png(const std::vector<Vec2>& corner_uvs, int size) {
  if (size < 16 || size > 8192) throw Error(ErrorCode::invalid_input, "UV layout size out of range");
  Canvas cv{size, std::vector<uint8_t>(size_t(size) * size * 4, 255)};
  // The dominant orientation is "not flipped" (see uv_metrics).
  double oriented = 0;
  for (size_t t = 0; t + 2 < corner_uvs.size(); t += 3)
    oriented += cross(corner_uvs[t + 1] - corner_uvs[t], corner_uvs[t + 2] - corner_uvs[t]);
  auto px = [&](Vec2 uv) { return Vec2{uv.x * size, uv.y * size}; };  // v = 0 at the top row
  for (size_t t = 0; t + 2 < corner_uvs.size(); t += 3) {
    Vec2 a = px(corner_uvs[t]), b = px(corner_uvs[t + 1]), c = px(corner_uvs[t + 2]);
    bool flipped = cross(b - a, c - a) * oriented < 0;
    if (flipped) cv.fill(a, b, c, 230, 40, 40);
    else cv.fill(a, b, c, 205, 215, 230);
  }
  for (size_t t = 0; t + 2 < corner_uvs.size(); t += 3) {
    Vec2 a = px(corner_uvs[t]), b = px(corner_uvs[t + 1]), c = px(corner_uvs[t + 2]);
    cv.line(a, b, 40, 60, 90);
    cv.line(b, c, 40, 60, 90);
    cv.line(c, a, 40, 60, 90);
  }
  return encode_png(cv.rgba, size, size);
}

}  // namespace soupuv::quality
