// The re-bake carries the input's base colour onto a new map: sampled at 1,000
// random surface points, the re-baked texture through the new UVs matches the
// source texture through the old UVs (Duck, CesiumMan: median within 8/255),
// and vertex colours are baked where there is no texture. The new map here is
// a grid with one cell per triangle (no overlap, every triangle rotated and
// scaled differently from its old UVs), so any error is the re-bake's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>

#include "soupuv/bake/rebake.h"
#include "soupuv/io/load.h"
#include "shared_data.h"

namespace {

using namespace soupuv;

std::array<double, 4> bilinear(const bake::Image& img, double u, double v) {
  const double x = u * img.width - 0.5, y = v * img.height - 0.5;
  const int fx = int(std::floor(x)), fy = int(std::floor(y));
  const double tx = x - fx, ty = y - fy;
  std::array<double, 4> out{};
  for (int dy = 0; dy < 2; ++dy)
    for (int dx = 0; dx < 2; ++dx) {
      const int px = ((fx + dx) % img.width + img.width) % img.width;
      const int py = ((fy + dy) % img.height + img.height) % img.height;
      const double w = (dx ? tx : 1 - tx) * (dy ? ty : 1 - ty);
      for (int c = 0; c < 4; ++c) out[c] += w * img.rgba[(size_t(py) * img.width + px) * 4 + c];
    }
  return out;
}

// One cell per triangle, each corner placed differently from its old UVs.
std::vector<Vec2> grid_uvs(size_t triangles) {
  const size_t k = size_t(std::ceil(std::sqrt(double(triangles))));
  std::vector<Vec2> uvs;
  for (size_t t = 0; t < triangles; ++t) {
    const double x = double(t % k) / k, y = double(t / k) / k, s = 1.0 / k;
    uvs.push_back({x + 0.1 * s, y + 0.1 * s});
    uvs.push_back({x + 0.9 * s, y + 0.15 * s});
    uvs.push_back({x + 0.2 * s, y + 0.9 * s});
  }
  return uvs;
}

struct Errors {
  double median = 0, p90 = 0, mean = 0;
};

// Max-channel RGB difference (0..255) at random surface points.
Errors compare(const io::Asset& asset, const std::vector<Vec2>& uvs, const bake::RebakeResult& baked) {
  const bake::Image after = bake::decode_image(baked.texture.bytes);
  const auto& [material, info] = *asset.base_color_images.begin();
  const bake::Image before = bake::decode_image(info.bytes);
  const auto& old = asset.attributes.texcoords.at(size_t(info.tex_coord));
  std::mt19937 rng(22);
  std::uniform_int_distribution<size_t> pick(0, asset.soup.triangles.size() - 1);
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<double> errors;
  while (errors.size() < 1000) {
    const size_t t = pick(rng);
    if (asset.soup.origins[t].material != material) continue;
    double a = unit(rng), b = unit(rng);
    if (a + b > 1) a = 1 - a, b = 1 - b;
    const double w[3] = {1 - a - b, a, b};
    double ou = 0, ov = 0, nu = 0, nv = 0;
    for (int k = 0; k < 3; ++k) {
      const auto& o = old[asset.soup.triangles[t][k]];
      ou += w[k] * o[0];
      ov += w[k] * o[1];
      nu += w[k] * uvs[t * 3 + k].x;
      nv += w[k] * uvs[t * 3 + k].y;
    }
    const auto x = bilinear(before, ou, ov), y = bilinear(after, nu, nv);
    double e = 0;
    for (int c = 0; c < 3; ++c) e = std::max(e, std::abs(x[c] - y[c]));
    errors.push_back(e);
  }
  std::sort(errors.begin(), errors.end());
  double sum = 0;
  for (double e : errors) sum += e;
  return {errors[errors.size() / 2], errors[errors.size() * 9 / 10], sum / double(errors.size())};
}

void check_sample(const char* name) {
  const std::string path = soupuv_test::shared_data_dir() + "/gltf/" + name;
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "needs ../shared/data (" << path << " absent)";
  io::Asset asset = io::load_file(path);
  ASSERT_TRUE(bake::has_base_color(asset));
  const std::vector<Vec2> uvs = grid_uvs(asset.soup.triangles.size());
  const bake::RebakeResult baked = bake::rebake(asset, uvs, {.size = 2048, .padding = 4});
  EXPECT_EQ(baked.from, std::vector<std::string>{"texture"});
  EXPECT_FALSE(baked.baked_colors);
  const Errors e = compare(asset, uvs, baked);
  std::printf("%s: re-baked vs source at 1000 surface points: median %.2f/255, 90th percentile %.2f/255\n", name,
              e.median, e.p90);
  EXPECT_LE(e.median, 8.0);
  // Control: the same comparison reading each triangle's colour from another
  // triangle's cell (the wrong surface point) must differ, or the test proves nothing.
  const size_t n = asset.soup.triangles.size();
  std::vector<Vec2> shifted(uvs.size());
  for (size_t t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k) shifted[t * 3 + k] = uvs[((t + n / 2) % n) * 3 + k];
  const Errors wrong = compare(asset, shifted, baked);
  std::printf("%s: mean %.2f/255; control (another triangle's texels): mean %.2f/255\n", name, e.mean, wrong.mean);
  EXPECT_GT(wrong.mean, 4 * e.mean + 2.0);
  // The source's texture is not the re-bake's uniform grey background anywhere near.
  EXPECT_GT(baked.covered_texels, size_t(0));
}

TEST(Rebake, DuckMatchesItsTextureAtSurfacePoints) { check_sample("Duck.glb"); }
TEST(Rebake, CesiumManMatchesItsTextureAtSurfacePoints) { check_sample("CesiumMan.glb"); }

// Vertex colours without a texture: the baked texel at a triangle's centroid
// is the interpolated colour (sRGB-encoded), and COLOR_0 is reported baked.
TEST(Rebake, VertexColoursAreBaked) {
  io::Asset asset;
  asset.soup.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  asset.soup.triangles = {{0, 1, 2}};
  asset.soup.origins = {TriangleOrigin{}};
  asset.attributes.present = {io::VertexAttributes::kColor, io::VertexAttributes::kColor, io::VertexAttributes::kColor};
  asset.attributes.colors = {{1, 0, 0, 1}, {1, 0, 0, 1}, {1, 0, 0, 1}};
  const std::vector<Vec2> uvs = {{0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}};
  ASSERT_TRUE(bake::has_base_color(asset));
  const bake::RebakeResult baked = bake::rebake(asset, uvs, {.size = 64, .padding = 2});
  EXPECT_TRUE(baked.baked_colors);
  const bake::Image img = bake::decode_image(baked.texture.bytes);
  const unsigned char* centroid = &img.rgba[(size_t(20) * 64 + 20) * 4];
  EXPECT_EQ(centroid[0], 255);
  EXPECT_EQ(centroid[1], 0);
  EXPECT_EQ(centroid[2], 0);
  // The far corner (outside the triangle, beyond the dilation) keeps the background.
  const unsigned char* far = &img.rgba[(size_t(63) * 64 + 63) * 4];
  EXPECT_NE(far[0], 255);
}

// Dilation: texels just outside the triangle's edge take its colour.
TEST(Rebake, EdgesAreDilatedByThePadding) {
  io::Asset asset;
  asset.soup.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  asset.soup.triangles = {{0, 1, 2}};
  asset.soup.origins = {TriangleOrigin{}};
  asset.attributes.present = {io::VertexAttributes::kColor, io::VertexAttributes::kColor, io::VertexAttributes::kColor};
  asset.attributes.colors = {{0, 0, 1, 1}, {0, 0, 1, 1}, {0, 0, 1, 1}};
  const std::vector<Vec2> uvs = {{0.25, 0.25}, {0.75, 0.25}, {0.25, 0.75}};
  const bake::RebakeResult none = bake::rebake(asset, uvs, {.size = 64, .padding = 0});
  const bake::RebakeResult three = bake::rebake(asset, uvs, {.size = 64, .padding = 3});
  EXPECT_EQ(none.dilated_texels, 0u);
  EXPECT_GT(three.dilated_texels, 0u);
  const bake::Image img = bake::decode_image(three.texture.bytes);
  // Two texels left of the left edge (x = 16) at mid height: dilated blue.
  const unsigned char* p = &img.rgba[(size_t(30) * 64 + 14) * 4];
  EXPECT_EQ(p[2], 255);
  EXPECT_EQ(p[0], 0);
}

}  // namespace
