// Welding the per-thread output of the grid extractors (marching cubes,
// marching tetrahedra): every surface vertex is created on a grid edge and
// named by that edge's key, so two cells sharing the edge create bit-identical
// copies. weld_edge_vertices keeps one vertex per key and rewrites the
// key-triangles as a TriMesh. Input: per-thread vertex and triangle lists
// (consumed). Output: the welded mesh, vertices in key order.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "soupuv/mesh.h"
#include "soupuv/vec.h"

namespace soupuv::proxy {

struct EdgeVertex {
  uint64_t key;
  Vec3 position;
};

TriMesh weld_edge_vertices(std::vector<std::vector<EdgeVertex>>& vertices,
                           const std::vector<std::vector<std::array<uint64_t, 3>>>& triangles);

}  // namespace soupuv::proxy
