// One glTF mesh primitive as local-space triangles.
//
// Input : the document, the BufferTable, mesh and primitive indices, limits.
// Output: PrimitiveGeometry — the vertices some triangle uses (local space,
//         as stored) and the triangles after TRIANGLES/STRIP/FAN expansion,
//         with their index in that expansion (source_index). POINTS/LINES
//         come back with skipped = true. Draco primitives are decoded from
//         their extension's bufferView. Errors: indices out of range,
//         non-finite positions (naming mesh/primitive/accessor), Draco counts
//         not matching the accessors.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/buffer_table.h"
#include "soupuv/vec.h"

namespace soupuv::io::detail {

struct PrimitiveGeometry {
  bool skipped = false;        // points or lines
  int32_t material = -1;
  std::vector<Vec3> positions;
  std::vector<Tri> triangles;
  std::vector<uint32_t> source_index;  // per triangle
  // Kept attributes, per vertex like `positions` (empty when absent):
  // VertexAttributes' bits in `present`.
  uint32_t present = 0;
  std::vector<std::array<float, 3>> normals;
  std::vector<std::array<float, 4>> colors;
  std::vector<std::vector<std::array<float, 2>>> texcoords;  // [n][vertex], n < kMaxTexcoords
  std::vector<std::vector<std::array<uint16_t, 4>>> joints;  // [n][vertex], n < kMaxSkinSets
  std::vector<std::vector<std::array<float, 4>>> weights;    // [n][vertex], with joints[n]
};

// Triangles that `index_count` indices make in glTF `mode` (0 for points/lines).
uint64_t triangles_for_mode(uint64_t mode, uint64_t index_count);

// The i-th triangle of a strip/fan/list, as indices into the index array.
Tri expand_triangle(uint64_t mode, uint64_t i);

// Keeps only vertices that triangles use, renumbering the triangles; checks
// every index is < positions.size() and every used position is finite.
// `kept`, when given, receives the old index of every kept vertex, in the new order.
void compact_and_check(std::vector<Vec3>& positions, std::vector<Tri>& triangles, const std::string& where,
                       std::vector<uint32_t>* kept = nullptr);

PrimitiveGeometry read_primitive(const nlohmann::json& doc, BufferTable& buffers, uint64_t mesh,
                                 uint64_t primitive, uint64_t max_bytes, uint64_t max_triangles,
                                 std::vector<std::string>& warnings);

}  // namespace soupuv::io::detail
