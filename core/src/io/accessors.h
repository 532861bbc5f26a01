// Reading glTF accessors into plain arrays, with every extent checked.
//
// Input : the document, the BufferTable, an accessor index.
// Output: read_positions — count × VEC3 as double (float exactly; normalized
//         and KHR_mesh_quantization integers converted per the glTF spec);
//         read_indices — count × uint32 (UNSIGNED_BYTE/SHORT/INT SCALAR).
//         Sparse substitution is applied; accessors without a bufferView are zeros.
//         Errors: invalid_input (offset + stride*(count-1) + element size past
//         the view, bad types, sparse indices out of range), limit_exceeded.
#pragma once

#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/buffer_table.h"
#include "soupuv/vec.h"

namespace soupuv::io::detail {

// Count of an accessor (for limit checks and Draco count matching).
uint64_t accessor_count(const nlohmann::json& doc, uint64_t accessor);

std::vector<Vec3> read_positions(const nlohmann::json& doc, BufferTable& buffers, uint64_t accessor,
                                 uint64_t max_bytes);
// Any accessor as float components (normalized integers converted by the
// glTF formulas); `components` is set to its per-element count.
std::vector<float> read_floats(const nlohmann::json& doc, BufferTable& buffers, uint64_t accessor,
                               uint64_t max_bytes, uint64_t& components);
std::vector<uint32_t> read_indices(const nlohmann::json& doc, BufferTable& buffers, uint64_t accessor,
                                   uint64_t max_bytes);

}  // namespace soupuv::io::detail
