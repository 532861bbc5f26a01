// Loader features on small hand-built files whose every byte the test states:
// strips and fans, quantized and strided positions, sparse accessors without a
// bufferView, degenerate triangles, node graphs (TRS, cycles, DAG blow-up),
// accessor overruns and refused extensions.
#include <gtest/gtest.h>

#include "load_test_support.h"
#include "soupuv/errors.h"
#include "soupuv/io/load.h"

using namespace soupuv;
using namespace soupuv::io;
using nlohmann::json;

namespace {

// Four vertices of a unit square in z = 0, as floats.
const std::vector<float> kSquare = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};

ErrorCode error_code(const std::vector<uint8_t>& bytes, const LoadOptions& options = {}) {
  try {
    load_memory(bytes, options);
  } catch (const Error& e) {
    return e.code();
  }
  return ErrorCode::internal;  // stands for "loaded"
}

std::vector<uint8_t> square_glb(json doc, const std::vector<uint16_t>& indices) {
  std::vector<uint8_t> bin;
  test::append(bin, kSquare);
  test::append(bin, indices);
  return test::make_glb(doc, bin);
}

}  // namespace

TEST(LoadFeatures, TriangleStripAndFanExpand) {
  // Strip over index positions 0 1 2 3 holding vertices 0 1 3 2: triangle 0
  // takes positions (0,1,2), the odd triangle 1 takes (1,3,2) per the glTF
  // spec, i.e. vertices (1,2,3), keeping the winding.
  Asset strip = load_memory(square_glb(test::one_mesh_doc(4, 4, 5), {0, 1, 3, 2}));
  ASSERT_EQ(strip.soup.triangle_count(), 2u);
  EXPECT_EQ(strip.soup.origins[1].source_index, 1u);
  Vec3 n0 = triangle_normal(strip.soup, 0), n1 = triangle_normal(strip.soup, 1);
  EXPECT_GT(dot(n0, n1), 0.99);  // consistent winding
  EXPECT_DOUBLE_EQ(strip.soup.corner(1, 0).x, 1.0);  // vertex 1 = (1,0,0)
  EXPECT_DOUBLE_EQ(strip.soup.corner(1, 0).y, 0.0);
  EXPECT_DOUBLE_EQ(strip.soup.corner(1, 1).y, 1.0);  // vertex 2 = (1,1,0)
  EXPECT_DOUBLE_EQ(strip.soup.corner(1, 2).x, 0.0);  // vertex 3 = (0,1,0)

  Asset fan = load_memory(square_glb(test::one_mesh_doc(4, 4, 6), {0, 1, 2, 3}));
  ASSERT_EQ(fan.soup.triangle_count(), 2u);
  EXPECT_GT(dot(triangle_normal(fan.soup, 0), triangle_normal(fan.soup, 1)), 0.99);
  double area = triangle_area(fan.soup, 0) + triangle_area(fan.soup, 1);
  EXPECT_DOUBLE_EQ(area, 1.0);
}

TEST(LoadFeatures, NonIndexedTrianglesAndDegeneratesDropped) {
  // Two triangles without indices; the second repeats a vertex (zero area).
  std::vector<float> pos = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0};
  std::vector<uint8_t> bin;
  test::append(bin, pos);
  Asset a = load_memory(test::make_glb(test::one_mesh_doc(6, 0), bin));
  EXPECT_EQ(a.soup.triangle_count(), 1u);
  EXPECT_EQ(a.dropped_degenerate, 1u);
  EXPECT_EQ(a.soup.origins[0].source_index, 0u);
  ASSERT_FALSE(a.soup.warnings.empty());
  EXPECT_NE(a.soup.warnings.back().find("zero-area"), std::string::npos);
  // Only vertices kept triangles use are in the soup.
  EXPECT_EQ(a.soup.positions.size(), 3u);
}

TEST(LoadFeatures, QuantizedStridedPositions) {
  // KHR_mesh_quantization: normalized unsigned shorts, each VEC3 padded to 8
  // bytes by byteStride.
  std::vector<uint16_t> q = {0, 0, 0, 0, 65535, 0, 0, 0, 0, 65535, 0, 0};
  std::vector<uint16_t> idx = {0, 1, 2, 0};
  std::vector<uint8_t> bin;
  test::append(bin, q);
  test::append(bin, idx);
  json doc = test::one_mesh_doc(3, 3);
  doc["extensionsUsed"] = {"KHR_mesh_quantization"};
  doc["extensionsRequired"] = {"KHR_mesh_quantization"};
  doc["accessors"][0]["componentType"] = 5123;
  doc["accessors"][0]["normalized"] = true;
  doc["bufferViews"][0] = {{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 24}, {"byteStride", 8}};
  doc["bufferViews"][1]["byteOffset"] = 24;
  doc["buffers"][0]["byteLength"] = 32;
  Asset a = load_memory(test::make_glb(doc, bin));
  ASSERT_EQ(a.soup.triangle_count(), 1u);
  EXPECT_DOUBLE_EQ(a.soup.corner(0, 1).x, 1.0);
  EXPECT_DOUBLE_EQ(a.soup.corner(0, 2).y, 1.0);

  // A stride smaller than the element is malformed.
  doc["bufferViews"][0]["byteStride"] = 4;
  EXPECT_EQ(error_code(test::make_glb(doc, bin)), ErrorCode::invalid_input);
}

TEST(LoadFeatures, SparseAccessorWithoutBufferViewStartsFromZeros) {
  // POSITION: 3 zero vertices, two replaced sparsely -> one proper triangle.
  std::vector<uint8_t> bin;
  test::append(bin, std::vector<uint16_t>{1, 2});
  test::append(bin, std::vector<float>{1, 0, 0, 0, 1, 0});
  json doc = {
      {"asset", {{"version", "2.0"}}},
      {"nodes", {{{"mesh", 0}}}},
      {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}}},
      {"accessors", {{{"componentType", 5126}, {"count", 3}, {"type", "VEC3"},
                      {"sparse", {{"count", 2},
                                  {"indices", {{"bufferView", 0}, {"componentType", 5123}}},
                                  {"values", {{"bufferView", 1}}}}}}}},
      {"bufferViews", {{{"buffer", 0}, {"byteLength", 4}}, {{"buffer", 0}, {"byteOffset", 4}, {"byteLength", 24}}}},
      {"buffers", {{{"byteLength", 28}}}},
  };
  Asset a = load_memory(test::make_glb(doc, bin));
  ASSERT_EQ(a.soup.triangle_count(), 1u);
  EXPECT_DOUBLE_EQ(triangle_area(a.soup, 0), 0.5);
  // A sparse index past the accessor count is caught.
  bin[0] = 7;
  EXPECT_EQ(error_code(test::make_glb(doc, bin)), ErrorCode::invalid_input);
}

TEST(LoadFeatures, NodeTrsNestingAndScenes) {
  json doc = test::one_mesh_doc(4, 6);
  // Root translates by (10,0,0) and holds a child rotated 90 deg about z and
  // scaled by 2: local (1,0,0) -> (0,2,0) -> world (10,2,0).
  const double h = std::sqrt(0.5);
  doc["nodes"] = {{{"translation", {10, 0, 0}}, {"children", {1}}},
                  {{"rotation", {0, 0, h, h}}, {"scale", {2, 2, 2}}, {"mesh", 0}},
                  {{"mesh", 0}}};  // not in any scene: ignored
  doc["scenes"] = {{{"nodes", {0}}}};
  Asset a = load_memory(square_glb(doc, {0, 1, 2, 0, 2, 3}));
  ASSERT_EQ(a.soup.triangle_count(), 2u);
  EXPECT_EQ(a.soup.origins[0].node, 1);
  Vec3 p = a.soup.corner(0, 1);  // vertex 1 = (1,0,0)
  EXPECT_NEAR(p.x, 10, 1e-12);
  EXPECT_NEAR(p.y, 2, 1e-12);
  // Without scenes every root node counts: now node 2 too.
  doc.erase("scenes");
  EXPECT_EQ(load_memory(square_glb(doc, {0, 1, 2, 0, 2, 3})).soup.triangle_count(), 4u);
}

TEST(LoadFeatures, NodeCyclesAndBlowUpAreRefused) {
  json doc = test::one_mesh_doc(4, 6);
  doc["nodes"] = {{{"children", {1}}}, {{"children", {0}}, {"mesh", 0}}};
  doc["scenes"] = {{{"nodes", {0}}}};
  EXPECT_EQ(error_code(square_glb(doc, {0, 1, 2, 0, 2, 3})), ErrorCode::invalid_input);
  // A ladder of 40 nodes, each with two edges to the next: 2^40 paths.
  json nodes = json::array();
  for (int i = 0; i < 40; ++i) nodes.push_back({{"children", {i + 1, i + 1}}});
  nodes.push_back({{"mesh", 0}});
  doc["nodes"] = nodes;
  EXPECT_EQ(error_code(square_glb(doc, {0, 1, 2, 0, 2, 3})), ErrorCode::limit_exceeded);
}

TEST(LoadFeatures, OverrunsAndBadReferencesAreInvalidInput) {
  json doc = test::one_mesh_doc(4, 6);
  auto glb = [&] { return square_glb(doc, {0, 1, 2, 0, 2, 3}); };
  ASSERT_EQ(load_memory(glb()).soup.triangle_count(), 2u);
  json good = doc;
  doc["accessors"][0]["byteOffset"] = 4;  // last vertex now runs past the view
  EXPECT_EQ(error_code(glb()), ErrorCode::invalid_input);
  doc = good;
  doc["bufferViews"][1]["byteLength"] = 1u << 30;  // view past the buffer
  EXPECT_EQ(error_code(glb()), ErrorCode::invalid_input);
  doc = good;
  doc["accessors"][1]["count"] = uint64_t(1) << 62;  // count * size overflows
  EXPECT_NE(error_code(glb()), ErrorCode::internal);
  doc = good;
  doc["meshes"][0]["primitives"][0]["material"] = 3;  // no materials array
  EXPECT_EQ(error_code(glb()), ErrorCode::invalid_input);
  doc = good;
  doc["accessors"][1]["componentType"] = 5126;  // float indices
  EXPECT_EQ(error_code(glb()), ErrorCode::invalid_input);
  doc = good;
  doc["nodes"][0]["mesh"] = "zero";
  EXPECT_EQ(error_code(glb()), ErrorCode::invalid_input);
  doc = good;
  doc["buffers"][0]["byteLength"] = 1000;  // more than the BIN chunk holds
  EXPECT_EQ(error_code(glb()), ErrorCode::invalid_input);
}

TEST(LoadFeatures, DataUriBuffersAndDocument) {
  std::vector<uint8_t> bin;
  test::append(bin, kSquare);
  test::append(bin, std::vector<uint16_t>{0, 1, 2, 0, 2, 3});
  json doc = test::one_mesh_doc(4, 6);
  doc["buffers"][0]["uri"] = "data:application/gltf-buffer;base64," + test::base64(bin);
  doc["images"] = {{{"uri", "missing-texture.png"}}};  // never read: not an error
  doc["buffers"].push_back({{"byteLength", 10}, {"uri", "unused.bin"}});  // unused: not an error
  std::string text = doc.dump();
  Asset a = load_memory(std::vector<uint8_t>(text.begin(), text.end()));
  EXPECT_EQ(a.format, Format::gltf);
  EXPECT_EQ(a.soup.triangle_count(), 2u);
  EXPECT_FALSE(a.document["buffers"][0].contains("uri"));  // payload not kept
  EXPECT_EQ(a.document["images"][0]["uri"], "missing-texture.png");

  doc["buffers"][0]["uri"] = "data:application/gltf-buffer;base64,AAAA*AAA";
  text = doc.dump();
  EXPECT_EQ(error_code(std::vector<uint8_t>(text.begin(), text.end())), ErrorCode::invalid_input);
}

TEST(LoadFeatures, RequiredGeometryExtensionsWeCannotReadAreRefused) {
  json doc = test::one_mesh_doc(4, 6);
  doc["extensionsRequired"] = {"EXT_meshopt_compression"};
  EXPECT_EQ(error_code(square_glb(doc, {0, 1, 2, 0, 2, 3})), ErrorCode::unsupported);
  doc["extensionsRequired"] = {"KHR_texture_transform"};  // materials only: fine
  EXPECT_EQ(load_memory(square_glb(doc, {0, 1, 2, 0, 2, 3})).soup.triangle_count(), 2u);
  doc["asset"]["version"] = "1.0";
  EXPECT_EQ(error_code(square_glb(doc, {0, 1, 2, 0, 2, 3})), ErrorCode::unsupported);
}

TEST(LoadFeatures, MorphTargetsAndLinesGiveWarnings) {
  json doc = test::one_mesh_doc(4, 6);
  doc["meshes"][0]["primitives"][0]["targets"] = json::array({{{"POSITION", 0}}});
  json lines = doc["meshes"][0]["primitives"][0];
  lines.erase("targets");
  lines["mode"] = 1;
  doc["meshes"][0]["primitives"].push_back(lines);
  Asset a = load_memory(square_glb(doc, {0, 1, 2, 0, 2, 3}));
  EXPECT_EQ(a.soup.triangle_count(), 2u);
  EXPECT_EQ(a.skipped_primitives, 1u);
  EXPECT_EQ(a.soup.warnings.size(), 2u);
}

TEST(LoadFeatures, GlbContainerChecks) {
  std::vector<uint8_t> good = square_glb(test::one_mesh_doc(4, 6), {0, 1, 2, 0, 2, 3});
  ASSERT_EQ(load_memory(good).soup.triangle_count(), 2u);
  auto patched = [&](size_t at, uint32_t v) {
    std::vector<uint8_t> b = good;
    for (int i = 0; i < 4; ++i) b[at + i] = uint8_t(v >> (8 * i));
    return b;
  };
  EXPECT_EQ(error_code(patched(4, 1)), ErrorCode::invalid_input);                   // version 1
  EXPECT_EQ(error_code(patched(8, uint32_t(good.size() + 4))), ErrorCode::invalid_input);  // length lie
  EXPECT_EQ(error_code(patched(12, 0xFFFFFFF0u)), ErrorCode::invalid_input);       // JSON chunk too long
  EXPECT_EQ(error_code(patched(12, 5)), ErrorCode::invalid_input);                 // misaligned chunk
  EXPECT_EQ(error_code(patched(16, 0x004E4942)), ErrorCode::invalid_input);        // BIN first
  std::vector<uint8_t> trailing = good;
  trailing.insert(trailing.end(), 4, 0);  // bytes after the declared length
  EXPECT_EQ(error_code(trailing), ErrorCode::invalid_input);
}
