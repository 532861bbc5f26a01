// The glTF buffers and bufferViews, resolved lazily and checked.
//
// Input : the parsed document, the GLB BIN chunk (if any) and the LoadOptions.
// Output: for a bufferView index, its byte range (view inside the buffer,
//         buffer at least byteLength long) and byteStride; every failure is an
//         Error with a one-line reason. Buffers nobody reads are never touched,
//         so unused or missing files are not errors. External URIs are read
//         only when options allow them, and only below options.base_dir.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "soupuv/io/load.h"

namespace soupuv::io::detail {

struct ViewBytes {
  std::span<const uint8_t> bytes;
  uint64_t stride = 0;  // 0: tightly packed
};

class BufferTable {
 public:
  // `budget` is the number of bytes still allowed to be loaded (data: and
  // external buffers count against LoadOptions::max_bytes together with the file).
  BufferTable(const nlohmann::json& doc, std::span<const uint8_t> glb_bin, bool has_bin,
              const LoadOptions& options, uint64_t budget);

  std::span<const uint8_t> buffer(uint64_t index, const std::string& where);
  ViewBytes view(uint64_t index, const std::string& where);
  // The bytes a buffer or image URI names (data: or an allowed external file),
  // counted against the same byte budget.
  std::vector<uint8_t> read_uri(const std::string& uri, const std::string& where);

 private:
  std::vector<uint8_t> read_external(const std::string& uri, const std::string& where);

  const nlohmann::json& doc_;
  std::span<const uint8_t> glb_bin_;
  bool has_bin_;
  const LoadOptions& options_;
  uint64_t budget_;
  std::vector<std::unique_ptr<std::vector<uint8_t>>> owned_;  // decoded/external buffers
  std::vector<std::span<const uint8_t>> resolved_;
  std::vector<bool> is_resolved_;
};

// Percent-decodes a relative URI and checks that it stays inside base_dir;
// returns the file path to read. Throws Error{unsupported|invalid_input}.
std::string resolve_external_path(const std::string& uri, const std::string& base_dir);

}  // namespace soupuv::io::detail
