// A minimal, independent GLB reader for the writer's tests: it shares no code
// with the writer, so a round trip through it checks what a glTF consumer
// would see. It trusts its input (our own output) apart from range checks
// that turn mistakes into test failures instead of crashes.
#pragma once

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace soupuv::testing {

struct Glb {
  nlohmann::json doc;
  std::vector<uint8_t> bin;

  static uint32_t u32(const std::vector<uint8_t>& b, size_t at) {
    if (at + 4 > b.size()) throw std::runtime_error("GLB truncated");
    uint32_t v;
    std::memcpy(&v, &b[at], 4);
    return v;
  }

  explicit Glb(const std::vector<uint8_t>& bytes) {
    if (u32(bytes, 0) != 0x46546C67 || u32(bytes, 4) != 2) throw std::runtime_error("not GLB v2");
    if (u32(bytes, 8) != bytes.size()) throw std::runtime_error("GLB length mismatch");
    uint32_t json_length = u32(bytes, 12);
    if (u32(bytes, 16) != 0x4E4F534A || json_length % 4 != 0) throw std::runtime_error("bad JSON chunk");
    doc = nlohmann::json::parse(bytes.begin() + 20, bytes.begin() + 20 + json_length);
    size_t at = 20 + json_length;
    if (at < bytes.size()) {
      uint32_t bin_length = u32(bytes, at);
      if (u32(bytes, at + 4) != 0x004E4942 || bin_length % 4 != 0) throw std::runtime_error("bad BIN chunk");
      if (at + 8 + bin_length != bytes.size()) throw std::runtime_error("BIN chunk size mismatch");
      bin.assign(bytes.begin() + at + 8, bytes.end());
    }
  }

  // The bytes of bufferView v.
  std::vector<uint8_t> view(int v) const {
    const auto& bv = doc["bufferViews"][v];
    size_t offset = bv.value("byteOffset", 0), length = bv["byteLength"];
    if (offset + length > bin.size()) throw std::runtime_error("bufferView beyond BIN");
    return {bin.begin() + offset, bin.begin() + offset + length};
  }

  // Accessor a as floats (float32 components only), tightly packed.
  std::vector<float> floats(int a) const {
    const auto& acc = doc["accessors"][a];
    if (acc["componentType"] != 5126) throw std::runtime_error("not a float accessor");
    const std::string type = acc["type"];
    size_t comps = type == "MAT4" ? 16 : type == "VEC4" ? 4 : type == "VEC3" ? 3 : type == "VEC2" ? 2 : 1;
    size_t count = acc["count"];
    std::vector<uint8_t> bytes = view(acc["bufferView"]);
    size_t offset = acc.value("byteOffset", 0);
    if (offset + count * comps * 4 > bytes.size()) throw std::runtime_error("accessor beyond view");
    std::vector<float> out(count * comps);
    std::memcpy(out.data(), bytes.data() + offset, out.size() * 4);
    return out;
  }

  std::vector<uint32_t> indices(int a) const {
    const auto& acc = doc["accessors"][a];
    size_t count = acc["count"];
    std::vector<uint8_t> bytes = view(acc["bufferView"]);
    size_t offset = acc.value("byteOffset", 0);
    int type = acc["componentType"];
    size_t size = type == 5125 ? 4 : type == 5123 ? 2 : 1;
    if (offset + count * size > bytes.size()) throw std::runtime_error("indices beyond view");
    std::vector<uint32_t> out(count);
    for (size_t i = 0; i < count; ++i) {
      const uint8_t* p = bytes.data() + offset + i * size;
      out[i] = size == 4 ? (p[0] | p[1] << 8 | p[2] << 16 | uint32_t(p[3]) << 24)
             : size == 2 ? (p[0] | p[1] << 8) : p[0];
    }
    return out;
  }
};

}  // namespace soupuv::testing
