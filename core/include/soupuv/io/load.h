// Loading untrusted glTF / GLB / Draco input into a Soup, defensively: the GLB
// container, every accessor and every Draco payload are checked before use,
// and external URIs are refused unless explicitly allowed.
//
// Input : a file path or a byte range; LoadOptions (limits, external URIs).
// Output: an Asset (soup in world space + source document), or
//         soupuv::Error{invalid_input | unsupported | limit_exceeded | no_triangles}
//         with a one-line, specific message.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "soupuv/io/asset.h"

namespace soupuv::io {

struct LoadOptions {
  // External buffer/image URIs are refused unless this is set AND base_dir is
  // given (load_file gives the file's own folder). The CLI sets it unless
  // --no-external-files; the server's workers load an upload's own folder.
  // data: URIs are always allowed.
  bool allow_external_uris = false;
  std::string base_dir;
  uint64_t max_bytes = 1ull << 30;        // input file size limit
  uint64_t max_triangles = 20'000'000;    // after expanding strips/fans and instancing
};

// Loads a file; the format is sniffed from the content (GLB magic, '{' for
// glTF JSON, "DRACO" for raw Draco), not from the extension. With
// allow_external_uris and an empty base_dir, the file's own directory is the
// base directory (the CLI case); relative URIs may not leave it ('..',
// absolute paths, schemes and symlinks leading out are refused).
Asset load_file(const std::string& path, const LoadOptions& options = {});

// Loads from memory; external URIs are resolved against options.base_dir only
// when allowed.
Asset load_memory(std::span<const uint8_t> bytes, const LoadOptions& options = {});

}  // namespace soupuv::io
