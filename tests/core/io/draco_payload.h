// The mesh a primitive's KHR_draco_mesh_compression payload decodes to, by
// Draco's own decoder (for the writer's tests: what a glTF consumer gets).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <draco/compression/decode.h>

#include "write_test_reader.h"

namespace soupuv::testing {

// Null, with `error` set, when the payload does not decode.
inline std::unique_ptr<draco::Mesh> decode_draco_primitive(const Glb& glb, const nlohmann::json& primitive,
                                                           std::string& error) {
  const std::vector<uint8_t> payload =
      glb.view(primitive["extensions"]["KHR_draco_mesh_compression"]["bufferView"]);
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(payload.data()), payload.size());
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok()) {
    error = decoded.status().error_msg();
    return nullptr;
  }
  return std::move(decoded).value();
}

}  // namespace soupuv::testing
