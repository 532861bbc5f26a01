// The binary side of the writer (see gltf_write_parts.h): the BIN chunk built
// view by view, and the GLB container around JSON and BIN.
#include <cstring>

#include "gltf_write_parts.h"
#include "soupuv/errors.h"

namespace soupuv::io::detail {

namespace {

void pad_to_4(std::vector<uint8_t>& bytes, uint8_t fill) {
  while (bytes.size() % 4 != 0) bytes.push_back(fill);
}

void put_u32(std::vector<uint8_t>& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<uint8_t>(v >> (8 * i)));
}

}  // namespace

int BinBuilder::add_view(std::span<const uint8_t> bytes, int target) {
  pad_to_4(data_, 0);  // every accessor component type divides 4
  nlohmann::json view = {{"buffer", 0}, {"byteOffset", data_.size()}, {"byteLength", bytes.size()}};
  if (target != 0) view["target"] = target;
  data_.insert(data_.end(), bytes.begin(), bytes.end());
  views_.push_back(view);
  return static_cast<int>(views_.size()) - 1;
}

std::vector<uint8_t> pack_glb(const nlohmann::json& document, const std::vector<uint8_t>& bin) {
  std::string text = document.dump();
  std::vector<uint8_t> json_chunk(text.begin(), text.end());
  pad_to_4(json_chunk, ' ');
  std::vector<uint8_t> bin_chunk = bin;
  pad_to_4(bin_chunk, 0);
  uint64_t total = 12 + 8 + json_chunk.size() + (bin_chunk.empty() ? 0 : 8 + bin_chunk.size());
  if (total > 0xFFFFFFFFull)
    throw Error(ErrorCode::limit_exceeded, "output GLB would exceed 4 GiB");
  std::vector<uint8_t> glb;
  glb.reserve(total);
  put_u32(glb, 0x46546C67);  // "glTF"
  put_u32(glb, 2);
  put_u32(glb, static_cast<uint32_t>(total));
  put_u32(glb, static_cast<uint32_t>(json_chunk.size()));
  put_u32(glb, 0x4E4F534A);  // "JSON"
  glb.insert(glb.end(), json_chunk.begin(), json_chunk.end());
  if (!bin_chunk.empty()) {
    put_u32(glb, static_cast<uint32_t>(bin_chunk.size()));
    put_u32(glb, 0x004E4942);  // "BIN\0"
    glb.insert(glb.end(), bin_chunk.begin(), bin_chunk.end());
  }
  return glb;
}

}  // namespace soupuv::io::detail
