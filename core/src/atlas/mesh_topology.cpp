#include "atlas/mesh_topology.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "soupuv/errors.h"

namespace soupuv::atlas {

MeshTopology build_topology(const TriMesh& mesh) {
  const int nf = static_cast<int>(mesh.faces.size());
  const int nv = static_cast<int>(mesh.vertices.size());
  if (nf == 0) throw Error(ErrorCode::no_triangles, "atlas: the mesh has no faces");
  for (const Vec3& p : mesh.vertices)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw Error(ErrorCode::invalid_input, "atlas: non-finite vertex coordinate");

  // Directed half-edges sorted by (from, to) let us find each twin by binary
  // search: cheaper in memory than a hash map at 100k+ faces.
  struct HalfEdge { int from, to, face, k; };
  std::vector<HalfEdge> half(3 * static_cast<size_t>(nf));
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) {
      int a = mesh.faces[f][k], b = mesh.faces[f][(k + 1) % 3];
      if (a < 0 || a >= nv || b < 0 || b >= nv)
        throw Error(ErrorCode::invalid_input, "atlas: face index out of range");
      if (a == b)
        throw Error(ErrorCode::invalid_input, "atlas: face with a repeated vertex");
      half[3 * f + k] = {a, b, f, k};
    }
  std::sort(half.begin(), half.end(), [](const HalfEdge& x, const HalfEdge& y) {
    return x.from != y.from ? x.from < y.from : x.to < y.to;
  });
  for (size_t i = 1; i < half.size(); ++i)
    if (half[i].from == half[i - 1].from && half[i].to == half[i - 1].to)
      throw Error(ErrorCode::invalid_input,
                  "atlas: the mesh is not an oriented 2-manifold (edge " +
                      std::to_string(half[i].from) + "-" + std::to_string(half[i].to) +
                      " used twice in the same direction)");

  MeshTopology t;
  t.face_neighbor.assign(nf, {-1, -1, -1});
  t.face_edge.assign(nf, {-1, -1, -1});
  auto find = [&](int from, int to) -> const HalfEdge* {
    auto it = std::lower_bound(half.begin(), half.end(), HalfEdge{from, to, 0, 0},
                               [](const HalfEdge& x, const HalfEdge& y) {
                                 return x.from != y.from ? x.from < y.from : x.to < y.to;
                               });
    if (it == half.end() || it->from != from || it->to != to) return nullptr;
    return &*it;
  };
  double length_sum = 0;
  for (const HalfEdge& h : half) {
    if (t.face_edge[h.face][h.k] >= 0) continue;
    const HalfEdge* twin = find(h.to, h.from);
    if (!twin)
      throw Error(ErrorCode::invalid_input,
                  "atlas: the mesh is not closed (edge " + std::to_string(h.from) + "-" +
                      std::to_string(h.to) + " has one face)");
    int e = static_cast<int>(t.edge_vertices.size());
    t.edge_vertices.push_back({std::min(h.from, h.to), std::max(h.from, h.to)});
    t.face_edge[h.face][h.k] = e;
    t.face_edge[twin->face][twin->k] = e;
    t.face_neighbor[h.face][h.k] = twin->face;
    t.face_neighbor[twin->face][twin->k] = h.face;
    t.edge_length.push_back(norm(mesh.vertices[h.from] - mesh.vertices[h.to]));
    length_sum += t.edge_length.back();
  }
  t.mean_edge_length = length_sum / std::max<size_t>(1, t.edge_vertices.size());

  t.face_normal.resize(nf);
  t.face_area.resize(nf);
  t.face_centroid.resize(nf);
  for (int f = 0; f < nf; ++f) {
    const Vec3& a = mesh.vertices[mesh.faces[f][0]];
    const Vec3& b = mesh.vertices[mesh.faces[f][1]];
    const Vec3& c = mesh.vertices[mesh.faces[f][2]];
    Vec3 n = cross(b - a, c - a);
    t.face_area[f] = 0.5 * norm(n);
    t.face_normal[f] = normalized(n);
    t.face_centroid[f] = (a + b + c) / 3.0;
  }
  return t;
}

}  // namespace soupuv::atlas
