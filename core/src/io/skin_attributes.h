// A primitive's skinning attributes (JOINTS_n / WEIGHTS_n), read in pairs so
// that the writer can carry them to every output vertex like NORMAL.
//
// Input : the primitive's "attributes" object, its vertex count (POSITION's).
// Output: PrimitiveGeometry::joints / weights [n][vertex] and skin_bit(n) in
//         `present` for every set n < kMaxSkinSets whose JOINTS_n and
//         WEIGHTS_n are both readable VEC4s of the vertex count with joint
//         indices that are integers in [0, 65535]. Anything else is named in
//         `warnings` as dropped (never an error: the geometry still maps).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/buffer_table.h"
#include "io/primitive_geometry.h"

namespace soupuv::io::detail {

// True for JOINTS_* and WEIGHTS_* (read here, not by the generic attribute reader).
bool is_skin_attribute(const std::string& name);

void read_skin_attributes(const nlohmann::json& doc, BufferTable& buffers, const nlohmann::json& attributes,
                          size_t vertices, uint64_t max_bytes, const std::string& where, PrimitiveGeometry& out,
                          std::vector<std::string>& warnings);

}  // namespace soupuv::io::detail
