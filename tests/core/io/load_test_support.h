// Helpers for the loader tests: reading sample files and building small GLB /
// glTF files in memory so each test states exactly the bytes it feeds in.
#pragma once

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include "shared_data.h"

namespace soupuv::io::test {

inline std::string data_path(const std::string& relative) {
  return soupuv_test::shared_data_dir() + "/" + relative;
}

inline std::vector<uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void put_u32(std::vector<uint8_t>& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(uint8_t(v >> (8 * i)));
}

// A GLB of `doc` and `bin` (padded to 4 bytes as the container requires).
inline std::vector<uint8_t> make_glb(const nlohmann::json& doc, std::vector<uint8_t> bin) {
  std::string json = doc.dump();
  while (json.size() % 4) json.push_back(' ');
  while (bin.size() % 4) bin.push_back(0);
  std::vector<uint8_t> out;
  uint32_t total = uint32_t(12 + 8 + json.size() + (bin.empty() ? 0 : 8 + bin.size()));
  put_u32(out, 0x46546C67);
  put_u32(out, 2);
  put_u32(out, total);
  put_u32(out, uint32_t(json.size()));
  put_u32(out, 0x4E4F534A);
  out.insert(out.end(), json.begin(), json.end());
  if (!bin.empty()) {
    put_u32(out, uint32_t(bin.size()));
    put_u32(out, 0x004E4942);
    out.insert(out.end(), bin.begin(), bin.end());
  }
  return out;
}

template <typename T>
void append(std::vector<uint8_t>& bin, const std::vector<T>& values) {
  size_t at = bin.size();
  bin.resize(at + values.size() * sizeof(T));
  std::memcpy(bin.data() + at, values.data(), values.size() * sizeof(T));
}

inline std::string base64(const std::vector<uint8_t>& bytes) {
  static const char* abc = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t v = uint32_t(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= uint32_t(bytes[i + 1]) << 8;
    if (i + 2 < bytes.size()) v |= bytes[i + 2];
    out += abc[(v >> 18) & 63];
    out += abc[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? abc[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? abc[v & 63] : '=';
  }
  return out;
}

// A one-node, one-mesh document over a single buffer of `byte_length` bytes:
// POSITION (float VEC3, `vertices`) at offset 0 and, when index_count > 0,
// uint16 indices right after.
inline nlohmann::json one_mesh_doc(uint32_t vertices, uint32_t index_count, uint32_t mode = 4) {
  nlohmann::json doc = {
      {"asset", {{"version", "2.0"}}},
      {"scenes", {{{"nodes", {0}}}}},
      {"nodes", {{{"mesh", 0}}}},
      {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", vertices}, {"type", "VEC3"}}}},
      {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", vertices * 12}}}},
      {"buffers", {{{"byteLength", vertices * 12 + index_count * 2}}}},
  };
  nlohmann::json prim = {{"attributes", {{"POSITION", 0}}}, {"mode", mode}};
  if (index_count) {
    doc["accessors"].push_back({{"bufferView", 1}, {"componentType", 5123}, {"count", index_count}, {"type", "SCALAR"}});
    doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", vertices * 12}, {"byteLength", index_count * 2}});
    prim["indices"] = 1;
  }
  doc["meshes"] = {{{"primitives", {prim}}}};
  return doc;
}

}  // namespace soupuv::io::test
