// What the loader returns: the soup plus what the writer needs to put every
// triangle back in its original node/mesh/primitive/material structure.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

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
  // For the writer's bit-exact round trip (requested by io-write): the float32
  // value of soup vertex v in its primitive's own frame, exactly as read from
  // the accessor (dequantized, before any node transform); parallel to
  // soup.positions. The writer needs each soup vertex to be used by triangles
  // of one (node, mesh) instance only (instanced meshes: one copy per node).
  // Empty when the loader did not record them: the writer then derives local
  // positions from world ones (not bit-exact under non-identity transforms).
  std::vector<std::array<float, 3>> local_positions;
};

}  // namespace soupuv::io
