// The re-bake (see soupuv/bake/rebake.h): rasterise every triangle in its new
// UVs, sample the input's base colour at the same barycentrics through the
// old UVs / vertex colours, then dilate.
#include "soupuv/bake/rebake.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>

#include "soupuv/errors.h"

namespace soupuv::bake {

io::Texture encode_png(const Image& image);  // image_codec.cpp

namespace {

using Rgba = std::array<double, 4>;  // linear light, straight alpha

double srgb_to_linear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }
double linear_to_srgb(double c) {
  c = std::clamp(c, 0.0, 1.0);
  return c <= 0.0031308 ? c * 12.92 : 1.055 * std::pow(c, 1 / 2.4) - 0.055;
}

// glTF wrap modes: 33071 clamp, 33648 mirrored repeat, 10497 repeat.
int wrap(int i, int n, int mode) {
  if (mode == 33071) return std::clamp(i, 0, n - 1);
  if (mode == 33648) {
    int period = 2 * n;
    int k = ((i % period) + period) % period;
    return k < n ? k : period - 1 - k;
  }
  return ((i % n) + n) % n;
}

// Bilinear sample at texture coordinate (u, v) (origin top-left), in linear light.
Rgba sample(const Image& img, double u, double v, int wrap_s, int wrap_t) {
  if (!std::isfinite(u) || !std::isfinite(v)) u = v = 0;
  const double x = u * img.width - 0.5, y = v * img.height - 0.5;
  const double fx = std::floor(x), fy = std::floor(y);
  const double tx = x - fx, ty = y - fy;
  Rgba out{0, 0, 0, 0};
  for (int dy = 0; dy < 2; ++dy)
    for (int dx = 0; dx < 2; ++dx) {
      const int px = wrap(int(fx) + dx, img.width, wrap_s), py = wrap(int(fy) + dy, img.height, wrap_t);
      const double w = (dx ? tx : 1 - tx) * (dy ? ty : 1 - ty);
      const unsigned char* p = &img.rgba[(size_t(py) * size_t(img.width) + size_t(px)) * 4];
      for (int c = 0; c < 3; ++c) out[c] += w * srgb_to_linear(p[c] / 255.0);
      out[3] += w * p[3] / 255.0;
    }
  return out;
}

struct Source {
  const Image* image = nullptr;
  const io::SourceImage* info = nullptr;
};

}  // namespace

bool has_base_color(const io::Asset& asset) {
  if (!asset.attributes.colors.empty()) return true;
  std::set<int32_t> used;
  for (const TriangleOrigin& o : asset.soup.origins) used.insert(o.material);
  for (const auto& [m, image] : asset.base_color_images)
    if (used.count(m)) return true;
  return false;
}

nlohmann::json RebakeResult::diagnostics() const {
  return {{"size", texture.width}, {"from", from}, {"covered_texels", covered_texels},
          {"dilated_texels", dilated_texels}, {"seconds", seconds}};
}

RebakeResult rebake(const io::Asset& asset, std::span<const Vec2> corner_uvs, const RebakeOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const Soup& soup = asset.soup;
  const io::VertexAttributes& attrs = asset.attributes;
  if (corner_uvs.size() != soup.triangles.size() * 3)
    throw Error(ErrorCode::invalid_input, "re-bake needs 3 UVs per triangle");
  if (options.size < 1 || options.size > int(io::kMaxTextureSide))
    throw Error(ErrorCode::invalid_input, "re-bake size out of range");
  RebakeResult result;
  const int n = options.size;

  // Decode each material's image once; one that does not decode is a warning.
  std::map<int32_t, Image> images;
  for (const auto& [m, info] : asset.base_color_images) {
    try {
      images[m] = decode_image(info.bytes);
    } catch (const Error& e) {
      result.warnings.push_back("material " + std::to_string(m) + " base-colour image not re-baked: " + e.what());
    }
  }
  const bool colors = !attrs.colors.empty();
  result.baked_colors = colors;
  std::set<std::string> from;

  std::vector<Rgba> acc(size_t(n) * size_t(n), Rgba{0, 0, 0, 0});
  std::vector<uint8_t> filled(size_t(n) * size_t(n), 0);
  for (size_t t = 0; t < soup.triangles.size(); ++t) {
    const Tri& tri = soup.triangles[t];
    Source src;
    if (auto it = images.find(soup.origins[t].material); it != images.end()) {
      const io::SourceImage& info = asset.base_color_images.at(it->first);
      if (size_t(info.tex_coord) < attrs.texcoords.size() &&
          (attrs.present[tri[0]] & io::VertexAttributes::texcoord_bit(info.tex_coord)))
        src = {&it->second, &info};
    }
    const bool vc = colors && (attrs.present[tri[0]] & io::VertexAttributes::kColor);
    from.insert(src.image ? "texture" : vc ? "vertex_colors" : "factor");
    if (src.image && vc) from.insert("vertex_colors");
    // The triangle in texel space (texel centres at i + 0.5).
    Vec2 p[3];
    for (int k = 0; k < 3; ++k) p[k] = {corner_uvs[t * 3 + k].x * n, corner_uvs[t * 3 + k].y * n};
    const double area = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[2].x - p[0].x) * (p[1].y - p[0].y);
    if (!std::isfinite(area) || area == 0) continue;
    const int x0 = std::max(0, int(std::floor(std::min({p[0].x, p[1].x, p[2].x}))));
    const int x1 = std::min(n - 1, int(std::ceil(std::max({p[0].x, p[1].x, p[2].x}))));
    const int y0 = std::max(0, int(std::floor(std::min({p[0].y, p[1].y, p[2].y}))));
    const int y1 = std::min(n - 1, int(std::ceil(std::max({p[0].y, p[1].y, p[2].y}))));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const double cx = x + 0.5, cy = y + 0.5;
        // Barycentrics of the texel centre; inside with a hair of tolerance
        // so texels on a shared edge are not lost to rounding.
        double b1 = ((cx - p[0].x) * (p[2].y - p[0].y) - (p[2].x - p[0].x) * (cy - p[0].y)) / area;
        double b2 = ((p[1].x - p[0].x) * (cy - p[0].y) - (cx - p[0].x) * (p[1].y - p[0].y)) / area;
        double b0 = 1 - b1 - b2;
        constexpr double eps = -1e-9;
        if (b0 < eps || b1 < eps || b2 < eps) continue;
        Rgba c{1, 1, 1, 1};
        if (src.image) {
          const auto& uv = attrs.texcoords[size_t(src.info->tex_coord)];
          const double u = b0 * uv[tri[0]][0] + b1 * uv[tri[1]][0] + b2 * uv[tri[2]][0];
          const double v = b0 * uv[tri[0]][1] + b1 * uv[tri[1]][1] + b2 * uv[tri[2]][1];
          c = sample(*src.image, u, v, src.info->wrap_s, src.info->wrap_t);
        }
        if (vc)
          for (int ch = 0; ch < 4; ++ch)
            c[ch] *= std::clamp(b0 * attrs.colors[tri[0]][ch] + b1 * attrs.colors[tri[1]][ch] +
                                    b2 * attrs.colors[tri[2]][ch], 0.0, 1.0);
        const size_t i = size_t(y) * size_t(n) + size_t(x);
        acc[i] = c;  // a later triangle on the same texel wins (islands do not share texels)
        filled[i] = 1;
      }
  }
  result.covered_texels = size_t(std::count(filled.begin(), filled.end(), 1));

  // Dilation: `padding` rings, each empty texel next to filled ones takes their mean.
  for (int ring = 0; ring < options.padding; ++ring) {
    std::vector<std::pair<size_t, Rgba>> grown;
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const size_t i = size_t(y) * size_t(n) + size_t(x);
        if (filled[i]) continue;
        Rgba sum{0, 0, 0, 0};
        int count = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int xx = x + dx, yy = y + dy;
            if ((dx || dy) && xx >= 0 && yy >= 0 && xx < n && yy < n && filled[size_t(yy) * size_t(n) + size_t(xx)]) {
              const Rgba& o = acc[size_t(yy) * size_t(n) + size_t(xx)];
              for (int ch = 0; ch < 4; ++ch) sum[ch] += o[ch];
              ++count;
            }
          }
        if (count)
          grown.push_back({i, {sum[0] / count, sum[1] / count, sum[2] / count, sum[3] / count}});
      }
    if (grown.empty()) break;
    for (auto& [i, c] : grown) {
      acc[i] = c;
      filled[i] = 2;
    }
    result.dilated_texels += grown.size();
  }

  Image out;
  out.width = out.height = n;
  out.rgba.resize(size_t(n) * size_t(n) * 4);
  for (size_t i = 0; i < acc.size(); ++i) {
    // Texels no triangle reaches: mid grey, opaque (never seen on the model).
    const Rgba c = filled[i] ? acc[i] : Rgba{0.2, 0.2, 0.2, 1};
    for (int ch = 0; ch < 3; ++ch) out.rgba[i * 4 + size_t(ch)] = (unsigned char)std::lround(linear_to_srgb(c[ch]) * 255);
    out.rgba[i * 4 + 3] = (unsigned char)std::lround(std::clamp(c[3], 0.0, 1.0) * 255);
  }
  result.texture = encode_png(out);
  result.from.assign(from.begin(), from.end());
  if (result.baked_colors)
    result.warnings.push_back("COLOR_0 baked into the re-baked texture and not written (glTF would multiply it in twice)");
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace soupuv::bake
