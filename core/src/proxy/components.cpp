// Component split and inner/outer classification. See soupuv/proxy/components.h.
#include "soupuv/proxy/components.h"

#include <algorithm>
#include <memory>
#include "soupuv/geometry/distance_bvh.h"
#include "soupuv/union_find.h"

namespace soupuv::proxy {
namespace {

bool box_inside(const Box3& inner, const Box3& outer) {
  for (int k = 0; k < 3; ++k)
    if (inner.lo[k] < outer.lo[k] || inner.hi[k] > outer.hi[k]) return false;
  return true;
}

}  // namespace

double signed_volume(const TriMesh& mesh, const std::vector<int>& face_component, int component) {
  double six_v = 0;
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    if (component >= 0 && face_component[f] != component) continue;
    const auto& t = mesh.faces[f];
    six_v += dot(mesh.vertices[t[0]], cross(mesh.vertices[t[1]], mesh.vertices[t[2]]));
  }
  return six_v / 6;
}

Components find_components(const TriMesh& mesh) {
  Components out;
  UnionFind vertices(mesh.vertices.size());
  for (const auto& t : mesh.faces)
    for (int k = 1; k < 3; ++k) vertices.unite(t[0], t[k]);
  std::vector<int> id_of_root(mesh.vertices.size(), -1);
  out.face_component.resize(mesh.faces.size());
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const uint32_t root = vertices.find(mesh.faces[f][0]);
    if (id_of_root[root] < 0) id_of_root[root] = out.count++;
    out.face_component[f] = id_of_root[root];
  }

  std::vector<Box3> boxes(out.count);
  std::vector<int> sample_vertex(out.count, -1);
  std::vector<std::vector<std::array<Vec3, 3>>> tris(out.count);
  out.volume.assign(out.count, 0.0);
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    int c = out.face_component[f];
    const auto& t = mesh.faces[f];
    std::array<Vec3, 3> p{mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]};
    for (const Vec3& v : p) boxes[c].add(v);
    if (sample_vertex[c] < 0) sample_vertex[c] = t[0];
    out.volume[c] += dot(p[0], cross(p[1], p[2])) / 6;
    tris[c].push_back(p);
  }
  // A component is inner when one of its vertices is inside another component
  // whose box contains its box (cheap rejection first, paper §5).
  out.inner.assign(out.count, 0);
  std::vector<std::unique_ptr<geometry::DistanceBvh>> bvh(out.count);
  for (int a = 0; a < out.count; ++a) {
    for (int b = 0; b < out.count && !out.inner[a]; ++b) {
      if (a == b || !box_inside(boxes[a], boxes[b])) continue;
      if (!bvh[b]) bvh[b] = std::make_unique<geometry::DistanceBvh>(tris[b]);
      out.inner[a] = bvh[b]->contains(mesh.vertices[sample_vertex[a]]);
    }
  }
  return out;
}

TriMesh keep_faces(const TriMesh& mesh, const std::vector<char>& keep) {
  TriMesh out;
  std::vector<int> remap(mesh.vertices.size(), -1);
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    if (!keep[f]) continue;
    std::array<int, 3> t;
    for (int k = 0; k < 3; ++k) {
      int v = mesh.faces[f][k];
      if (remap[v] < 0) {
        remap[v] = int(out.vertices.size());
        out.vertices.push_back(mesh.vertices[v]);
      }
      t[k] = remap[v];
    }
    out.faces.push_back(t);
  }
  return out;
}

}  // namespace soupuv::proxy
