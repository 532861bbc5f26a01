// The picture test: renders the mapped soup with the UV-check texture from
// four views to a PNG in the build tree (pictures/), so a person can look at
// continuity; and checks the rendering is a picture of the object.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "pipeline_support.h"
#include "render.h"
#include "soupuv/io/texture.h"
#include "soupuv/quality/uv_layout.h"

using namespace soupuv;
using namespace soupuv::testing;

namespace {
void save(const std::string& name, const std::vector<uint8_t>& bytes) {
  std::filesystem::path dir = std::filesystem::path(SOUPUV_BINARY_DIR) / "pictures";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / name, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), long(bytes.size()));
}
}  // namespace

TEST(Picture, TorusWithCheckTexture) {
  TriMesh mesh = shapes::torus_with(1.0, 0.45, 800);
  Soup soup = shapes::to_soup(mesh, 1e-3, 1);
  MapResult r = run_map(soup, fast_options());
  std::vector<Vec3> corners;
  for (size_t t = 0; t < soup.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) corners.push_back(soup.corner(t, k));
  render::Rgba tex = render::decode_image(io::uv_check_texture(512).bytes);
  render::Rgba img = render::render_views(corners, r.corner_uvs, tex, 256);
  save("torus-field.png", quality::encode_png(img.pixels, img.width, img.height));
  save("torus-field-uv.png", quality::uv_layout_png(r.corner_uvs, 512));
  // The object covers a good part of each view, and no pixel is magenta
  // (non-finite UVs).
  size_t covered = 0, magenta = 0;
  for (size_t i = 0; i < img.pixels.size(); i += 4) {
    bool background = img.pixels[i] == 48 && img.pixels[i + 1] == 52 && img.pixels[i + 2] == 60;
    covered += !background;
    magenta += img.pixels[i] > 200 && img.pixels[i + 1] < 30 && img.pixels[i + 2] > 200;
  }
  size_t total = img.pixels.size() / 4;
  EXPECT_GT(covered, total / 6);
  EXPECT_EQ(magenta, 0u);
}
