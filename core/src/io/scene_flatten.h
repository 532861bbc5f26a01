// Flattening the glTF node graph to mesh instances in world space.
//
// Input : the document. Roots are all scenes' root nodes (each once); without
//         scenes, every node that is nobody's child.
// Output: one MeshInstance per (path to a mesh-carrying node), world = product
//         of the nodes' matrices (matrix or T*R*S) along the path. Errors:
//         invalid_input for bad indices, non-finite transforms or cycles;
//         limit_exceeded past max_instances node visits (DAGs can multiply paths).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "soupuv/io/asset.h"

namespace soupuv::io::detail {

Mat4 node_local_matrix(const nlohmann::json& node, const std::string& where);
Mat4 multiply(const Mat4& a, const Mat4& b);
bool is_identity(const Mat4& m);
Vec3 transform_point(const Mat4& m, Vec3 p);

std::vector<MeshInstance> flatten_scenes(const nlohmann::json& doc, uint64_t max_instances);

}  // namespace soupuv::io::detail
