// The writer's output node hierarchy (see gltf_write_parts.h): the source
// scenes expanded into strict trees, and each mesh instance placed on the
// output node of its own path. O(paths) for the expansion, O(instances x
// paths of the same node) for the placement.
#include <cmath>
#include <limits>
#include <map>

#include "gltf_write_parts.h"
#include "soupuv/errors.h"

namespace soupuv::io::detail {

namespace {

using nlohmann::json;

constexpr size_t kMaxOutputNodes = 1'000'000;  // a diamond-shaped DAG can have 2^depth paths

Mat4 identity() { return Mat4{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; }

Mat4 multiply(const Mat4& a, const Mat4& b) {
  Mat4 r{};
  for (int col = 0; col < 4; ++col)
    for (int row = 0; row < 4; ++row) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a[k * 4 + row] * b[col * 4 + k];
      r[col * 4 + row] = s;
    }
  return r;
}

bool numbers(const json& node, const char* key, size_t n, double* out) {
  auto it = node.find(key);
  if (it == node.end() || !it->is_array() || it->size() != n) return false;
  for (size_t i = 0; i < n; ++i) {
    if (!(*it)[i].is_number()) return false;
    out[i] = (*it)[i].get<double>();
  }
  return true;
}

// A node's local matrix: "matrix" if present, else T * R * S (glTF's order).
Mat4 local_matrix(const json& node) {
  Mat4 m = identity();
  if (numbers(node, "matrix", 16, m.data())) return m;
  double t[3] = {0, 0, 0}, q[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
  numbers(node, "translation", 3, t);
  numbers(node, "rotation", 4, q);
  numbers(node, "scale", 3, s);
  double x = q[0], y = q[1], z = q[2], w = q[3];
  double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y + z * w),     2 * (x * z - y * w),
                 2 * (x * y - z * w),     1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
                 2 * (x * z + y * w),     2 * (y * z - x * w),     1 - 2 * (x * x + y * y)};
  for (int col = 0; col < 3; ++col)
    for (int row = 0; row < 3; ++row) m[col * 4 + row] = r[col * 3 + row] * s[col];
  m[12] = t[0]; m[13] = t[1]; m[14] = t[2];
  return m;
}

const json& array_or_empty(const json& document, const char* key) {
  static const json empty = json::array();
  auto it = document.find(key);
  return it != document.end() && it->is_array() ? *it : empty;
}

std::vector<size_t> valid_children(const json& node, size_t count) {
  std::vector<size_t> out;
  if (!node.is_object()) return out;
  for (const json& c : node.value("children", json::array()))
    if (c.is_number_unsigned() && c.get<size_t>() < count) out.push_back(c.get<size_t>());
  return out;
}

struct Expander {
  const json& source;  // document nodes
  NodeTree& tree;
  std::vector<bool> on_path;

  // Emits the output node for `node` reached with parent world `parent` and
  // returns its index; children are visited depth first.
  int32_t visit(size_t node, const Mat4& parent) {
    if (tree.nodes.size() >= kMaxOutputNodes)
      throw Error(ErrorCode::limit_exceeded, "node hierarchy expands to more than 1000000 nodes");
    const json& src = source[node];
    json out = json::object();
    if (src.is_object())
      for (const char* key : {"name", "matrix", "translation", "rotation", "scale", "camera", "extras"})
        if (src.contains(key)) out[key] = src[key];
    int32_t index = static_cast<int32_t>(tree.nodes.size());
    Mat4 world = multiply(parent, src.is_object() ? local_matrix(src) : identity());
    tree.nodes.push_back(out);
    tree.source_node.push_back(static_cast<int32_t>(node));
    tree.world.push_back(world);
    on_path[node] = true;
    json children = json::array();
    for (size_t c : valid_children(src, source.size()))
      if (!on_path[c]) children.push_back(visit(c, world));  // a cycle is cut where it closes
    on_path[node] = false;
    if (!children.empty()) tree.nodes[index]["children"] = children;
    return index;
  }
};

double matrix_distance(const Mat4& a, const Mat4& b) {
  double d = 0;
  for (int i = 0; i < 16; ++i) d = std::max(d, std::fabs(a[i] - b[i]));
  return d;
}

bool is_identity(const Mat4& m) { return m == identity(); }

}  // namespace

NodeTree expand_node_tree(const json& document) {
  NodeTree tree;
  const json& nodes = array_or_empty(document, "nodes");
  Expander expander{nodes, tree, std::vector<bool>(nodes.size(), false)};
  std::vector<std::vector<size_t>> scene_roots;
  for (const json& scene : array_or_empty(document, "scenes")) {
    std::vector<size_t> roots;
    if (scene.is_object())
      for (const json& r : scene.value("nodes", json::array()))
        if (r.is_number_unsigned() && r.get<size_t>() < nodes.size()) roots.push_back(r.get<size_t>());
    scene_roots.push_back(roots);
  }
  if (scene_roots.empty()) {
    // No scene: every node nobody names as a child is a root.
    std::vector<bool> child(nodes.size(), false);
    for (const json& n : nodes)
      for (size_t c : valid_children(n, nodes.size())) child[c] = true;
    std::vector<size_t> roots;
    for (size_t i = 0; i < nodes.size(); ++i)
      if (!child[i]) roots.push_back(i);
    scene_roots.push_back(roots);
  }
  const json& scenes = array_or_empty(document, "scenes");
  for (size_t s = 0; s < scene_roots.size(); ++s) {
    json scene = {{"nodes", json::array()}};
    if (s < scenes.size() && scenes[s].is_object() && scenes[s].contains("name"))
      scene["name"] = scenes[s]["name"];
    for (size_t r : scene_roots[s]) scene["nodes"].push_back(expander.visit(r, identity()));
    tree.scenes.push_back(scene);
  }
  if (document.contains("scene") && document["scene"].is_number_unsigned() &&
      document["scene"].get<size_t>() < tree.scenes.size())
    tree.scene = document["scene"].get<int>();
  return tree;
}

std::vector<int32_t> place_instances(NodeTree& tree, const std::vector<MeshInstance>& instances) {
  std::multimap<int32_t, int32_t> paths;  // source node -> output nodes
  for (size_t i = 0; i < tree.source_node.size(); ++i)
    paths.emplace(tree.source_node[i], static_cast<int32_t>(i));
  std::vector<bool> taken(tree.nodes.size(), false);
  std::vector<int32_t> placement(instances.size(), -1);
  for (size_t i = 0; i < instances.size(); ++i) {
    const MeshInstance& inst = instances[i];
    double best = std::numeric_limits<double>::infinity();
    auto [lo, hi] = paths.equal_range(inst.node);
    for (auto it = lo; it != hi; ++it) {
      double d = matrix_distance(tree.world[it->second], inst.world);
      if (!taken[it->second] && d < best) {
        best = d;
        placement[i] = it->second;
      }
    }
    if (placement[i] >= 0) {
      taken[placement[i]] = true;
      continue;
    }
    json root = json::object();
    if (!is_identity(inst.world)) root["matrix"] = inst.world;
    placement[i] = static_cast<int32_t>(tree.nodes.size());
    tree.nodes.push_back(root);
    tree.source_node.push_back(inst.node);
    tree.world.push_back(inst.world);
    taken.push_back(true);
    tree.scenes[tree.scene]["nodes"].push_back(placement[i]);
  }
  return placement;
}

}  // namespace soupuv::io::detail
