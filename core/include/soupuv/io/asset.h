// What the loader returns: the soup plus what the writer needs to put every
// triangle back in its original node/mesh/primitive/material structure.
#pragma once

#include <cstddef>
#include <string>

#include <nlohmann/json.hpp>

#include "soupuv/soup.h"

namespace soupuv::io {

enum class Format { glb, gltf, drc };

struct Asset {
  Format format = Format::glb;
  Soup soup;  // world space; soup.origins[t] says where triangle t came from
  // The source glTF JSON as parsed (nodes, meshes, materials, ...), without
  // buffer payloads; for a raw .drc a minimal synthesized document.
  nlohmann::json document;
  size_t dropped_degenerate = 0;  // zero-area triangles removed while loading
  size_t skipped_primitives = 0;  // points/lines primitives skipped (with a warning)
};

}  // namespace soupuv::io
