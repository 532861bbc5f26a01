// CGAL self-intersection test for the proxy. See
// soupuv/cgal/proxy_self_intersections.h.
#include "soupuv/cgal/proxy_self_intersections.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <vector>

#include "soupuv/errors.h"

namespace soupuv::cgal {

bool self_intersects(const TriMesh& in) {
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Mesh = CGAL::Surface_mesh<Kernel::Point_3>;
  Mesh mesh;
  std::vector<Mesh::Vertex_index> vertex;
  vertex.reserve(in.vertices.size());
  for (const Vec3& p : in.vertices) vertex.push_back(mesh.add_vertex({p.x, p.y, p.z}));
  for (const auto& f : in.faces)
    if (mesh.add_face(vertex[f[0]], vertex[f[1]], vertex[f[2]]) == Mesh::null_face())
      throw Error(ErrorCode::invalid_input, "self-intersection test needs an oriented 2-manifold");
  return CGAL::Polygon_mesh_processing::does_self_intersect(mesh);
}

}  // namespace soupuv::cgal
