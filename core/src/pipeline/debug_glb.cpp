// Minimal GLB files for the debug outputs: one mesh, float32 attributes,
// uint32 indices, optionally one embedded PNG texture. Not the product writer
// (io/write.h keeps the input's structure); these show intermediate results.
#include <cstring>

#include <nlohmann/json.hpp>

#include "soupuv/pipeline.h"

namespace soupuv {

namespace {

// Accumulates the BIN chunk and the JSON's bufferViews/accessors.
class GlbBuilder {
 public:
  nlohmann::json doc = {{"asset", {{"version", "2.0"}, {"generator", "soupuv debug"}}},
                        {"buffers", nlohmann::json::array()},
                        {"bufferViews", nlohmann::json::array()},
                        {"accessors", nlohmann::json::array()}};

  int view(const void* data, size_t bytes, int target) {
    while (bin_.size() % 4) bin_.push_back(0);
    size_t offset = bin_.size();
    bin_.resize(offset + bytes);
    if (bytes) std::memcpy(bin_.data() + offset, data, bytes);
    nlohmann::json v = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}};
    if (target) v["target"] = target;
    doc["bufferViews"].push_back(v);
    return int(doc["bufferViews"].size()) - 1;
  }

  int vec3_accessor(const std::vector<float>& xyz) {
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < xyz.size(); ++i) {
      lo[i % 3] = std::min(lo[i % 3], xyz[i]);
      hi[i % 3] = std::max(hi[i % 3], xyz[i]);
    }
    int v = view(xyz.data(), xyz.size() * 4, 34962);
    doc["accessors"].push_back({{"bufferView", v}, {"componentType", 5126}, {"count", xyz.size() / 3},
                                {"type", "VEC3"}, {"min", {lo[0], lo[1], lo[2]}}, {"max", {hi[0], hi[1], hi[2]}}});
    return int(doc["accessors"].size()) - 1;
  }

  int vec2_accessor(const std::vector<float>& uv) {
    int v = view(uv.data(), uv.size() * 4, 34962);
    doc["accessors"].push_back({{"bufferView", v}, {"componentType", 5126}, {"count", uv.size() / 2}, {"type", "VEC2"}});
    return int(doc["accessors"].size()) - 1;
  }

  int index_accessor(const std::vector<uint32_t>& idx) {
    int v = view(idx.data(), idx.size() * 4, 34963);
    doc["accessors"].push_back({{"bufferView", v}, {"componentType", 5125}, {"count", idx.size()}, {"type", "SCALAR"}});
    return int(doc["accessors"].size()) - 1;
  }

  std::vector<uint8_t> finish() {
    while (bin_.size() % 4) bin_.push_back(0);
    doc["buffers"].push_back({{"byteLength", bin_.size()}});
    std::string json = doc.dump();
    while (json.size() % 4) json.push_back(' ');
    std::vector<uint8_t> out;
    auto u32 = [&](uint32_t x) { for (int i = 0; i < 4; ++i) out.push_back(uint8_t(x >> (8 * i))); };
    u32(0x46546C67);  // "glTF"
    u32(2);
    u32(uint32_t(12 + 8 + json.size() + 8 + bin_.size()));
    u32(uint32_t(json.size()));
    u32(0x4E4F534A);  // "JSON"
    out.insert(out.end(), json.begin(), json.end());
    u32(uint32_t(bin_.size()));
    u32(0x004E4942);  // "BIN\0"
    out.insert(out.end(), bin_.begin(), bin_.end());
    return out;
  }

 private:
  std::vector<uint8_t> bin_;
};

}  // namespace

debug_bytes proxy_debug_glb(const MapDebug& debug, const std::vector<uint8_t>& texture_png) {
  const TriMesh& m = debug.proxy.mesh;
  std::vector<float> pos, uv;
  std::vector<uint32_t> idx;
  const bool has_uv = debug.atlas.face_uvs.size() == m.faces.size();
  // Three vertices per face: a seam gives a vertex several UVs.
  for (size_t f = 0; f < m.faces.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      Vec3 p = m.vertices[m.faces[f][k]];
      pos.insert(pos.end(), {float(p.x), float(p.y), float(p.z)});
      if (has_uv) uv.insert(uv.end(), {float(debug.atlas.face_uvs[f][k].x), float(debug.atlas.face_uvs[f][k].y)});
      idx.push_back(uint32_t(idx.size()));
    }
  GlbBuilder b;
  nlohmann::json prim = {{"attributes", {{"POSITION", b.vec3_accessor(pos)}}},
                         {"indices", b.index_accessor(idx)}, {"mode", 4}};
  if (has_uv && !texture_png.empty()) {
    prim["attributes"]["TEXCOORD_0"] = b.vec2_accessor(uv);
    int image_view = b.view(texture_png.data(), texture_png.size(), 0);
    b.doc["images"] = {{{"bufferView", image_view}, {"mimeType", "image/png"}}};
    b.doc["samplers"] = {{{"magFilter", 9729}, {"minFilter", 9987}}};
    b.doc["textures"] = {{{"source", 0}, {"sampler", 0}}};
    b.doc["materials"] = {{{"name", "proxy atlas"},
                           {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}},
                                                     {"metallicFactor", 0.0}}}}};
    prim["material"] = 0;
  }
  b.doc["meshes"] = {{{"name", "proxy"}, {"primitives", {prim}}}};
  b.doc["nodes"] = {{{"mesh", 0}, {"name", "proxy"}}};
  b.doc["scenes"] = {{{"nodes", {0}}}};
  b.doc["scene"] = 0;
  return b.finish();
}

debug_bytes field_lines_glb(const field::FieldLines& lines, size_t max_lines) {
  const size_t n = lines.size();
  const size_t stride = max_lines > 0 && n > max_lines ? (n + max_lines - 1) / max_lines : 1;
  std::vector<float> pos;
  std::vector<uint32_t> idx;
  for (size_t i = 0; i < n; i += stride) {
    uint32_t b = lines.offsets[i], e = lines.offsets[i + 1];
    for (uint32_t j = b; j < e; ++j) {
      if (j > b) idx.insert(idx.end(), {uint32_t(pos.size() / 3 - 1), uint32_t(pos.size() / 3)});
      const Vec3& p = lines.points[j];
      pos.insert(pos.end(), {float(p.x), float(p.y), float(p.z)});
    }
  }
  GlbBuilder b;
  nlohmann::json prim = {{"attributes", {{"POSITION", b.vec3_accessor(pos)}}}, {"mode", 1}};
  if (!idx.empty()) prim["indices"] = b.index_accessor(idx);
  b.doc["meshes"] = {{{"name", "field lines"}, {"primitives", {prim}}}};
  b.doc["nodes"] = {{{"mesh", 0}, {"name", "field lines"}}};
  b.doc["scenes"] = {{{"nodes", {0}}}};
  b.doc["scene"] = 0;
  return b.finish();
}

}  // namespace soupuv
