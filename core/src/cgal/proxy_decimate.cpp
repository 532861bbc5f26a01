// CGAL edge-collapse decimation for the proxy. See soupuv/cgal/proxy_decimate.h.
#include "soupuv/cgal/proxy_decimate.h"

#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Bounded_normal_change_filter.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Edge_length_cost.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Edge_length_stop_predicate.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Midpoint_placement.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>

#include "surface_mesh_convert.h"

namespace soupuv::cgal {

TriMesh collapse_short_edges(const TriMesh& in, double min_edge_length) {
  namespace SMS = CGAL::Surface_mesh_simplification;
  SurfaceMesh mesh = to_surface_mesh(in, ErrorCode::internal, "decimate");
  SMS::Edge_length_stop_predicate<double> stop(min_edge_length);
  SMS::edge_collapse(mesh, stop,
                     CGAL::parameters::get_cost(SMS::Edge_length_cost<SurfaceMesh>())
                         .get_placement(SMS::Midpoint_placement<SurfaceMesh>())
                         .filter(SMS::Bounded_normal_change_filter<>()));
  return to_trimesh(mesh, "decimate");
}

}  // namespace soupuv::cgal
