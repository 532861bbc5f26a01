#include "soupuv/server/upload_check.h"

#include <cstdint>
#include <cstring>
#include <fstream>

#include <nlohmann/json.hpp>

namespace soupuv::server {
namespace {

constexpr uint64_t kMaxJsonBytes = 64ull << 20;

UploadVerdict bad(const std::string& detail) { return {false, "invalid-model", detail}; }

uint32_t le32(const unsigned char* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

UploadVerdict check_uris(const nlohmann::json& doc) {
  if (!doc.is_object()) return bad("glTF JSON must be an object");
  for (const char* key : {"buffers", "images"}) {
    if (!doc.contains(key)) continue;
    if (!doc[key].is_array()) return bad(std::string(key) + " must be an array");
    for (const auto& item : doc[key]) {
      if (!item.is_object() || !item.contains("uri")) continue;
      const auto& uri = item["uri"];
      if (!uri.is_string() || uri.get<std::string>().rfind("data:", 0) != 0)
        return {false, "external-uri",
                std::string("external URI in ") + key +
                    " refused: uploads must be self-contained (GLB, or glTF with data: URIs)"};
    }
  }
  return {};
}

UploadVerdict parse_and_check(const std::string& text) {
  auto doc = nlohmann::json::parse(text, nullptr, false);
  if (doc.is_discarded()) return bad("the glTF JSON does not parse");
  return check_uris(doc);
}

}  // namespace

const char* file_name_for(ModelKind kind) {
  switch (kind) {
    case ModelKind::glb: return "input.glb";
    case ModelKind::gltf: return "input.gltf";
    case ModelKind::draco: return "input.drc";
  }
  return "input.bin";
}

UploadVerdict check_model_file(const std::filesystem::path& file, ModelKind kind) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return {false, "internal", "upload vanished"};
  in.seekg(0, std::ios::end);
  const uint64_t size = uint64_t(in.tellg());
  in.seekg(0);
  if (size == 0) return bad("the upload is empty");

  if (kind == ModelKind::draco) {
    char magic[5] = {};
    in.read(magic, 5);
    if (size < 5 || std::memcmp(magic, "DRACO", 5) != 0) return bad("not a Draco file (no DRACO magic)");
    return {};
  }
  if (kind == ModelKind::gltf) {
    if (size > kMaxJsonBytes) return {false, "too-large", "glTF JSON larger than 64 MiB"};
    std::string text(size, '\0');
    in.read(text.data(), std::streamsize(size));
    return parse_and_check(text);
  }
  unsigned char header[20] = {};
  in.read(reinterpret_cast<char*>(header), 20);
  if (size < 20) return bad("too short for a GLB (needs a 12-byte header and a chunk header)");
  if (std::memcmp(header, "glTF", 4) != 0) return bad("not a GLB: the magic is not 'glTF'");
  if (le32(header + 4) != 2) return bad("unsupported GLB version " + std::to_string(le32(header + 4)));
  if (le32(header + 8) != size)
    return bad("GLB header length " + std::to_string(le32(header + 8)) + " differs from the " +
               std::to_string(size) + " bytes received");
  const uint64_t json_len = le32(header + 12);
  if (le32(header + 16) != 0x4E4F534Au) return bad("the first GLB chunk is not JSON");
  if (json_len > size - 20 || json_len > kMaxJsonBytes) return bad("GLB JSON chunk runs past the end of the file");
  std::string text(json_len, '\0');
  in.read(text.data(), std::streamsize(json_len));
  return parse_and_check(text);
}

}  // namespace soupuv::server
