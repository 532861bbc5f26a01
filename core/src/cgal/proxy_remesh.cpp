// CGAL isotropic remeshing for the proxy. See soupuv/cgal/proxy_remesh.h.
#include "soupuv/cgal/proxy_remesh.h"

#include <CGAL/Polygon_mesh_processing/remesh.h>

#include "surface_mesh_convert.h"

namespace soupuv::cgal {

TriMesh isotropic_remesh(const TriMesh& in, double target_edge_length, int iterations) {
  SurfaceMesh mesh = to_surface_mesh(in, ErrorCode::internal, "remesh");
  CGAL::Polygon_mesh_processing::isotropic_remeshing(
      faces(mesh), target_edge_length, mesh,
      CGAL::parameters::number_of_iterations(iterations).protect_constraints(false));
  return to_trimesh(mesh, "remesh");
}

}  // namespace soupuv::cgal
