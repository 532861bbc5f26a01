// Conversions between our TriMesh and CGAL's Surface_mesh, shared by the CGAL
// wrappers in this folder (and, like them, never included outside it).
#pragma once

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include <array>
#include <string>
#include <vector>

#include "soupuv/errors.h"
#include "soupuv/mesh.h"

namespace soupuv::cgal {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;

// Builds a Surface_mesh; a face CGAL refuses (non-manifold or inconsistently
// oriented input) throws Error{error_code, "<what>: ..."}.
inline SurfaceMesh to_surface_mesh(const TriMesh& in, ErrorCode error_code, const std::string& what) {
  SurfaceMesh mesh;
  std::vector<SurfaceMesh::Vertex_index> vertex;
  vertex.reserve(in.vertices.size());
  for (const Vec3& p : in.vertices) vertex.push_back(mesh.add_vertex({p.x, p.y, p.z}));
  for (const auto& f : in.faces)
    if (mesh.add_face(vertex[f[0]], vertex[f[1]], vertex[f[2]]) == SurfaceMesh::null_face())
      throw Error(error_code, what + ": input is not an oriented 2-manifold");
  return mesh;
}

// Reads a triangle Surface_mesh back (garbage collected first, so indices are dense).
inline TriMesh to_trimesh(SurfaceMesh& mesh, const std::string& what) {
  mesh.collect_garbage();
  TriMesh out;
  out.vertices.reserve(mesh.number_of_vertices());
  for (auto v : mesh.vertices()) {
    const auto& p = mesh.point(v);
    out.vertices.push_back({p.x(), p.y(), p.z()});
  }
  out.faces.reserve(mesh.number_of_faces());
  for (auto f : mesh.faces()) {
    std::array<int, 3> t{};
    int k = 0;
    for (auto v : vertices_around_face(mesh.halfedge(f), mesh)) {
      if (k == 3) throw Error(ErrorCode::internal, what + ": produced a non-triangle");
      t[k++] = int(v.idx());
    }
    out.faces.push_back(t);
  }
  return out;
}

}  // namespace soupuv::cgal
