#include "io/scene_flatten.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "io/checked_json.h"
#include "soupuv/errors.h"

namespace soupuv::io::detail {

constexpr Mat4 kIdentity{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

Mat4 multiply(const Mat4& a, const Mat4& b) {
  Mat4 r{};
  for (int c = 0; c < 4; ++c)
    for (int row = 0; row < 4; ++row) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a[k * 4 + row] * b[c * 4 + k];
      r[c * 4 + row] = s;
    }
  return r;
}

bool is_identity(const Mat4& m) { return m == kIdentity; }

Vec3 transform_point(const Mat4& m, Vec3 p) {
  // Identity keeps the input bits (even -0.0), which the writer relies on.
  if (is_identity(m)) return p;
  return {m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12], m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13],
          m[2] * p.x + m[6] * p.y + m[10] * p.z + m[14]};
}

Mat4 node_local_matrix(const nlohmann::json& node, const std::string& where) {
  if (auto m = get_opt_numbers(node, "matrix", 16, where)) {
    Mat4 r{};
    std::copy(m->begin(), m->end(), r.begin());
    return r;
  }
  auto t = get_opt_numbers(node, "translation", 3, where).value_or(std::vector<double>{0, 0, 0});
  auto q = get_opt_numbers(node, "rotation", 4, where).value_or(std::vector<double>{0, 0, 0, 1});
  auto s = get_opt_numbers(node, "scale", 3, where).value_or(std::vector<double>{1, 1, 1});
  const double x = q[0], y = q[1], z = q[2], w = q[3];
  // Rotation matrix of the unit quaternion (x, y, z, w), columns scaled by s.
  const double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y + z * w),     2 * (x * z - y * w),
                       2 * (x * y - z * w),     1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
                       2 * (x * z + y * w),     2 * (y * z - x * w),     1 - 2 * (x * x + y * y)};
  Mat4 m{};
  for (int c = 0; c < 3; ++c)
    for (int row = 0; row < 3; ++row) m[c * 4 + row] = r[c * 3 + row] * s[c];
  m[12] = t[0];
  m[13] = t[1];
  m[14] = t[2];
  m[15] = 1;
  return m;
}

std::vector<MeshInstance> flatten_scenes(const nlohmann::json& doc, uint64_t max_instances) {
  // Every node is parsed once; the walk below may visit it along many paths.
  struct NodeInfo {
    Mat4 local;
    int64_t mesh = -1;
    std::vector<uint64_t> children;
  };
  const size_t node_count = array_size(doc, "nodes");
  std::vector<NodeInfo> nodes(node_count);
  std::vector<bool> is_child(node_count, false);
  for (size_t n = 0; n < node_count; ++n) {
    std::string where = "node " + std::to_string(n);
    const nlohmann::json& node = element(doc, "nodes", n, where);
    NodeInfo& info = nodes[n];
    info.local = node_local_matrix(node, where);
    if (auto mesh = get_opt_uint(node, "mesh", where)) {
      element(doc, "meshes", *mesh, where);
      if (*mesh > INT32_MAX || n > INT32_MAX) fail_input(where + ": index too large");
      info.mesh = int64_t(*mesh);
    }
    if (const nlohmann::json* c = find_member(node, "children", where)) {
      if (!c->is_array()) fail_input(where + ": children is not an array");
      for (const auto& child : *c) {
        if (!child.is_number_unsigned() || child.get<uint64_t>() >= node_count)
          fail_input(where + ": child is not a valid node index");
        info.children.push_back(child.get<uint64_t>());
        is_child[child.get<uint64_t>()] = true;
      }
    }
  }

  std::vector<uint64_t> roots;
  std::set<uint64_t> seen_roots;
  size_t scene_count = array_size(doc, "scenes");
  for (size_t s = 0; s < scene_count; ++s) {
    std::string where = "scene " + std::to_string(s);
    const nlohmann::json& scene = element(doc, "scenes", s, where);
    if (const nlohmann::json* ns = find_member(scene, "nodes", where)) {
      if (!ns->is_array()) fail_input(where + ": nodes is not an array");
      for (const auto& r : *ns) {
        if (!r.is_number_unsigned() || r.get<uint64_t>() >= node_count)
          fail_input(where + ": root is not a valid node index");
        if (seen_roots.insert(r.get<uint64_t>()).second) roots.push_back(r.get<uint64_t>());
      }
    }
  }
  if (scene_count == 0)
    for (size_t n = 0; n < node_count; ++n)
      if (!is_child[n]) roots.push_back(n);

  // Iterative depth-first walk (untrusted depth must not blow the stack);
  // on_path detects cycles, which glTF forbids.
  struct Frame { uint64_t node; Mat4 world; size_t next_child; };
  std::vector<MeshInstance> out;
  std::vector<bool> on_path(node_count, false);
  uint64_t visits = 0;
  for (uint64_t root : roots) {
    std::vector<Frame> stack;
    auto enter = [&](uint64_t n, const Mat4& parent) {
      if (on_path[n]) fail_input("node " + std::to_string(n) + " is its own ancestor (cycle in the node graph)");
      if (++visits > max_instances)
        throw Error(ErrorCode::limit_exceeded, "node graph expands to more than " +
                                                   std::to_string(max_instances) + " node instances");
      const NodeInfo& info = nodes[n];
      Mat4 world = multiply(parent, info.local);
      for (double v : world)
        if (!std::isfinite(v)) fail_input("node " + std::to_string(n) + ": world transform is not finite");
      // A skinned mesh is placed by its node like any other: that is its
      // bind pose, which the soup is mapped in (the writer keeps the skin).
      if (info.mesh >= 0) out.push_back({int32_t(n), int32_t(info.mesh), world});
      on_path[n] = true;
      stack.push_back({n, world, 0});
    };
    enter(root, kIdentity);
    while (!stack.empty()) {
      Frame& top = stack.back();
      if (top.next_child < nodes[top.node].children.size()) {
        uint64_t child = nodes[top.node].children[top.next_child++];
        Mat4 world = top.world;
        enter(child, world);
      } else {
        on_path[top.node] = false;
        stack.pop_back();
      }
    }
  }
  return out;
}

}  // namespace soupuv::io::detail
