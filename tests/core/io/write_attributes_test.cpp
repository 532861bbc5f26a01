// The output keeps what it can of the input's vertex attributes, one test per
// kind: NORMAL (Duck), COLOR_0 (a small GLB built here), TEXCOORD_n moved to
// TEXCOORD_n+1 with the same values (Duck), and the drops named in the
// warnings: TANGENT (TwoSidedPlane). Skinning attributes and their skin:
// write_skin_test.cpp.
// Each written GLB is loaded back and compared corner by corner (triangle
// order is kept per primitive, and these samples have one primitive each).
#include <gtest/gtest.h>

#include <cmath>

#include "load_test_support.h"
#include "shared_data.h"
#include "soupuv/baseline/box_projection.h"
#include "soupuv/io/load.h"
#include "soupuv/io/write.h"

namespace soupuv::io {
namespace {

struct RoundTrip {
  Asset before, after;
  WriteResult written;
};

RoundTrip round_trip(Asset before, const WriteOptions& options = {}) {
  const auto uvs = baseline::box_projection(before.soup).corner_uvs;
  RoundTrip r{std::move(before), {}, {}};
  r.written = write_glb(r.before, uvs, options);
  r.after = load_memory(r.written.glb);
  return r;
}

RoundTrip sample(const char* rel) {
  LoadOptions options;
  options.allow_external_uris = true;  // a .gltf's files beside it, as the CLI reads them
  return round_trip(load_file(soupuv_test::shared_data_dir() + "/" + rel, options));
}

bool has_warning(const WriteResult& w, const Asset& a, const std::string& part) {
  for (const auto* list : {&w.warnings, &a.soup.warnings})
    for (const auto& s : *list)
      if (s.find(part) != std::string::npos) return true;
  return false;
}

// Attribute of corner k of triangle t, before and after.
template <class Get>
void expect_corners_equal(const RoundTrip& r, Get get, float tolerance) {
  ASSERT_EQ(r.before.soup.triangles.size(), r.after.soup.triangles.size());
  for (size_t t = 0; t < r.before.soup.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const auto a = get(r.before, r.before.soup.triangles[t][k]);
      const auto b = get(r.after, r.after.soup.triangles[t][k]);
      for (size_t c = 0; c < a.size(); ++c) ASSERT_NEAR(a[c], b[c], tolerance) << "triangle " << t << " corner " << k;
    }
}

TEST(WriteAttributes, NormalKept) {
  RoundTrip r = sample("gltf/Duck.glb");
  ASSERT_FALSE(r.before.attributes.normals.empty());
  ASSERT_FALSE(r.after.attributes.normals.empty());
  EXPECT_NE(std::find(r.written.attributes.begin(), r.written.attributes.end(), "NORMAL"), r.written.attributes.end());
  expect_corners_equal(r, [](const Asset& a, uint32_t v) {
    auto n = a.attributes.normals[v];
    const float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    return std::array<float, 3>{n[0] / len, n[1] / len, n[2] / len};  // written normalized
  }, 1e-6f);
}

TEST(WriteAttributes, TexcoordsMoveUpOneSet) {
  RoundTrip r = sample("gltf/Duck.glb");
  ASSERT_EQ(r.before.attributes.texcoords.size(), 1u);
  ASSERT_EQ(r.after.attributes.texcoords.size(), 2u);  // the new map, then the source's
  expect_corners_equal(r, [&](const Asset& a, uint32_t v) {
    return &a == &r.before ? a.attributes.texcoords[0][v] : a.attributes.texcoords[1][v];
  }, 0.0f);
}

TEST(WriteAttributes, ColorKeptOrLeftOutWhenBaked) {
  // One triangle with float RGB COLOR_0 (alpha 1 on reading).
  std::vector<uint8_t> bin;
  test::append(bin, std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0});
  test::append(bin, std::vector<float>{1, 0, 0, 0, 1, 0, 0, 0, 1});
  nlohmann::json doc = test::one_mesh_doc(3, 0);
  doc["buffers"][0]["byteLength"] = bin.size();
  doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 36}});
  doc["accessors"].push_back({{"bufferView", 1}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}});
  doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = 1;
  Asset in = load_memory(test::make_glb(doc, bin));
  ASSERT_EQ(in.attributes.colors.size(), 3u);
  RoundTrip kept = round_trip(in);
  ASSERT_EQ(kept.after.attributes.colors.size(), 3u);
  expect_corners_equal(kept, [](const Asset& a, uint32_t v) { return a.attributes.colors[v]; }, 0.0f);
  WriteOptions baked;
  baked.keep_colors = false;
  RoundTrip dropped = round_trip(in, baked);
  EXPECT_TRUE(dropped.after.attributes.colors.empty());
}

TEST(WriteAttributes, TangentDroppedWithAWarning) {
  RoundTrip r = sample("gltf/TwoSidedPlane/TwoSidedPlane.gltf");
  EXPECT_TRUE(has_warning(r.written, r.before, "TANGENT dropped"));
  EXPECT_FALSE(r.after.attributes.normals.empty());  // NORMAL of the same primitive kept
}

}  // namespace
}  // namespace soupuv::io
