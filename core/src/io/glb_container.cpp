#include "io/glb_container.h"

#include <string>

#include "io/checked_json.h"

namespace soupuv::io::detail {
namespace {

constexpr uint32_t kMagic = 0x46546C67;      // "glTF"
constexpr uint32_t kChunkJson = 0x4E4F534A;  // "JSON"
constexpr uint32_t kChunkBin = 0x004E4942;   // "BIN\0"

uint32_t read_u32(std::span<const uint8_t> b, size_t at) {
  return uint32_t(b[at]) | uint32_t(b[at + 1]) << 8 | uint32_t(b[at + 2]) << 16 |
         uint32_t(b[at + 3]) << 24;
}

}  // namespace

bool has_glb_magic(std::span<const uint8_t> bytes) {
  return bytes.size() >= 4 && read_u32(bytes, 0) == kMagic;
}

GlbChunks parse_glb(std::span<const uint8_t> bytes) {
  const uint64_t size = bytes.size();
  if (size < 12) fail_input("GLB: file of " + std::to_string(size) + " bytes is shorter than the 12-byte header");
  if (read_u32(bytes, 0) != kMagic) fail_input("GLB: bad magic (not 'glTF')");
  uint32_t version = read_u32(bytes, 4);
  if (version != 2) fail_input("GLB: version " + std::to_string(version) + " is not 2");
  uint64_t length = read_u32(bytes, 8);
  if (length != size)
    fail_input("GLB: header length " + std::to_string(length) + " does not match the file size " +
               std::to_string(size) + (length > size ? " (truncated or lying header)" : ""));

  GlbChunks out;
  uint64_t at = 12;
  int index = 0;
  while (at < length) {
    if (length - at < 8)
      fail_input("GLB: chunk " + std::to_string(index) + " header runs past the end of the file");
    uint64_t chunk_length = read_u32(bytes, size_t(at));
    uint32_t type = read_u32(bytes, size_t(at + 4));
    uint64_t data_at = at + 8;
    if (chunk_length > length - data_at)
      fail_input("GLB: chunk " + std::to_string(index) + " of " + std::to_string(chunk_length) +
                 " bytes runs past the end of the file");
    // Chunks start and end on 4-byte boundaries; anything else is a broken writer.
    if (chunk_length % 4 != 0)
      fail_input("GLB: chunk " + std::to_string(index) + " length " + std::to_string(chunk_length) +
                 " is not a multiple of 4");
    auto data = bytes.subspan(size_t(data_at), size_t(chunk_length));
    if (index == 0) {
      if (type != kChunkJson) fail_input("GLB: first chunk is not JSON");
      if (chunk_length == 0) fail_input("GLB: JSON chunk is empty");
      out.json = data;
    } else if (index == 1 && type == kChunkBin) {
      out.bin = data;
      out.has_bin = true;
    } else if (type == kChunkJson || type == kChunkBin) {
      fail_input("GLB: chunk " + std::to_string(index) + " repeats a JSON or BIN chunk");
    }
    // Other chunk types are extensions' business and are skipped by the spec.
    at = data_at + chunk_length;
    ++index;
  }
  if (index == 0) fail_input("GLB: no JSON chunk");
  return out;
}

}  // namespace soupuv::io::detail
