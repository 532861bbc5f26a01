// Seam hints (paper §6): user polylines turned into paths along mesh edges.
//
// Inputs:  mesh, topology, the hints (3D points; each snaps to its nearest
//          vertex), weights alpha and beta.
// Output:  the edge ids of all paths (forced seams) and warnings for hint
//          points that could not be joined.
//
// Consecutive points are joined by Dijkstra over the mesh edges with the cost
//   |x - y| + alpha' (1 - (Dx + Dy) / (2 max_z Dz)) + beta' |Dx - Dy| / max_z Dz
// where Dx is the magnitude of the cotangent Laplacian of the positions at x
// (mean curvature; Meyer et al. 2003 with barycentric areas), alpha' and beta'
// are alpha and beta times the mean edge length (so the weights are unitless),
// and the edges of earlier segments of the same hint cost infinity.
#pragma once

#include <string>
#include <vector>

#include "atlas/mesh_topology.h"
#include "soupuv/atlas/build_atlas.h"

namespace soupuv::atlas {

struct SeamPaths {
  std::vector<int> edges;
  std::vector<std::string> warnings;
};

// Laplacian magnitude per vertex, exposed for tests.
std::vector<double> laplacian_magnitude(const TriMesh& mesh);

SeamPaths trace_seam_hints(const TriMesh& mesh, const MeshTopology& topology,
                           const std::vector<SeamHint>& hints, double alpha, double beta);

}  // namespace soupuv::atlas
