// Which instance each soup triangle belongs to, and each corner's position in
// its instance's frame (see gltf_write_parts.h).
#include <map>

#include <Eigen/Dense>

#include "gltf_write_parts.h"

namespace soupuv::io::detail {

namespace {

// World matrix of the first scene path reaching `node`, for assets that carry
// no instance table (built in tests or by older loaders).
Mat4 first_path_world(const NodeTree& tree, int32_t node) {
  for (size_t i = 0; i < tree.source_node.size(); ++i)
    if (tree.source_node[i] == node) return tree.world[i];
  return Mat4{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
}

}  // namespace

InstanceTable instance_table(const Asset& asset) {
  const Soup& soup = asset.soup;
  bool given = asset.triangle_instance.size() == soup.triangles.size() && !asset.instances.empty();
  if (given) {
    bool in_range = true;
    for (uint32_t i : asset.triangle_instance) in_range = in_range && i < asset.instances.size();
    if (in_range) return {asset.triangle_instance, asset.instances};
  }
  InstanceTable table;
  NodeTree tree = expand_node_tree(asset.document);
  std::map<std::pair<int32_t, int32_t>, uint32_t> index;
  table.triangle_instance.reserve(soup.triangles.size());
  for (const TriangleOrigin& o : soup.origins) {
    auto [it, inserted] = index.try_emplace({o.node, o.mesh}, static_cast<uint32_t>(table.instances.size()));
    if (inserted) table.instances.push_back({o.node, o.mesh, first_path_world(tree, o.node)});
    table.triangle_instance.push_back(it->second);
  }
  return table;
}

std::vector<Float3> corner_positions(const Asset& asset, const InstanceTable& table,
                                     std::vector<std::string>& warnings) {
  const Soup& soup = asset.soup;
  std::vector<Float3> out(soup.triangles.size() * 3);
  if (asset.local_positions.size() == soup.positions.size() && !soup.positions.empty()) {
    for (size_t t = 0; t < soup.triangles.size(); ++t)
      for (int k = 0; k < 3; ++k) out[t * 3 + k] = asset.local_positions[soup.triangles[t][k]];
    return out;
  }
  std::vector<Eigen::Matrix4d> inverse;
  bool derived = false;
  for (const MeshInstance& inst : table.instances) {
    Eigen::Matrix4d w = Eigen::Map<const Eigen::Matrix4d>(inst.world.data());
    derived = derived || !w.isIdentity(0.0);
    inverse.push_back(w.inverse());
  }
  for (size_t t = 0; t < soup.triangles.size(); ++t) {
    const Eigen::Matrix4d& inv = inverse[table.triangle_instance[t]];
    for (int k = 0; k < 3; ++k) {
      Vec3 w = soup.positions[soup.triangles[t][k]];
      Eigen::Vector4d l = inv * Eigen::Vector4d(w.x, w.y, w.z, 1.0);
      out[t * 3 + k] = {static_cast<float>(l[0]), static_cast<float>(l[1]), static_cast<float>(l[2])};
    }
  }
  if (derived)
    warnings.push_back("local positions re-derived from world space (the loader gave none): "
                       "positions under transformed nodes may differ in the last bits");
  return out;
}

}  // namespace soupuv::io::detail
