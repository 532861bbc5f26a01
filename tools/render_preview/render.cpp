#include "render.h"

#include <algorithm>
#include <cmath>

#include "soupuv/errors.h"

#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#include <stb/stb_image.h>
#pragma GCC diagnostic pop

namespace soupuv::render {

Rgba decode_image(const std::vector<uint8_t>& bytes) {
  int w = 0, h = 0, n = 0;
  uint8_t* data = stbi_load_from_memory(bytes.data(), int(bytes.size()), &w, &h, &n, 4);
  if (!data) throw Error(ErrorCode::invalid_input, "texture image could not be decoded");
  Rgba img{w, h, std::vector<uint8_t>(data, data + size_t(w) * h * 4)};
  stbi_image_free(data);
  return img;
}

namespace {

// Bilinear texture lookup with wrap-around (glTF's default sampler: repeat).
void sample(const Rgba& tex, Vec2 uv, double rgb[3]) {
  double x = uv.x * tex.width - 0.5, y = uv.y * tex.height - 0.5;
  double fx = std::floor(x), fy = std::floor(y);
  double ax = x - fx, ay = y - fy;
  auto at = [&](long i, long j, int c) {
    i = ((i % tex.width) + tex.width) % tex.width;
    j = ((j % tex.height) + tex.height) % tex.height;
    return double(tex.pixels[4 * (size_t(j) * tex.width + size_t(i)) + c]);
  };
  long i = long(fx), j = long(fy);
  for (int c = 0; c < 3; ++c)
    rgb[c] = (1 - ax) * (1 - ay) * at(i, j, c) + ax * (1 - ay) * at(i + 1, j, c) +
             (1 - ax) * ay * at(i, j + 1, c) + ax * ay * at(i + 1, j + 1, c);
}

struct Camera {
  Vec3 right, up, forward;  // orthonormal; forward points into the screen
};

Camera camera(double azimuth_deg, double elevation_deg) {
  double az = azimuth_deg * M_PI / 180, el = elevation_deg * M_PI / 180;
  Vec3 to_eye{std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az)};  // y up
  Vec3 forward = -to_eye;
  Vec3 right = normalized(cross(forward, Vec3{0, 1, 0}));
  Vec3 up = cross(right, forward);
  return {right, up, forward};
}

}  // namespace

Rgba render_views(const std::vector<Vec3>& corners, const std::vector<Vec2>& uvs,
                  const Rgba& texture, int view) {
  if (corners.size() != uvs.size() || corners.size() % 3)
    throw Error(ErrorCode::invalid_input, "render: 3 positions and 3 UVs per triangle expected");
  Rgba out{2 * view, 2 * view, std::vector<uint8_t>(size_t(4) * view * view * 4, 0)};
  for (size_t i = 0; i < out.pixels.size(); i += 4) {  // neutral background
    out.pixels[i] = 48; out.pixels[i + 1] = 52; out.pixels[i + 2] = 60; out.pixels[i + 3] = 255;
  }
  Box3 box;
  for (Vec3 p : corners) box.add(p);
  const Vec3 center = box.center();
  const double radius = 0.5 * box.diagonal() + 1e-12;
  const Camera cams[4] = {camera(0, 15), camera(90, 15), camera(180, 15), camera(-45, 55)};

  for (int v = 0; v < 4; ++v) {
    const Camera& cam = cams[v];
    const int ox = (v % 2) * view, oy = (v / 2) * view;
    std::vector<double> depth(size_t(view) * view, INFINITY);
    auto to_screen = [&](Vec3 p, double& sx, double& sy, double& z) {
      Vec3 q = p - center;
      sx = (dot(q, cam.right) / radius * 0.5 * 0.95 + 0.5) * view;
      sy = (0.5 - dot(q, cam.up) / radius * 0.5 * 0.95) * view;
      z = dot(q, cam.forward);
    };
    for (size_t t = 0; t < corners.size(); t += 3) {
      double x[3], y[3], z[3];
      for (int k = 0; k < 3; ++k) to_screen(corners[t + k], x[k], y[k], z[k]);
      double area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
      if (!(std::abs(area) > 1e-12)) continue;
      Vec3 n = normalized(cross(corners[t + 1] - corners[t], corners[t + 2] - corners[t]));
      double light = 0.35 + 0.65 * std::abs(dot(n, cam.forward));  // two-sided headlight
      int x0 = std::max(0, int(std::floor(std::min({x[0], x[1], x[2]}))));
      int x1 = std::min(view - 1, int(std::ceil(std::max({x[0], x[1], x[2]}))));
      int y0 = std::max(0, int(std::floor(std::min({y[0], y[1], y[2]}))));
      int y1 = std::min(view - 1, int(std::ceil(std::max({y[0], y[1], y[2]}))));
      for (int py = y0; py <= y1; ++py)
        for (int px = x0; px <= x1; ++px) {
          double cx = px + 0.5, cy = py + 0.5;
          double w0 = ((x[1] - cx) * (y[2] - cy) - (x[2] - cx) * (y[1] - cy)) / area;
          double w1 = ((x[2] - cx) * (y[0] - cy) - (x[0] - cx) * (y[2] - cy)) / area;
          double w2 = 1 - w0 - w1;
          if (w0 < 0 || w1 < 0 || w2 < 0) continue;
          double zz = w0 * z[0] + w1 * z[1] + w2 * z[2];
          double& d = depth[size_t(py) * view + px];
          if (zz >= d) continue;
          d = zz;
          Vec2 uv = w0 * uvs[t] + w1 * uvs[t + 1] + w2 * uvs[t + 2];
          double rgb[3] = {255, 0, 255};  // magenta: non-finite UVs
          if (std::isfinite(uv.x) && std::isfinite(uv.y)) sample(texture, uv, rgb);
          uint8_t* p = &out.pixels[4 * (size_t(oy + py) * out.width + size_t(ox + px))];
          for (int c = 0; c < 3; ++c) p[c] = uint8_t(std::clamp(rgb[c] * light, 0.0, 255.0));
          p[3] = 255;
        }
    }
  }
  return out;
}

}  // namespace soupuv::render
