// CGAL edge-collapse decimation for the proxy. See soupuv/cgal/proxy_decimate.h.
#include "soupuv/cgal/proxy_decimate.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Bounded_normal_change_filter.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Edge_length_cost.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Edge_length_stop_predicate.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Midpoint_placement.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>

#include "soupuv/errors.h"

namespace soupuv::cgal {

TriMesh collapse_short_edges(const TriMesh& in, double min_edge_length) {
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;
  namespace SMS = CGAL::Surface_mesh_simplification;
  Mesh mesh;
  std::vector<Mesh::Vertex_index> vertex;
  vertex.reserve(in.vertices.size());
  for (const Vec3& p : in.vertices) vertex.push_back(mesh.add_vertex({p.x, p.y, p.z}));
  for (const auto& f : in.faces)
    if (mesh.add_face(vertex[f[0]], vertex[f[1]], vertex[f[2]]) == Mesh::null_face())
      throw Error(ErrorCode::internal, "decimate: input is not an oriented 2-manifold");

  SMS::Edge_length_stop_predicate<double> stop(min_edge_length);
  SMS::edge_collapse(mesh, stop,
                     CGAL::parameters::get_cost(SMS::Edge_length_cost<Mesh>())
                         .get_placement(SMS::Midpoint_placement<Mesh>())
                         .filter(SMS::Bounded_normal_change_filter<>()));
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
      if (k == 3) throw Error(ErrorCode::internal, "decimate: produced a non-triangle");
      t[k++] = int(v.idx());
    }
    out.faces.push_back(t);
  }
  return out;
}

}  // namespace soupuv::cgal
