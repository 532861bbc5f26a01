// Loader -> writer -> loader on the shared samples: the written GLB loads back
// to the same triangles, bit for bit — local positions and world positions —
// with the UVs we wrote (read back through the independent test reader).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>

#include "soupuv/baseline/box_projection.h"
#include "soupuv/io/load.h"
#include "soupuv/io/write.h"
#include "write_test_reader.h"
#include "shared_data.h"

namespace soupuv::io {
namespace {

using Corner = std::array<uint64_t, 3>;  // bit patterns of a world position
using Triangle = std::array<Corner, 3>;

uint64_t bits(double d) {
  uint64_t b;
  std::memcpy(&b, &d, 8);
  return b;
}

// World-space triangles as exact bit patterns, rotated to a canonical first
// corner (the writer keeps winding) and sorted (it may regroup triangles).
std::vector<Triangle> world_triangles(const Soup& soup) {
  std::vector<Triangle> out;
  for (size_t t = 0; t < soup.triangles.size(); ++t) {
    Triangle tri;
    for (int k = 0; k < 3; ++k) {
      Vec3 p = soup.corner(t, k);
      tri[k] = {bits(p.x), bits(p.y), bits(p.z)};
    }
    std::rotate(tri.begin(), std::min_element(tri.begin(), tri.end()), tri.end());
    out.push_back(tri);
  }
  std::sort(out.begin(), out.end());
  return out;
}

class WriteRoundTrip : public ::testing::TestWithParam<const char*> {};

TEST_P(WriteRoundTrip, SameTrianglesBitForBit) {
  std::string path = soupuv_test::shared_data_dir() + "/" + GetParam();
  LoadOptions options;
  options.allow_external_uris = true;
  Asset before = load_file(path, options);
  std::vector<Vec2> uvs = baseline::box_projection(before.soup).corner_uvs;
  WriteOptions write_options;
  write_options.check_texture_size = 64;  // the texture is not under test here
  WriteResult written = write_glb(before, uvs, write_options);
  EXPECT_EQ(written.triangles, before.soup.triangle_count());

  Asset after = load_memory(written.glb);
  ASSERT_EQ(after.soup.triangle_count(), before.soup.triangle_count());
  EXPECT_TRUE(world_triangles(after.soup) == world_triangles(before.soup))
      << "world positions changed in the round trip";
  EXPECT_EQ(after.instances.size(), before.instances.size());

  // Local positions, as float bits, per instance and in the source order of
  // each primitive; compared as sorted multisets since instances may reorder.
  auto locals = [](const Asset& a) {
    std::vector<std::array<uint32_t, 3>> out;
    for (const auto& p : a.local_positions) {
      std::array<uint32_t, 3> b;
      std::memcpy(b.data(), p.data(), 12);
      out.push_back(b);
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  };
  EXPECT_TRUE(locals(after) == locals(before)) << "local positions changed";

  // Every written UV is one we computed (float32 of it).
  testing::Glb glb(written.glb);
  std::vector<std::array<float, 2>> want;
  for (const Vec2& uv : uvs) want.push_back({float(uv.x), float(uv.y)});
  std::sort(want.begin(), want.end());
  for (const auto& mesh : glb.doc["meshes"])
    for (const auto& prim : mesh["primitives"]) {
      std::vector<float> got = glb.floats(prim["attributes"]["TEXCOORD_0"]);
      for (size_t i = 0; i < got.size(); i += 2)
        ASSERT_TRUE(std::binary_search(want.begin(), want.end(), std::array<float, 2>{got[i], got[i + 1]}));
    }
}

// Lossless Draco output, decoded by our loader: the same triangles, bit for bit.
TEST(WriteRoundTripDraco, SameTrianglesBitForBit) {
  for (const char* name : {"gltf/CubeScaledInstances/cube_att.gltf", "soups/spot-soup.glb", "gltf/CesiumMan.glb"}) {
    LoadOptions options;
    options.allow_external_uris = true;
    Asset before = load_file(soupuv_test::shared_data_dir() + "/" + name, options);
    WriteOptions write_options;
    write_options.draco = true;
    write_options.check_texture_size = 64;
    WriteResult written = write_glb(before, baseline::box_projection(before.soup).corner_uvs, write_options);
    Asset after = load_memory(written.glb);
    EXPECT_TRUE(world_triangles(after.soup) == world_triangles(before.soup)) << name;
  }
}

INSTANTIATE_TEST_SUITE_P(Samples, WriteRoundTrip,
                         ::testing::Values("gltf/Box.glb", "gltf/Box_Draco.glb", "gltf/Duck.glb",
                                           "gltf/CesiumMan.glb", "gltf/Fox/Fox.gltf",
                                           "gltf/CubeScaledInstances/cube_att.gltf",
                                           "gltf/SimpleSparseAccessor/SimpleSparseAccessor.gltf",
                                           "gltf/Triangle/Triangle.gltf",
                                           "gltf/Triangle/Triangle_translation_only_matrix.gltf",
                                           "gltf/TwoSidedPlane/TwoSidedPlane.gltf",
                                           "drc/cube_att.drc", "soups/suzanne-soup.glb",
                                           "soups/spot-soup-draco.glb"),
                         [](const auto& info) {
                           std::string name = info.param;
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

}  // namespace
}  // namespace soupuv::io
