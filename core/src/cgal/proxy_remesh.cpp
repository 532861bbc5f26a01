// CGAL isotropic remeshing for the proxy. See soupuv/cgal/proxy_remesh.h.
#include "soupuv/cgal/proxy_remesh.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Surface_mesh.h>

#include "soupuv/errors.h"

namespace soupuv::cgal {
namespace {
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;
}  // namespace

TriMesh isotropic_remesh(const TriMesh& in, double target_edge_length, int iterations) {
  Mesh mesh;
  std::vector<Mesh::Vertex_index> vertex;
  vertex.reserve(in.vertices.size());
  for (const Vec3& p : in.vertices) vertex.push_back(mesh.add_vertex({p.x, p.y, p.z}));
  for (const auto& f : in.faces)
    if (mesh.add_face(vertex[f[0]], vertex[f[1]], vertex[f[2]]) == Mesh::null_face())
      throw Error(ErrorCode::internal, "remesh: input is not an oriented 2-manifold");

  CGAL::Polygon_mesh_processing::isotropic_remeshing(
      faces(mesh), target_edge_length, mesh,
      CGAL::parameters::number_of_iterations(iterations).protect_constraints(false));
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
      if (k == 3) throw Error(ErrorCode::internal, "remesh: produced a non-triangle");
      t[k++] = int(v.idx());
    }
    out.faces.push_back(t);
  }
  return out;
}

}  // namespace soupuv::cgal
