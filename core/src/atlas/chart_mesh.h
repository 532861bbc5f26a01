// One chart cut out of the mesh as its own small mesh, and its topology.
//
// Inputs:  the mesh, its topology, the chart's faces, chart id per face and
//          forced seam flags per edge; face_local is a scratch array over all
//          faces (each face belongs to one chart, so charts extracted in
//          parallel write disjoint entries).
// Output:  ChartMesh with local vertices: mesh corners are merged only across
//          edges interior to the chart and not forced seams, so a vertex where
//          the chart touches itself, or a seam slit, gets several local copies.
//          euler = V - E + F and the number of boundary loops; a topological
//          disk has euler 1 and one loop.
#pragma once

#include <array>
#include <vector>

#include "mesh_topology.h"  // relative: the tests include this header by path
#include "soupuv/mesh.h"

namespace soupuv::atlas {

struct ChartMesh {
  std::vector<int> faces;                  // global face ids
  std::vector<std::array<int, 3>> tri;     // local vertex ids per face, same order
  std::vector<int> vertex_global;          // local vertex -> mesh vertex
  std::vector<Vec3> position;              // local vertex -> 3D position
  std::vector<int> boundary;               // the first boundary loop, in order
  int euler = 0;
  int boundary_loops = 0;
  bool is_disk() const { return euler == 1 && boundary_loops == 1; }
};

ChartMesh extract_chart(const TriMesh& mesh, const MeshTopology& topology,
                        const std::vector<int>& faces, const std::vector<int>& face_chart,
                        const std::vector<char>& forced_seam, std::vector<int>& face_local);

}  // namespace soupuv::atlas
