// Edge adjacency of a closed triangle mesh, shared by segmentation, seams and
// chart extraction.
//
// Inputs:  a TriMesh.
// Outputs: for every face f and local edge k (from corner k to corner k+1),
//          the face across that edge and its unique edge id; per-face unit
//          normals and areas; per-edge vertex pairs. build_topology throws
//          Error{invalid_input} unless every edge has exactly two faces with
//          opposite orientation (a closed, oriented 2-manifold).
#pragma once

#include <array>
#include <vector>

#include "soupuv/mesh.h"
#include "soupuv/vec.h"

namespace soupuv::atlas {

struct MeshTopology {
  std::vector<std::array<int, 3>> face_neighbor;  // face across edge k of f
  std::vector<std::array<int, 3>> face_edge;      // edge id of edge k of f
  std::vector<std::array<int, 2>> edge_vertices;  // smaller vertex first
  std::vector<double> edge_length;
  std::vector<Vec3> face_normal;                  // unit (zero if degenerate)
  std::vector<double> face_area;
  std::vector<Vec3> face_centroid;
  double mean_edge_length = 0;
};

MeshTopology build_topology(const TriMesh& mesh);

}  // namespace soupuv::atlas
