// The GLB binary container, checked before anything inside it is trusted.
//
// Input : the whole file's bytes.
// Output: the JSON chunk and the optional BIN chunk as sub-ranges of the
//         input, or Error{invalid_input} when the magic, version 2, the total
//         length, the chunk order/types, chunk sizes or 4-byte alignment are wrong.
#pragma once

#include <cstdint>
#include <span>

namespace soupuv::io::detail {

struct GlbChunks {
  std::span<const uint8_t> json;
  std::span<const uint8_t> bin;  // empty when the file has no BIN chunk
  bool has_bin = false;
};

bool has_glb_magic(std::span<const uint8_t> bytes);
GlbChunks parse_glb(std::span<const uint8_t> bytes);

}  // namespace soupuv::io::detail
