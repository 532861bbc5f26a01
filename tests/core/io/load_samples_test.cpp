// Every shared sample loads with the triangle count an independent reader
// (a short Python script walking the JSON, accessors and node matrices,
// counting zero-area triangles) found; node transforms, Draco and the
// external-URI switch are checked against known geometry.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "load_test_support.h"
#include "soupuv/errors.h"
#include "soupuv/io/load.h"

using namespace soupuv;
using namespace soupuv::io;
using test::data_path;

namespace {

LoadOptions local_files(const std::string& dir) {
  LoadOptions o;
  o.allow_external_uris = true;
  o.base_dir = data_path(dir);
  return o;
}

void expect_consistent(const Asset& a) {
  const Soup& s = a.soup;
  ASSERT_EQ(s.origins.size(), s.triangles.size());
  ASSERT_EQ(a.triangle_instance.size(), s.triangles.size());
  ASSERT_EQ(a.local_positions.size(), s.positions.size());
  for (const Tri& t : s.triangles)
    for (uint32_t v : t) ASSERT_LT(v, s.positions.size());
  for (uint32_t i : a.triangle_instance) ASSERT_LT(i, a.instances.size());
  for (const Vec3& p : s.positions) ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
  for (size_t t = 0; t < s.triangles.size(); ++t) ASSERT_GT(triangle_area(s, t), 0.0);
}

struct Sample {
  const char* path;
  const char* dir;  // non-null: external buffers allowed below this directory
  size_t triangles;
};

// Counts from the independent Python reader (see file comment).
const Sample kSamples[] = {
    {"gltf/Box.glb", nullptr, 12},
    {"gltf/Box_Draco.glb", nullptr, 12},
    {"gltf/CesiumMan.glb", nullptr, 4672},
    {"gltf/Duck.glb", nullptr, 4212},
    {"gltf/BoxMetaDraco/BoxMetaDraco.gltf", "gltf/BoxMetaDraco", 12},
    {"gltf/CubeScaledInstances/cube_att.gltf", "gltf/CubeScaledInstances", 48},
    {"gltf/Fox/Fox.gltf", "gltf/Fox", 576},
    {"gltf/SimpleSparseAccessor/SimpleSparseAccessor.gltf", "gltf/SimpleSparseAccessor", 12},
    {"gltf/Triangle/Triangle.gltf", "gltf/Triangle", 1},
    {"gltf/Triangle/Triangle_identity_matrix.gltf", "gltf/Triangle", 1},
    {"gltf/Triangle/Triangle_translation_only_matrix.gltf", "gltf/Triangle", 1},
    {"gltf/TwoSidedPlane/TwoSidedPlane.gltf", "gltf/TwoSidedPlane", 2},
    {"gltf/ZeroLengthBufferView/ZeroLengthBufferView.gltf", "gltf/ZeroLengthBufferView", 2},
    {"soups/fandisk-soup.glb", nullptr, 12946},
    {"soups/fandisk-soup.original.glb", nullptr, 12946},
    {"soups/spot-soup.glb", nullptr, 5856},
    {"soups/spot-soup.original.glb", nullptr, 5856},
    {"soups/spot-soup-draco.glb", nullptr, 5856},
    {"soups/stanford-bunny-soup.glb", nullptr, 69451},
    {"soups/stanford-bunny-soup.original.glb", nullptr, 69451},
    {"soups/suzanne-soup.glb", nullptr, 968},
    {"soups/suzanne-soup.original.glb", nullptr, 968},
    {"soups/teapot-soup.glb", nullptr, 6320},
    {"soups/teapot-soup.original.glb", nullptr, 6320},
};

}  // namespace

TEST(LoadSamples, EverySampleLoadsWithItsTriangleCount) {
  for (const Sample& s : kSamples) {
    SCOPED_TRACE(s.path);
    LoadOptions o = s.dir ? local_files(s.dir) : LoadOptions{};
    Asset a = load_file(data_path(s.path), o);
    EXPECT_EQ(a.soup.triangle_count(), s.triangles);
    EXPECT_EQ(a.dropped_degenerate, 0u);
    expect_consistent(a);
  }
}

TEST(LoadSamples, SoupSamplesAreSoupsAndOriginalsAreNot) {
  Asset soup = load_file(data_path("soups/suzanne-soup.glb"));
  Asset original = load_file(data_path("soups/suzanne-soup.original.glb"));
  // The loader keeps the source's vertex sharing within a primitive.
  EXPECT_TRUE(sharing_stats(soup.soup).is_soup);
  EXPECT_FALSE(sharing_stats(original.soup).is_soup);
  // Same triangle order: triangle i of the soup is a noisy copy of triangle i.
  double diag = bounding_box(original.soup).diagonal();
  for (size_t t = 0; t < soup.soup.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k)
      ASSERT_LT(norm(soup.soup.corner(t, k) - original.soup.corner(t, k)), 2e-3 * diag);
}

TEST(LoadSamples, RawDracoFilesDecode) {
  // cube_att is a cube: 12 triangles over [0,1]^3 (as in CubeScaledInstances).
  Asset cube = load_file(data_path("drc/cube_att.drc"));
  EXPECT_EQ(cube.format, Format::drc);
  EXPECT_EQ(cube.soup.triangle_count(), 12u);
  Box3 box = bounding_box(cube.soup);
  EXPECT_NEAR(box.lo.x, 0, 1e-6);
  EXPECT_NEAR(box.hi.y, 1, 1e-6);
  expect_consistent(cube);
  for (const char* f : {"drc/test_nm.drc", "drc/bunny_gltf.drc"}) {
    SCOPED_TRACE(f);
    Asset a = load_file(data_path(f));
    EXPECT_GT(a.soup.triangle_count(), 10u);
    EXPECT_EQ(a.soup.origins[0].node, -1);
    expect_consistent(a);
  }
}

TEST(LoadSamples, CubeScaledInstancesAppliesEveryNodePath) {
  Asset a = load_file(data_path("gltf/CubeScaledInstances/cube_att.gltf"), local_files("gltf/CubeScaledInstances"));
  // Node 5 carries the unit cube [0,1]^3 and has four parents: identity,
  // T(0,2,0)S(4), T(2,0,0)S(2), T(-2,0,0)S(3).
  ASSERT_EQ(a.instances.size(), 4u);
  std::map<uint32_t, Box3> boxes;
  for (size_t t = 0; t < a.soup.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) boxes[a.triangle_instance[t]].add(a.soup.corner(t, k));
  struct Expected { Vec3 lo, hi; };
  const Expected expected[] = {{{0, 0, 0}, {1, 1, 1}}, {{0, 2, 0}, {4, 6, 4}}, {{2, 0, 0}, {4, 2, 2}}, {{-2, 0, 0}, {1, 3, 3}}};
  for (uint32_t i = 0; i < 4; ++i) {
    EXPECT_EQ(a.instances[i].node, 5);
    for (int c = 0; c < 3; ++c) {
      EXPECT_DOUBLE_EQ(boxes[i].lo[c], expected[i].lo[c]) << "instance " << i;
      EXPECT_DOUBLE_EQ(boxes[i].hi[c], expected[i].hi[c]) << "instance " << i;
    }
  }
  Box3 all = bounding_box(a.soup);
  EXPECT_DOUBLE_EQ(all.lo.x, -2);
  EXPECT_DOUBLE_EQ(all.hi.y, 6);
}

TEST(LoadSamples, TriangleNodeMatrices) {
  Asset plain = load_file(data_path("gltf/Triangle/Triangle.gltf"), local_files("gltf/Triangle"));
  Asset moved = load_file(data_path("gltf/Triangle/Triangle_translation_only_matrix.gltf"), local_files("gltf/Triangle"));
  ASSERT_EQ(plain.soup.triangle_count(), 1u);
  ASSERT_EQ(moved.soup.triangle_count(), 1u);
  for (int k = 0; k < 3; ++k) {
    Vec3 d = moved.soup.corner(0, k) - plain.soup.corner(0, k);
    EXPECT_DOUBLE_EQ(d.x, 1.0);
    EXPECT_DOUBLE_EQ(d.y, 0.0);
  }
}

TEST(LoadSamples, IdentityTransformsKeepFloatInputsBitExact) {
  // Duck.glb scales its mesh by a node matrix; the soup samples have none.
  Asset a = load_file(data_path("soups/spot-soup.glb"));
  ASSERT_EQ(a.instances.size(), 1u);
  for (size_t v = 0; v < a.soup.positions.size(); ++v)
    for (int c = 0; c < 3; ++c) ASSERT_EQ(a.soup.positions[v][c], double(a.local_positions[v][c]));
  // And under a non-identity transform the local positions are still the stored floats.
  Asset duck = load_file(data_path("gltf/Duck.glb"));
  const Mat4& m = duck.instances[0].world;
  const auto& l = duck.local_positions[0];
  Vec3 w = duck.soup.positions[0];
  EXPECT_NEAR(w.x, m[0] * l[0] + m[4] * l[1] + m[8] * l[2] + m[12], 1e-9);
  EXPECT_NEAR(w.y, m[1] * l[0] + m[5] * l[1] + m[9] * l[2] + m[13], 1e-9);
}

TEST(LoadSamples, OriginsPointBackIntoTheDocument) {
  Asset a = load_file(data_path("gltf/Duck.glb"));
  const auto& doc = a.document;
  for (const TriangleOrigin& o : a.soup.origins) {
    ASSERT_GE(o.node, 0);
    ASSERT_EQ(doc["nodes"][o.node]["mesh"].get<int>(), o.mesh);
    ASSERT_LT(size_t(o.primitive), doc["meshes"][o.mesh]["primitives"].size());
    ASSERT_EQ(doc["meshes"][o.mesh]["primitives"][o.primitive].value("material", -1), o.material);
  }
  // Source indices enumerate the primitive's triangles in order.
  for (size_t t = 0; t < a.soup.triangle_count(); ++t) ASSERT_EQ(a.soup.origins[t].source_index, t);
}

TEST(LoadSamples, BoxAndBoxDracoGiveTheSameSoup) {
  Asset plain = load_file(data_path("gltf/Box.glb"));
  Asset draco = load_file(data_path("gltf/Box_Draco.glb"));
  ASSERT_EQ(plain.soup.triangle_count(), draco.soup.triangle_count());
  // Draco may reorder triangles and corners: match each triangle by its
  // sorted corners, within the quantization step (box of size 1, >= 11 bits).
  const double tol = 1e-3;
  auto key = [](const Soup& s, size_t t) {
    std::array<Vec3, 3> c{s.corner(t, 0), s.corner(t, 1), s.corner(t, 2)};
    std::sort(c.begin(), c.end(), [](Vec3 a, Vec3 b) {
      return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
    });
    return c;
  };
  std::vector<bool> used(draco.soup.triangle_count(), false);
  for (size_t t = 0; t < plain.soup.triangle_count(); ++t) {
    auto a = key(plain.soup, t);
    bool found = false;
    for (size_t u = 0; u < draco.soup.triangle_count() && !found; ++u) {
      if (used[u]) continue;
      auto b = key(draco.soup, u);
      bool same = true;
      for (int k = 0; k < 3; ++k) same = same && norm(a[k] - b[k]) < tol;
      if (same) used[u] = found = true;
    }
    EXPECT_TRUE(found) << "plain triangle " << t << " has no Draco twin";
  }
  Box3 pb = bounding_box(plain.soup), db = bounding_box(draco.soup);
  EXPECT_NEAR(norm(pb.lo - db.lo), 0, tol);
  EXPECT_NEAR(norm(pb.hi - db.hi), 0, tol);
}

TEST(LoadSamples, ExternalUrisRefusedUnlessAllowedWithBaseDir) {
  const std::string fox = data_path("gltf/Fox/Fox.gltf");
  auto code_of = [](auto&& f) {
    try {
      f();
    } catch (const Error& e) {
      return e.code();
    }
    return ErrorCode::internal;  // "no error" for these tests
  };
  EXPECT_EQ(code_of([&] { load_file(fox); }), ErrorCode::unsupported);
  LoadOptions allowed_without_dir;
  allowed_without_dir.allow_external_uris = true;
  // load_memory has no file to take a directory from: still refused.
  auto bytes = test::read_bytes(fox);
  EXPECT_EQ(code_of([&] { load_memory(bytes, allowed_without_dir); }), ErrorCode::unsupported);
  LoadOptions dir_without_allow;
  dir_without_allow.base_dir = data_path("gltf/Fox");
  EXPECT_EQ(code_of([&] { load_memory(bytes, dir_without_allow); }), ErrorCode::unsupported);
  EXPECT_EQ(load_memory(bytes, local_files("gltf/Fox")).soup.triangle_count(), 576u);
  // load_file with allow and no base_dir uses the file's own directory.
  EXPECT_EQ(load_file(fox, allowed_without_dir).soup.triangle_count(), 576u);

  // external-uri.gltf names /etc/passwd: refused even when external URIs are allowed.
  const std::string evil = data_path("bad/external-uri.gltf");
  EXPECT_EQ(code_of([&] { load_file(evil); }), ErrorCode::unsupported);
  EXPECT_EQ(code_of([&] { load_file(evil, local_files("bad")); }), ErrorCode::unsupported);
  // A relative climb out of the base directory is refused too.
  nlohmann::json doc = nlohmann::json::parse(test::read_bytes(data_path("gltf/Triangle/Triangle.gltf")));
  doc["buffers"][0]["uri"] = "../Triangle/simpleTriangle.bin";
  std::string text = doc.dump();
  std::vector<uint8_t> climbing(text.begin(), text.end());
  EXPECT_EQ(code_of([&] { load_memory(climbing, local_files("gltf/Triangle")); }), ErrorCode::unsupported);
  doc["buffers"][0]["uri"] = "simpleTriangle.bin";
  text = doc.dump();
  std::vector<uint8_t> inside(text.begin(), text.end());
  EXPECT_EQ(load_memory(inside, local_files("gltf/Triangle")).soup.triangle_count(), 1u);
}
