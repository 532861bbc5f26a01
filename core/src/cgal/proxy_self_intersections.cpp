// CGAL self-intersection test for the proxy. See
// soupuv/cgal/proxy_self_intersections.h.
#include "soupuv/cgal/proxy_self_intersections.h"

#include <CGAL/Polygon_mesh_processing/self_intersections.h>

#include "surface_mesh_convert.h"

namespace soupuv::cgal {

bool self_intersects(const TriMesh& in) {
  SurfaceMesh mesh = to_surface_mesh(in, ErrorCode::invalid_input, "self-intersection test");
  return CGAL::Polygon_mesh_processing::does_self_intersect(mesh);
}

}  // namespace soupuv::cgal
