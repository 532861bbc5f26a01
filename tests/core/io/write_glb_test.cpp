// The GLB writer against an independent reader (write_test_reader.h): positions
// bit-exact in their own frame, UVs as float32, vertices split only where UVs
// differ, instances kept as a strict node tree, materials and texture, Draco.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>


#include "draco_payload.h"
#include "soupuv/baseline/box_projection.h"
#include "soupuv/errors.h"
#include "soupuv/io/write.h"
#include "testing/shapes.h"
#include "write_test_reader.h"

namespace soupuv::io {
namespace {

using nlohmann::json;
using testing::Glb;

// One mesh, one primitive, no nodes (like a raw .drc), positions rounded to
// float so that "bit-exact" has a float32 value to compare with.
Asset asset_from(const TriMesh& mesh, double noise = 0.0) {
  Asset a;
  a.soup = shapes::to_soup(mesh, noise, 3);
  for (Vec3& p : a.soup.positions) {
    std::array<float, 3> f = {float(p.x), float(p.y), float(p.z)};
    p = {f[0], f[1], f[2]};
    a.local_positions.push_back(f);
  }
  for (size_t t = 0; t < a.soup.triangles.size(); ++t) {
    a.soup.origins[t] = {-1, 0, 0, -1, static_cast<uint32_t>(t)};
    a.triangle_instance.push_back(0);
  }
  a.instances.push_back({-1, 0, {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}});
  a.document = {{"asset", {{"version", "2.0"}}},
                {"meshes", {{{"name", "shape"}, {"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}}}};
  return a;
}

uint32_t bits(float f) {
  uint32_t b;
  std::memcpy(&b, &f, 4);
  return b;
}

// Corners of the written primitive `prim` as (x, y, z, u, v) float tuples, per triangle.
std::vector<std::array<float, 5>> corners(const Glb& glb, const json& prim) {
  std::vector<float> p = glb.floats(prim["attributes"]["POSITION"]);
  std::vector<float> uv = glb.floats(prim["attributes"]["TEXCOORD_0"]);
  std::vector<uint32_t> idx = glb.indices(prim["indices"]);
  std::vector<std::array<float, 5>> out;
  for (uint32_t i : idx) out.push_back({p[i * 3], p[i * 3 + 1], p[i * 3 + 2], uv[i * 2], uv[i * 2 + 1]});
  return out;
}

TEST(WriteGlb, PositionsBitExactAndUvsFloat32) {
  Asset a = asset_from(shapes::torus(1.0, 0.35, 24, 12), 1e-3);
  std::vector<Vec2> uvs = baseline::box_projection(a.soup).corner_uvs;
  WriteResult r = write_glb(a, uvs);
  Glb glb(r.glb);
  ASSERT_EQ(glb.doc["meshes"].size(), 1u);
  const json& prim = glb.doc["meshes"][0]["primitives"][0];
  auto c = corners(glb, prim);
  ASSERT_EQ(c.size(), a.soup.triangles.size() * 3);
  for (size_t t = 0; t < a.soup.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const auto& got = c[t * 3 + k];
      const auto& want = a.local_positions[a.soup.triangles[t][k]];
      for (int d = 0; d < 3; ++d) ASSERT_EQ(bits(got[d]), bits(want[d])) << t << " " << k;
      EXPECT_EQ(bits(got[3]), bits(float(uvs[t * 3 + k].x)));
      EXPECT_EQ(bits(got[4]), bits(float(uvs[t * 3 + k].y)));
    }
  // POSITION min/max are the exact extremes (the validator insists).
  std::vector<float> p = glb.floats(prim["attributes"]["POSITION"]);
  const json& acc = glb.doc["accessors"][prim["attributes"]["POSITION"].get<int>()];
  for (int d = 0; d < 3; ++d) {
    float lo = INFINITY, hi = -INFINITY;
    for (size_t i = d; i < p.size(); i += 3) lo = std::min(lo, p[i]), hi = std::max(hi, p[i]);
    EXPECT_EQ(acc["min"][d].get<float>(), lo);
    EXPECT_EQ(acc["max"][d].get<float>(), hi);
  }
}

TEST(WriteGlb, SplitsVerticesExactlyWhereUvsDiffer) {
  // A welded cube as a soup of shared vertices: box UVs are continuous inside
  // a face and differ across the 12 cube edges.
  TriMesh cube = shapes::cube(1.0, 3);
  Asset a = asset_from(cube);
  // to_soup gives every triangle its own vertices; positions repeat, so
  // welding must merge the repeated (position, uv) corners.
  std::vector<Vec2> uvs = baseline::box_projection(a.soup).corner_uvs;
  std::set<std::array<uint32_t, 5>> distinct;
  for (size_t t = 0; t < a.soup.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      auto lp = a.local_positions[a.soup.triangles[t][k]];
      distinct.insert({bits(lp[0]), bits(lp[1]), bits(lp[2]), bits(float(uvs[t * 3 + k].x)),
                       bits(float(uvs[t * 3 + k].y))});
    }
  WriteResult r = write_glb(a, uvs);
  EXPECT_EQ(r.vertices, distinct.size());
  // 6 faces of 4x4 grid points: positions on cube edges are split per face.
  EXPECT_EQ(r.vertices, 6u * 16u);
}

TEST(WriteGlb, TextureIsAnEmbeddedPngOnTexcoord0) {
  Asset a = asset_from(shapes::icosphere(1.0, 1));
  WriteResult r = write_glb(a, baseline::box_projection(a.soup).corner_uvs);
  Glb glb(r.glb);
  ASSERT_EQ(glb.doc["images"].size(), 1u);
  const json& image = glb.doc["images"][0];
  EXPECT_EQ(image["mimeType"], "image/png");
  EXPECT_FALSE(image.contains("uri"));
  std::vector<uint8_t> png = glb.view(image["bufferView"]);
  ASSERT_GE(png.size(), 8u);
  EXPECT_EQ(png[1], 'P');
  EXPECT_EQ(png[2], 'N');
  const json& material = glb.doc["materials"][glb.doc["meshes"][0]["primitives"][0]["material"].get<int>()];
  EXPECT_EQ(material["pbrMetallicRoughness"]["baseColorTexture"]["texCoord"], 0);
  EXPECT_EQ(glb.doc["textures"][material["pbrMetallicRoughness"]["baseColorTexture"]["index"].get<int>()]["source"], 0);
}

TEST(WriteGlb, MaterialsKeptOtherTexturesDroppedWithWarning) {
  Asset a = asset_from(shapes::icosphere(1.0, 1));
  for (auto& o : a.soup.origins) o.material = 1;
  a.document["materials"] = {
      {{"name", "unused"}},
      {{"name", "paint"}, {"doubleSided", true}, {"alphaMode", "MASK"}, {"alphaCutoff", 0.3},
       {"normalTexture", {{"index", 4}}},
       {"pbrMetallicRoughness", {{"baseColorFactor", {1, 0.5, 0.25, 1}}, {"metallicFactor", 0.1},
                                 {"baseColorTexture", {{"index", 7}, {"texCoord", 1}}}}}}};
  a.document["skins"] = {{{"joints", {0}}}};
  a.document["animations"] = {{{"channels", json::array()}}};
  WriteResult r = write_glb(a, baseline::box_projection(a.soup).corner_uvs);
  Glb glb(r.glb);
  const json& prim = glb.doc["meshes"][0]["primitives"][0];
  ASSERT_EQ(prim["material"], 1);
  const json& m = glb.doc["materials"][1];
  EXPECT_EQ(m["name"], "paint");
  EXPECT_EQ(m["doubleSided"], true);
  EXPECT_EQ(m["alphaMode"], "MASK");
  EXPECT_EQ(m["pbrMetallicRoughness"]["baseColorFactor"][1], 0.5);
  EXPECT_EQ(m["pbrMetallicRoughness"]["baseColorTexture"]["index"], 0);
  EXPECT_EQ(m["pbrMetallicRoughness"]["baseColorTexture"]["texCoord"], 0);
  EXPECT_FALSE(m.contains("normalTexture"));
  EXPECT_FALSE(glb.doc.contains("skins"));
  EXPECT_FALSE(glb.doc.contains("animations"));
  auto warned = [&](const std::string& word) {
    return std::any_of(r.warnings.begin(), r.warnings.end(),
                       [&](const std::string& w) { return w.find(word) != std::string::npos; });
  };
  EXPECT_TRUE(warned("normalTexture"));
  EXPECT_TRUE(warned("skin 0 dropped"));  // not loaded: no inverse bind matrices to write
  EXPECT_TRUE(warned("animations"));
}

// CubeScaledInstances' shape: node 5 (the mesh) is the child of four nodes.
TEST(WriteGlb, InstancesBecomeAStrictTreeWithLocalPositions) {
  Asset a = asset_from(shapes::cube(1.0, 1));
  a.document["nodes"] = json::parse(R"([{"children":[1,2,3,4]},{"children":[5]},
      {"translation":[0,2,0],"scale":[4,4,4],"children":[5]},
      {"translation":[2,0,0],"scale":[2,2,2],"children":[5]},
      {"translation":[-2,0,0],"scale":[3,3,3],"children":[5]},{"mesh":0,"name":"cube"}])");
  a.document["scenes"] = json::parse(R"([{"nodes":[0]}])");
  struct Path { double s; Vec3 t; };
  const Path paths[4] = {{1, {0, 0, 0}}, {4, {0, 2, 0}}, {2, {2, 0, 0}}, {3, {-2, 0, 0}}};
  Asset b = a;
  b.soup = Soup{};
  b.local_positions.clear();
  b.triangle_instance.clear();
  b.instances.clear();
  // Listed in another order than the scene walk, to exercise the matching.
  for (int i : {2, 0, 3, 1}) {
    const Path& path = paths[i];
    uint32_t base = b.soup.positions.size();
    for (size_t v = 0; v < a.soup.positions.size(); ++v) {
      b.soup.positions.push_back(path.s * a.soup.positions[v] + path.t);
      b.local_positions.push_back(a.local_positions[v]);
    }
    for (size_t t = 0; t < a.soup.triangles.size(); ++t) {
      const Tri& tri = a.soup.triangles[t];
      b.soup.triangles.push_back({tri[0] + base, tri[1] + base, tri[2] + base});
      b.soup.origins.push_back({5, 0, 0, -1, static_cast<uint32_t>(t)});
      b.triangle_instance.push_back(b.instances.size());
    }
    MeshInstance inst{5, 0, {path.s, 0, 0, 0, 0, path.s, 0, 0, 0, 0, path.s, 0, path.t.x, path.t.y, path.t.z, 1}};
    b.instances.push_back(inst);
  }
  std::vector<Vec2> uvs = baseline::box_projection(b.soup).corner_uvs;
  WriteResult r = write_glb(b, uvs);
  EXPECT_EQ(r.meshes, 4u);
  Glb glb(r.glb);
  const json& nodes = glb.doc["nodes"];
  // Strict tree: every node has at most one parent and roots have none.
  std::vector<int> parents(nodes.size(), 0);
  for (const json& n : nodes)
    for (const json& c : n.value("children", json::array())) parents[c.get<int>()]++;
  for (const json& root : glb.doc["scenes"][0]["nodes"]) EXPECT_EQ(parents[root.get<int>()], 0);
  for (int p : parents) EXPECT_LE(p, 1);
  // Each mesh sits under the parent whose scale matches its instance: the
  // box UVs of instance i were computed from that instance's world positions.
  std::map<int, double> parent_scale;
  for (const json& n : nodes)
    for (const json& c : n.value("children", json::array()))
      parent_scale[c.get<int>()] = n.contains("scale") ? n["scale"][0].get<double>() : 1.0;
  int meshes_seen = 0;
  for (size_t i = 0; i < nodes.size(); ++i) {
    if (!nodes[i].contains("mesh")) continue;
    ++meshes_seen;
    EXPECT_EQ(nodes[i]["name"], "cube");
    auto c = corners(glb, glb.doc["meshes"][nodes[i]["mesh"].get<int>()]["primitives"][0]);
    // Which instance: the one whose scale the parent has.
    int instance = -1;
    for (int k = 0; k < 4; ++k)
      if (b.instances[k].world[0] == parent_scale[i]) instance = k;
    ASSERT_GE(instance, 0);
    size_t first = instance * a.soup.triangles.size();
    for (size_t t = 0; t < a.soup.triangles.size(); ++t)
      for (int k = 0; k < 3; ++k) {
        const auto& lp = b.local_positions[b.soup.triangles[first + t][k]];
        for (int d = 0; d < 3; ++d) ASSERT_EQ(bits(c[t * 3 + k][d]), bits(lp[d]));
        EXPECT_EQ(c[t * 3 + k][3], float(uvs[(first + t) * 3 + k].x));
      }
  }
  EXPECT_EQ(meshes_seen, 4);
}

TEST(WriteGlb, DracoDecodesBackToTheSameTriangles) {
  Asset a = asset_from(shapes::torus(1.0, 0.3, 30, 14), 1e-3);
  std::vector<Vec2> uvs = baseline::box_projection(a.soup).corner_uvs;
  WriteOptions options;
  options.draco = true;
  WriteResult r = write_glb(a, uvs, options);
  Glb glb(r.glb);
  EXPECT_EQ(glb.doc["extensionsUsed"][0], "KHR_draco_mesh_compression");
  EXPECT_EQ(glb.doc["extensionsRequired"][0], "KHR_draco_mesh_compression");
  const json& prim = glb.doc["meshes"][0]["primitives"][0];
  const json& ext = prim["extensions"]["KHR_draco_mesh_compression"];
  std::string error;
  const auto decoded = decode_draco_primitive(glb, prim, error);
  ASSERT_TRUE(decoded) << error;
  const draco::Mesh& mesh = *decoded;
  const draco::PointAttribute* pos = mesh.GetAttributeByUniqueId(ext["attributes"]["POSITION"]);
  const draco::PointAttribute* tex = mesh.GetAttributeByUniqueId(ext["attributes"]["TEXCOORD_0"]);
  ASSERT_TRUE(pos && tex);
  EXPECT_EQ(glb.doc["accessors"][prim["attributes"]["POSITION"].get<int>()]["count"], mesh.num_points());
  EXPECT_EQ(glb.doc["accessors"][prim["indices"].get<int>()]["count"], mesh.num_faces() * 3);
  // Draco reorders faces, points and corners: compare triangles as sorted
  // sets of rotation-normalised corner tuples, bit for bit (lossless mode).
  using Corner = std::array<uint32_t, 5>;
  using Triangle = std::array<Corner, 3>;
  auto canonical = [](Triangle t) {
    while (!(t[0] <= t[1] && t[0] <= t[2])) std::rotate(t.begin(), t.begin() + 1, t.end());
    return t;
  };
  std::multiset<Triangle> want, got;
  for (size_t t = 0; t < a.soup.triangles.size(); ++t) {
    Triangle tri;
    for (int k = 0; k < 3; ++k) {
      auto lp = a.local_positions[a.soup.triangles[t][k]];
      tri[k] = {bits(lp[0]), bits(lp[1]), bits(lp[2]), bits(float(uvs[t * 3 + k].x)), bits(float(uvs[t * 3 + k].y))};
    }
    want.insert(canonical(tri));
  }
  for (draco::FaceIndex f(0); f < mesh.num_faces(); ++f) {
    Triangle tri;
    for (int k = 0; k < 3; ++k) {
      draco::PointIndex p = mesh.face(f)[k];
      float xyz[3], uv[2];
      pos->GetMappedValue(p, xyz);
      tex->GetMappedValue(p, uv);
      tri[k] = {bits(xyz[0]), bits(xyz[1]), bits(xyz[2]), bits(uv[0]), bits(uv[1])};
    }
    got.insert(canonical(tri));
  }
  EXPECT_TRUE(want == got);
}

TEST(WriteGlb, FlatNormalsAreUnitAndPerpendicular) {
  Asset a = asset_from(shapes::torus(1.0, 0.4, 16, 8), 1e-3);
  WriteOptions options;
  options.normals = true;
  options.check_texture_size = 64;
  for (bool draco : {false, true}) {
    options.draco = draco;
    WriteResult r = write_glb(a, baseline::box_projection(a.soup).corner_uvs, options);
    Glb glb(r.glb);
    const json& prim = glb.doc["meshes"][0]["primitives"][0];
    ASSERT_TRUE(prim["attributes"].contains("NORMAL")) << draco;
    if (draco) {
      EXPECT_TRUE(prim["extensions"]["KHR_draco_mesh_compression"]["attributes"].contains("NORMAL"));
      continue;  // payload contents are checked by DracoDecodesBackToTheSameTriangles
    }
    std::vector<float> p = glb.floats(prim["attributes"]["POSITION"]);
    std::vector<float> n = glb.floats(prim["attributes"]["NORMAL"]);
    std::vector<uint32_t> idx = glb.indices(prim["indices"]);
    for (size_t t = 0; t < idx.size(); t += 3) {
      Vec3 c[3], nn[3];
      for (int k = 0; k < 3; ++k) {
        uint32_t v = idx[t + k];
        c[k] = {p[v * 3], p[v * 3 + 1], p[v * 3 + 2]};
        nn[k] = {n[v * 3], n[v * 3 + 1], n[v * 3 + 2]};
      }
      Vec3 want = normalized(cross(c[1] - c[0], c[2] - c[0]));
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(norm(nn[k]), 1.0, 1e-6);
        EXPECT_NEAR(dot(nn[k], want), 1.0, 1e-6);
      }
    }
  }
}

TEST(WriteGlb, NonFiniteUvsAreWrittenAsZeroWithAWarning) {
  Asset a = asset_from(shapes::icosphere(1.0, 0));
  std::vector<Vec2> uvs = baseline::box_projection(a.soup).corner_uvs;
  uvs[4] = {NAN, 0.5};
  WriteResult r = write_glb(a, uvs);
  EXPECT_EQ(r.nonfinite_uvs, 1u);
  EXPECT_FALSE(r.warnings.empty());
}

TEST(WriteGlb, UnknownMaterialGetsTheDefaultMaterial) {
  Asset a = asset_from(shapes::icosphere(1.0, 0));
  for (auto& o : a.soup.origins) o.material = 5;  // the document has no materials
  WriteOptions options;
  options.check_texture_size = 64;
  Glb glb(write_glb(a, baseline::box_projection(a.soup).corner_uvs, options).glb);
  ASSERT_EQ(glb.doc["materials"].size(), 1u);
  EXPECT_EQ(glb.doc["meshes"][0]["primitives"][0]["material"], 0);
  EXPECT_TRUE(glb.doc["materials"][0]["pbrMetallicRoughness"].contains("baseColorTexture"));
}

TEST(WriteGlb, WrongUvCountIsAnError) {
  Asset a = asset_from(shapes::icosphere(1.0, 0));
  std::vector<Vec2> uvs(5);
  EXPECT_THROW(write_glb(a, uvs), Error);
}

}  // namespace
}  // namespace soupuv::io
